// The page: the 3D scene, the readout and the plot, fed by the state stream (/state, one
// JSON message per snapshot, about 60 a second). It draws only when something changed, and
// reconnects by itself when the robot restarts.

import * as THREE from 'three';
import { OrbitControls } from '/three/OrbitControls.js';
import { Arm, AXIS_COLOURS } from '/arm.js';
import { AnglePlot, JOINT_COLOURS } from '/plot.js';

const $ = (id) => document.getElementById(id);
const RECONNECT_MS = 1000;

// --- readout ---------------------------------------------------------------------------

const jointCells = JOINT_COLOURS.map((colour, j) => {
  const row = $('joints').tBodies[0].insertRow();
  const name = document.createElement('th');
  name.textContent = `J${j + 1}`;
  name.style.color = colour;
  row.appendChild(name);
  return row.insertCell();
});

function showReadout(state) {
  state.angles_deg.forEach((a, j) => (jointCells[j].textContent = a.toFixed(2)));
  state.coords.forEach((v, i) => ($(`c${i}`).textContent = v.toFixed(i < 3 ? 1 : 2)));
  $('coords-of').textContent = `${state.end === 'tool' ? 'tool tip' : 'flange'}, ${state.frame} frame`;
  $('gripper').textContent = `${state.gripper} %`;
  const hex = '#' + state.led.map((c) => c.toString(16).padStart(2, '0')).join('');
  $('led-swatch').style.background = hex;
  $('led').textContent = hex;
  const status = [state.powered ? 'powered on' : 'powered off', state.moving ? 'moving' : 'at rest'];
  if (state.protocol) status.push(`${state.protocol} protocol`);
  if (state.late_stalls > 0) {
    // The machine could not keep the simulation in real time: it ran this much late.
    status.push(`ran ${state.late_ms.toFixed(0)} ms late (${state.late_stalls} stalls)`);
  }
  $('status').textContent = status.join(' \u00b7 ');
  showCollision(state.collision);
  showProgram(state.basic_program);
}

// The Basic's own program (--basic-program), when it runs one: its name, what the board's
// screen says of it, and why its last record or playback ended early.
const PROGRAM_TITLES = { teach: 'teach and play' };

function showProgram(program) {
  $('program').hidden = !program;
  if (!program) return;
  $('program-name').textContent = PROGRAM_TITLES[program.name] ?? program.name;
  $('program-lines').textContent = program.lines.join('\n');
  $('program-error').hidden = !program.error;
  $('program-error').textContent = program.error ?? '';
}

// A click presses the Basic's button (held 150 ms of the robot's time, as a finger would).
for (const button of document.querySelectorAll('#program button[data-button]')) {
  button.addEventListener('click', async () => {
    try {
      const answer = await fetch(`/button/${button.dataset.button}`, { method: 'POST' });
      if (!answer.ok) showError(`button ${button.textContent}: ${await answer.text()}`);
    } catch (e) {
      showError(`button ${button.textContent}: ${e.message}`);
    }
  });
}

// The collision the Atom detected and the host has not cleared: its joint's row marked, and a
// line saying which joint, what error and when.
function showCollision(collision) {
  jointCells.forEach((cell, j) => cell.parentElement.classList.toggle('hit', collision?.joint === j + 1));
  $('collision').hidden = !collision;
  if (collision) {
    $('collision').textContent =
      `collision: J${collision.joint} (error ${collision.code}, ${collision.during}) at ${collision.t_s.toFixed(2)} s; clear_error_information() to move again`;
  }
}

function showLink(up) {
  $('link').textContent = up ? 'live' : 'disconnected';
  $('link').className = up ? 'up' : 'down';
}

function showError(text) {
  $('error').hidden = false;
  $('error').textContent = text;
}

// --- scene -----------------------------------------------------------------------------

