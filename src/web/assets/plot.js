// A small live plot of the six joint angles over the last seconds, on a 2D canvas.

// One colour per joint, also used for the joint names in the readout.
export const JOINT_COLOURS = ['#ff6b6b', '#ffd166', '#06d6a0', '#4cc9f0', '#b388ff', '#f4f4f4'];

const RANGE_DEG = 180;

export class AnglePlot {
  // `canvas`: where to draw; `seconds`: how much history to show.
  constructor(canvas, seconds = 10) {
    this.canvas = canvas;
    this.context = canvas.getContext('2d');
    this.seconds = seconds;
    this.samples = []; // {t, angles}, oldest first
    this.full = false; // whether samples older than the window were dropped
    this.changedAt = 0; // robot time of the last change of the angles
  }

  // Adds the angles at robot time `t` (s); tells whether the plot now looks different. It
  // does not once it is full of one unchanging pose (an arm at rest for the whole window).
  // A robot that restarted (time went back) starts a fresh plot.
  push(t, angles) {
    const last = this.samples[this.samples.length - 1];
    if (last && t < last.t) {
      this.samples = [];
      this.full = false;
    }
    if (!last || t < last.t || angles.some((a, j) => a !== last.angles[j])) this.changedAt = t;
    this.samples.push({ t, angles });
    const oldest = t - this.seconds;
    let drop = 0;
    while (drop < this.samples.length && this.samples[drop].t < oldest) drop++;
    if (drop > 0) {
      this.samples.splice(0, drop);
      this.full = true;
    }
    return !(this.full && t - this.changedAt > this.seconds);
  }

  draw() {
    const { canvas, context: g, samples } = this;
    const ratio = window.devicePixelRatio || 1;
    const w = canvas.clientWidth;
    const h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * ratio)) {
      canvas.width = Math.round(w * ratio);
      canvas.height = Math.round(h * ratio);
    }
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    g.clearRect(0, 0, w, h);
    const y = (deg) => h / 2 - (deg / RANGE_DEG) * (h / 2 - 4);
    g.strokeStyle = '#3a414a';
    g.fillStyle = '#7d8792';
    g.font = '10px system-ui, sans-serif';
    g.lineWidth = 1;
    for (const deg of [-90, 0, 90]) {
      g.beginPath();
      g.moveTo(0, y(deg) + 0.5);
      g.lineTo(w, y(deg) + 0.5);
      g.stroke();
      g.fillText(`${deg}\u00b0`, 2, y(deg) - 2);
    }
    g.fillText(`last ${this.seconds} s`, w - 52, h - 3);
    if (samples.length < 2) return;
    const now = samples[samples.length - 1].t;
    const x = (t) => w - ((now - t) / this.seconds) * w;
    g.lineWidth = 1.5;
    JOINT_COLOURS.forEach((colour, j) => {
      g.strokeStyle = colour;
      g.beginPath();
      samples.forEach((s, i) => (i === 0 ? g.moveTo : g.lineTo).call(g, x(s.t), y(s.angles[j])));
      g.stroke();
    });
  }
}
