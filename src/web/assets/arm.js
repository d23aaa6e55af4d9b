// The arm, drawn from the DH table kinematics-core computes with (served as /model.json).
//
// One group per DH frame, nested base -> 1 -> ... -> 6 (the flange); group i is posed by joint
// i's link transform A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i), theta_i = q_i + offset_i,
// so the drawn flange is where the firmware's forward kinematics puts it. Millimetres, z up.
// Each frame i carries the drum of joint i+1 (its axis is z_i) and the d_(i+1) link along
// z_i; each frame carries its own a_i link back along x_i.

import * as THREE from 'three';

const DEG = Math.PI / 180;

// The links' colour; the browser test finds the arm on a screenshot by this orange.
export const LINK_COLOUR = 0xf28c28;
// x, y, z axes of the frames drawn (base, tool): plain red, green, blue, so that nothing but
// the links is orange.
export const AXIS_COLOURS = [0xff3b3b, 0x3bd23b, 0x3b8bff];
const JOINT_COLOUR = 0x454b54;
// A joint the Atom detected a collision on.
const HIT_COLOUR = 0xd32f2f;
const BASE_COLOUR = 0x5d6670;
const GRIPPER_COLOUR = 0xb8c0c8;

const LINK_RADIUS_MM = 17;
const DRUM_RADIUS_MM = 24;
const DRUM_LENGTH_MM = 46;
// Finger gap of the drawn gripper at 100 % open (the drawing's, not a measured value).
const GRIPPER_SPAN_MM = 40;

const material = (colour) => new THREE.MeshStandardMaterial({ color: colour, roughness: 0.55, metalness: 0.1 });

// A cylinder of `radius` from point `from` to point `to` (arrays, mm) in `parent`.
function rod(parent, from, to, radius, mat) {
  const a = new THREE.Vector3(...from);
  const b = new THREE.Vector3(...to);
  const length = a.distanceTo(b);
  if (length < 1e-6) return null;
  const mesh = new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, length, 32), mat);
  mesh.position.copy(a).add(b).multiplyScalar(0.5);
  mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), b.clone().sub(a).normalize());
  parent.add(mesh);
  return mesh;
}

// A box of `size` [x, y, z] centred at `at` in `parent`.
function box(parent, size, at, mat) {
  const mesh = new THREE.Mesh(new THREE.BoxGeometry(...size), mat);
  mesh.position.set(...at);
  parent.add(mesh);
  return mesh;
}

// The link transform A_i of the DH table at DH angle `theta` (radians).
function linkMatrix(d, a, alpha, theta) {
  return new THREE.Matrix4()
    .makeRotationZ(theta)
    .multiply(new THREE.Matrix4().makeTranslation(0, 0, d))
    .multiply(new THREE.Matrix4().makeTranslation(a, 0, 0))
    .multiply(new THREE.Matrix4().makeRotationX(alpha));
}