function buildScene(model) {
  const canvas = $('scene');
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1d2127);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404850, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 2.2);
  sun.position.set(300, -500, 700);
  scene.add(sun);
  const grid = new THREE.GridHelper(600, 12, 0x56606b, 0x343b44);
  grid.rotation.x = Math.PI / 2; // the grid in the base's xy plane (z is up)
  scene.add(grid);
  const axes = new THREE.AxesHelper(90).setColors(...AXIS_COLOURS);
  axes.position.z = 1;
  scene.add(axes);

  const arm = new Arm(model);
  scene.add(arm.root);

  const camera = new THREE.PerspectiveCamera(40, 1, 5, 5000);
  camera.up.set(0, 0, 1);
  camera.position.set(470, -600, 400);
  const controls = new OrbitControls(camera, canvas);
  controls.target.set(30, 0, 180);
  controls.update();

  const resize = () => {
    const w = canvas.clientWidth;
    const h = canvas.clientHeight;
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  };
  return { renderer, scene, camera, controls, arm, resize };
}

// --- main ------------------------------------------------------------------------------

// What the page has done, for the browser tests and the cost bench (read over DevTools; kept
// out of the DOM so that counting costs no style or layout work).
const stats = { received: 0, drawn: 0, flangeMm: null };
window.viewStats = stats;

// The plot scrolls with time; it is redrawn at most this often while it changes.
const PLOT_PERIOD_MS = 50;

const plot = new AnglePlot($('plot'));
let view = null; // the scene, once the model has loaded and WebGL works
let latest = null; // the last state received
let shown = ''; // what the readout and the arm last showed (keyOf)
let sceneDirty = true;
let plotDirty = false;
let plotDrawnAt = 0;
let scheduled = false;

// Everything in a state message that is read out or drawn, except the time: an arm at rest
// sends the same key 60 times a second, and then the page does nothing.
const keyOf = (s) =>
  JSON.stringify([s.angles_deg, s.coords, s.end, s.frame, s.tool, s.gripper, s.led, s.powered, s.moving, s.collision, s.late_stalls, s.protocol, s.basic_program]);

function schedule() {
  if (!scheduled) {
    scheduled = true;
    requestAnimationFrame(draw);
  }
}

function draw(now) {
  scheduled = false;
  if (latest && keyOf(latest) !== shown) {
    shown = keyOf(latest);
    showReadout(latest);
    if (view) {
      view.arm.pose(latest);
      sceneDirty = true;
      const f = view.arm.flangeMm();
      stats.flangeMm = [f.x, f.y, f.z];
    }
  }
  if (plotDirty) {
    if (now - plotDrawnAt >= PLOT_PERIOD_MS) {
      plot.draw();
      plotDrawnAt = now;
      plotDirty = false;
    } else {
      schedule();
    }
  }
  if (view && sceneDirty) {
    view.renderer.render(view.scene, view.camera);
    sceneDirty = false;
    stats.drawn += 1;
  }
}

function connect() {
  const socket = new WebSocket(`ws://${location.host}/state`);
  socket.onopen = () => showLink(true);
  socket.onmessage = (event) => {
    latest = JSON.parse(event.data);
    stats.received += 1;
    plotDirty = plot.push(latest.t_s, latest.angles_deg) || plotDirty;
    if (plotDirty || keyOf(latest) !== shown) schedule();
  };
  socket.onclose = () => {
    showLink(false);
    setTimeout(connect, RECONNECT_MS);
  };
}

async function start() {
  try {
    const model = await (await fetch('/model.json')).json();
    view = buildScene(model);
    view.resize();
    shown = ''; // pose the arm with the state that came before the scene
    view.controls.addEventListener('change', () => {
      sceneDirty = true;
      schedule();
    });
    window.addEventListener('resize', () => {
      view.resize();
      sceneDirty = true;
      plotDirty = true; // its canvas takes the new width when drawn
      schedule();
    });
    schedule();
  } catch (e) {
    showError(`3D view unavailable: ${e.message}`);
  }
  connect();
}

start();