export class Arm {
  // `model`: {d_mm, a_mm, alpha_deg, theta_offset_deg}, six entries each.
  constructor(model) {
    this.model = model;
    this.root = new THREE.Group();
    this.frames = [];
    this.drums = [];
    const links = material(LINK_COLOUR);
    const joints = material(JOINT_COLOUR);
    this.jointMaterial = joints;
    this.hitMaterial = material(HIT_COLOUR);

    box(this.root, [130, 130, 24], [0, 0, -12], material(BASE_COLOUR));
    let parent = this.root;
    for (let i = 0; i < 6; i++) {
      const d = model.d_mm[i];
      const a = model.a_mm[i];
      // Joint i+1 turns about z_i: its drum sits on that axis (joint 1's on the base plate).
      const drumAt = i === 0 ? DRUM_LENGTH_MM / 2 : 0;
      this.drums.push(rod(parent, [0, 0, drumAt - DRUM_LENGTH_MM / 2], [0, 0, drumAt + DRUM_LENGTH_MM / 2], DRUM_RADIUS_MM, joints));
      rod(parent, [0, 0, 0], [0, 0, d], LINK_RADIUS_MM, links);
      const frame = new THREE.Group();
      frame.matrixAutoUpdate = false;
      parent.add(frame);
      rod(frame, [-a, 0, 0], [0, 0, 0], LINK_RADIUS_MM, links);
      this.frames.push(frame);
      parent = frame;
    }
    const flange = this.frames[5];
    rod(flange, [0, 0, -4], [0, 0, 0], DRUM_RADIUS_MM, joints);

    // The Atom sits on the last link; its LED matrix faces out.
    const atomAt = this.frames[4];
    box(atomAt, [10, 24, 24], [DRUM_RADIUS_MM + 5, 0, model.d_mm[5] / 2], material(0x202226));
    this.led = new THREE.MeshStandardMaterial({ color: 0x111111, emissive: 0x000000, roughness: 0.4 });
    box(atomAt, [2, 20, 20], [DRUM_RADIUS_MM + 11, 0, model.d_mm[5] / 2], this.led);

    // The gripper: a palm on the flange and two fingers that open along the flange's y axis.
    const steel = material(GRIPPER_COLOUR);
    box(flange, [36, 56, 18], [0, 0, 9], steel);
    this.fingers = [1, -1].map((side) => ({ side, mesh: box(flange, [14, 6, 40], [0, 0, 38], steel) }));

    // The tool frame, when one is set: axes at the tool tip and a line to it from the flange.
    this.tool = new THREE.Group();
    this.tool.matrixAutoUpdate = false;
    this.tool.add(new THREE.AxesHelper(50).setColors(...AXIS_COLOURS));
    flange.add(this.tool);
    this.toolLine = new THREE.Line(
      new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3()]),
      new THREE.LineDashedMaterial({ color: 0xe0e0e0, dashSize: 6, gapSize: 4 }),
    );
    flange.add(this.toolLine);
    this.tool.visible = this.toolLine.visible = false;

    this.pose({ angles_deg: [0, 0, 0, 0, 0, 0], gripper: 0, led: [0, 0, 0], tool: null, end: 'flange' });
  }

  // Poses the arm as a state message says (angles, gripper opening, LED colour, tool frame,
  // the joint of a collision).
  pose(state) {
    const m = this.model;
    state.angles_deg.forEach((q, i) => {
      const theta = (q + m.theta_offset_deg[i]) * DEG;
      this.frames[i].matrix.copy(linkMatrix(m.d_mm[i], m.a_mm[i], m.alpha_deg[i] * DEG, theta));
      this.frames[i].matrixWorldNeedsUpdate = true;
    });
    const gap = (Math.min(Math.max(state.gripper, 0), 100) / 100) * GRIPPER_SPAN_MM;
    for (const { side, mesh } of this.fingers) mesh.position.y = side * (gap / 2 + 3);
    const [r, g, b] = state.led;
    this.led.emissive.setRGB(r / 255, g / 255, b / 255, THREE.SRGBColorSpace);
    this.showTool(state.tool, state.end === 'tool');
    // The drum of a joint the Atom detected a collision on turns red until it is cleared.
    this.drums.forEach((drum, j) => {
      drum.material = state.collision?.joint === j + 1 ? this.hitMaterial : this.jointMaterial;
    });
    this.root.updateMatrixWorld(true);
  }

  showTool(tool, active) {
    const shown = tool !== null && tool !== undefined;
    this.tool.visible = this.toolLine.visible = shown;
    if (!shown) return;
    const [x, y, z, rx, ry, rz] = tool;
    // R = Rz(rz) Ry(ry) Rx(rx): three.js's 'ZYX' Euler order.
    const rotation = new THREE.Matrix4().makeRotationFromEuler(new THREE.Euler(rx * DEG, ry * DEG, rz * DEG, 'ZYX'));
    this.tool.matrix.makeTranslation(x, y, z).multiply(rotation);
    this.tool.matrixWorldNeedsUpdate = true;
    this.toolLine.geometry.setFromPoints([new THREE.Vector3(), new THREE.Vector3(x, y, z)]);
    this.toolLine.computeLineDistances();
    this.toolLine.material.opacity = active ? 1 : 0.5;
    this.toolLine.material.transparent = !active;
  }

  // Where the drawn flange is in the base frame, mm.
  flangeMm() {
    return new THREE.Vector3().setFromMatrixPosition(this.frames[5].matrixWorld);
  }
}
