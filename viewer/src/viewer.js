// nhdyn view: the page's app. Reads window.NHDYN_DATA (schema: viewer/README.md), shows the
// robot (urdf-loader on three.js), its runs (base trace, task path and reference, time
// slider, play/pause, speed, joint and eta values, error and tau plots) and exposes
// window.nhdyn for the browser test.
//
// Frames: the three.js world IS the URDF's world (metres, z up by default): nothing is
// rotated; the camera's `up` is the world's up, so link poses are read off matrixWorld as
// they are.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { STLLoader } from 'three/examples/jsm/loaders/STLLoader.js';
import { ColladaLoader } from 'three/examples/jsm/loaders/ColladaLoader.js';
import { OBJLoader } from 'three/examples/jsm/loaders/OBJLoader.js';
import URDFLoader from 'urdf-loader';

const PALETTE = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2',
  '#7f7f7f', '#bcbd22', '#17becf', '#393b79', '#637939', '#8c6d31', '#843c39', '#7b4173',
  '#3182bd', '#e6550d', '#31a354', '#756bb1', '#636363'];
const TRACE_COLOR = 0xe8402a;      // the base's trace up to the current time
const TRACE_DIM = 0xe9b3aa;        // the whole trace
const PATH_COLOR = 0xff8c00;       // the task point r(t)
const REF_COLOR = 0x1f5fd6;        // its reference r_d(t)
const BLANK_PNG = 'data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8/5+hHgAHggJ/PchI7wAAAABJRU5ErkJggg==';

// ---------------------------------------------------------------------------------------
// window.nhdyn: created at once, so a test can wait on `ready` whatever happens next.

let resolveReady, rejectReady;
const api = {
  version: 1,
  ready: new Promise((res, rej) => { resolveReady = res; rejectReady = rej; }),
  errors: [],      // problems that make the page wrong (bad data, exceptions)
  notices: [],     // things shown on the notice line (meshes not embedded, ...)
  timings: { bundleStart: performance.now() },   // ms since navigation start
  setTime: () => { throw new Error('nhdyn: not ready'); },
  linkPoses: () => { throw new Error('nhdyn: not ready'); },
};
window.nhdyn = api;
api.ready.catch(() => {});  // rejections are reported through errors and the console

function fail(message) {
  api.errors.push(message);
  console.error('nhdyn view: ' + message);
}

window.addEventListener('error', (e) => { api.errors.push(String(e.message || e)); });

// ---------------------------------------------------------------------------------------
// Small helpers

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) if (c != null) e.append(c);
  return e;
}

function b64ToBytes(s) {
  const bin = atob(s);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

function mimeOf(path) {
  const ext = path.split(/[?#]/)[0].split('.').pop().toLowerCase();
  return { png: 'image/png', jpg: 'image/jpeg', jpeg: 'image/jpeg', tga: 'image/x-tga',
    bmp: 'image/bmp', gif: 'image/gif', webp: 'image/webp' }[ext] || 'application/octet-stream';
}

// Largest i with t[i] <= x (0 if x < t[0]).
function lowerIndex(t, x) {
  let lo = 0, hi = t.length - 1;
  if (!(x >= t[0])) return 0;
  if (x >= t[hi]) return hi;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (t[mid] <= x) lo = mid; else hi = mid;
  }
  return lo;
}

// Row of `rows` at time x: the sample itself when x is a sample time (bit for bit), else the
// linear interpolation between the two samples around x; clamped to the ends.
function rowAt(t, rows, x) {
  const n = t.length;
  if (!rows || rows.length === 0) return null;
  if (n === 1 || !(x > t[0])) return rows[0];
  if (x >= t[n - 1]) return rows[n - 1];
  const i = lowerIndex(t, x);
  if (t[i] === x) return rows[i];
  const a = (x - t[i]) / (t[i + 1] - t[i]);
  const r0 = rows[i], r1 = rows[i + 1];
  if (typeof r0 === 'number') return r0 + a * (r1 - r0);
  return r0.map((v, k) => v + a * (r1[k] - v));
}

function fmt(v, digits = 4) {
  if (v == null || !Number.isFinite(v)) return '—';
  const s = v.toFixed(digits);
  return s === '-' + (0).toFixed(digits) ? (0).toFixed(digits) : s;
}

function niceTime(t) { return t.toFixed(t >= 100 ? 1 : 2); }

// ---------------------------------------------------------------------------------------
// Data checks: wrong data is an error with a message naming the field.

function checkData(d) {
  const problems = [];
  if (!d || typeof d !== 'object') return ['window.NHDYN_DATA is missing (the page was written without data)'];
  if (d.version !== 1) problems.push(`NHDYN_DATA.version is ${JSON.stringify(d.version)}, this page reads version 1`);
  const r = d.robot;
  if (!r || typeof r.urdf !== 'string') problems.push('NHDYN_DATA.robot.urdf (the URDF text) is missing');
  if (!r || !Array.isArray(r.joint_names)) problems.push('NHDYN_DATA.robot.joint_names is missing');
  if (!Array.isArray(d.runs) || d.runs.length === 0) problems.push('NHDYN_DATA.runs is empty');
  if (problems.length) return problems;
  const n = r.joint_names.length;
  d.runs.forEach((run, k) => {
    const where = `runs[${k}] ('${run.name}')`;
    if (!Array.isArray(run.t) || run.t.length === 0) { problems.push(`${where}: t is empty`); return; }
    if (!Array.isArray(run.q) || run.q.length !== run.t.length) {
      problems.push(`${where}: q has ${run.q ? run.q.length : 0} rows for ${run.t.length} times`); return;
    }
    for (let i = 0; i < run.q.length; i++) {
      if (!Array.isArray(run.q[i]) || run.q[i].length !== n) {
        problems.push(`${where}: q[${i}] has ${run.q[i] ? run.q[i].length : 0} entries, robot.joint_names ${n}`); return;
      }
    }
    for (let i = 1; i < run.t.length; i++) {
      if (!(run.t[i] > run.t[i - 1])) { problems.push(`${where}: t is not increasing at ${i}`); return; }
    }
  });
  return problems;
}

// ---------------------------------------------------------------------------------------
// The robot: URDF text parsed by urdf-loader, meshes from the embedded base64 map.

function loadRobot(data, manager, missing) {
  const meshes = data.robot.meshes || {};
  const loader = new URDFLoader(manager);
  loader.parseCollision = false;
  loader.parseVisual = true;
  // package://pkg/rel resolves to itself, relative paths stay as written: the keys of the
  // meshes map are the URDF's filename attributes verbatim.
  loader.packages = (pkg) => 'package://' + pkg;
  loader.workingPath = '';
  loader.loadMeshCb = (path, mgr, material, done) => {
    const b64 = meshes[path];
    const ext = path.split(/[?#]/)[0].split('.').pop().toLowerCase();
    const standIn = (why) => {
      missing.push({ path, why });
      const g = new THREE.Group();
      g.userData.nhdynMissing = path;
      done(g);
    };
    if (b64 == null) return standIn('not in the page');
    try {
      const bytes = b64ToBytes(b64);
      if (ext === 'stl') {
        const geom = new STLLoader().parse(bytes.buffer);
        done(new THREE.Mesh(geom, material));
      } else if (ext === 'dae') {
        const text = new TextDecoder().decode(bytes);
        const base = path.slice(0, path.lastIndexOf('/') + 1);
        const dae = new ColladaLoader(mgr).parse(text, base);
        done(dae.scene);
      } else if (ext === 'obj') {
        const obj = new OBJLoader(mgr).parse(new TextDecoder().decode(bytes));
        obj.traverse((o) => { if (o.isMesh) o.material = material; });
        done(obj);
      } else {
        standIn(`.${ext} files are not read (only .stl, .dae, .obj)`);
      }
    } catch (e) {
      standIn('unreadable: ' + (e && e.message ? e.message : e));
    }
  };
  const robot = loader.parse(data.robot.urdf);
  if (!robot || !robot.isURDFRobot) throw new Error('the URDF text has no <robot> element');
  for (const j of Object.values(robot.joints)) j.ignoreLimits = true;  // show q as simulated
  return robot;
}

// A box of the link's inertia (the solid box with the same principal moments, products of
// inertia ignored) at its centre of mass, or a 5 cm cube at the visual's origin.
function addStandIns(robot) {
  const done = new Set();
  const groups = [];
  robot.traverse((o) => { if (o.userData.nhdynMissing) groups.push(o); });
  const material = new THREE.MeshPhongMaterial({ color: 0xa8adb5 });
  for (const g of groups) {
    let link = g.parent;
    while (link && !link.isURDFLink) link = link.parent;
    if (!link || done.has(link)) continue;
    done.add(link);
    const box = inertiaBox(link.inertial);
    if (box) {
      const m = new THREE.Mesh(new THREE.BoxGeometry(box[0], box[1], box[2]), material);
      const o = link.inertial.origin;
      m.position.set(o.xyz[0], o.xyz[1], o.xyz[2]);
      m.quaternion.setFromEuler(new THREE.Euler(o.rpy[0], o.rpy[1], o.rpy[2], 'ZYX'));
      m.userData.nhdynStandIn = true;
      link.add(m);
    } else {
      const m = new THREE.Mesh(new THREE.BoxGeometry(0.05, 0.05, 0.05), material);
      m.userData.nhdynStandIn = true;
      g.add(m);
    }
  }
}

function inertiaBox(inertial) {
  if (!inertial || !(inertial.mass > 0)) return null;
  const { ixx, iyy, izz } = inertial.inertia;
  const m = inertial.mass;
  const a2 = 6 * (iyy + izz - ixx) / m, b2 = 6 * (ixx + izz - iyy) / m, c2 = 6 * (ixx + iyy - izz) / m;
  if (!(a2 > 0 && b2 > 0 && c2 > 0)) return null;
  const s = [Math.sqrt(a2), Math.sqrt(b2), Math.sqrt(c2)];
  if (Math.max(...s) > 10) return null;
  return s.map((v) => Math.max(v, 0.01));
}

function hasVisualGeometry(robot) {
  let found = false;
  robot.traverse((o) => { if (o.isMesh && !o.userData.nhdynSkeleton) found = true; });
  return found;
}

// "Links between frames": a rod from each link's origin to each child joint's origin, a ball
// at every link frame, a short rod along each revolute axis. For DH models and presets
// (URDFs without visuals) and on demand.
function buildSkeleton(robot) {
  const offsets = [];
  let total = 0;
  for (const j of Object.values(robot.joints)) {
    const p = j.position.clone();
    offsets.push([j, p]);
    total += p.length();
  }
  const r = Math.min(0.03, Math.max(0.008, 0.03 * total));
  const rodMat = new THREE.MeshPhongMaterial({ color: 0x4a78c2 });
  const ballMat = new THREE.MeshPhongMaterial({ color: 0xf2a33a });
  const axisMat = new THREE.MeshPhongMaterial({ color: 0x2e4f86 });
  const parts = [];
  const tag = (m) => { m.userData.nhdynSkeleton = true; parts.push(m); return m; };
  const up = new THREE.Vector3(0, 1, 0);
  for (const [j, p] of offsets) {
    const len = p.length();
    if (len > 1e-9 && j.parent) {
      const rod = tag(new THREE.Mesh(new THREE.CylinderGeometry(r, r, len, 12), rodMat));
      rod.position.copy(p).multiplyScalar(0.5);
      rod.quaternion.setFromUnitVectors(up, p.clone().normalize());
      j.parent.add(rod);
    }
    if ((j.jointType === 'revolute' || j.jointType === 'continuous') && j.axis) {
      const ax = tag(new THREE.Mesh(new THREE.CylinderGeometry(1.3 * r, 1.3 * r, 5 * r, 16), axisMat));
      ax.quaternion.setFromUnitVectors(up, j.axis.clone().normalize());
      j.add(ax);
    }
  }
  for (const link of Object.values(robot.links)) {
    link.add(tag(new THREE.Mesh(new THREE.SphereGeometry(1.6 * r, 16, 12), ballMat)));
  }
  return parts;
}

// ---------------------------------------------------------------------------------------
// Plots: hand-written canvas plots with a time cursor; click or drag to seek.

class Plot {
  constructor(parent, title, unit, onSeek) {
    this.title = title;
    this.unit = unit;
    this.series = [];
    this.hidden = new Set();
    this.cursorT = 0;
    this.onSeek = onSeek;
    this.root = el('div', { class: 'plot' });
    this.head = el('div', { class: 'plot-head' }, el('span', { class: 'plot-title', text: title }));
    this.readout = el('span', { class: 'plot-readout' });
    this.head.append(this.readout);
    this.canvas = el('canvas');
    this.legend = el('div', { class: 'legend' });
    this.root.append(this.head, this.canvas, this.legend);
    parent.append(this.root);
    this.cache = document.createElement('canvas');
    let dragging = false;
    const seek = (e) => {
      const rect = this.canvas.getBoundingClientRect();
      const x = (e.clientX - rect.left) / rect.width;
      const { x0, x1 } = this.frame || {};
      if (x0 === undefined) return;
      const px = x * this.cssW;
      const tt = this.t0 + (px - x0) / (x1 - x0) * (this.t1 - this.t0);
      this.onSeek(Math.min(this.t1, Math.max(this.t0, tt)));
    };
    this.canvas.addEventListener('pointerdown', (e) => { dragging = true; this.canvas.setPointerCapture(e.pointerId); seek(e); });
    this.canvas.addEventListener('pointermove', (e) => { if (dragging) seek(e); });
    this.canvas.addEventListener('pointerup', () => { dragging = false; });
  }

  // series: [{name, color, t, y, width, alpha, legend}]
  set(series, t0, t1) {
    this.series = series;
    this.t0 = t0; this.t1 = t1 > t0 ? t1 : t0 + 1;
    this.legend.textContent = '';
    const named = series.filter((s) => s.legend);
    for (const s of named) {
      const item = el('span', { class: 'legend-item' + (this.hidden.has(s.name) ? ' off' : ''), title: 'show / hide' },
        el('i', { style: `background:${s.color}` }), s.name);
      item.addEventListener('click', () => {
        if (this.hidden.has(s.name)) this.hidden.delete(s.name); else this.hidden.add(s.name);
        item.classList.toggle('off');
        this.redraw();
      });
      this.legend.append(item);
    }
    this.legend.style.display = named.length > 1 ? '' : 'none';
    this.redraw();
  }

  redraw() {
    const dpr = window.devicePixelRatio || 1;
    const cssW = this.canvas.clientWidth || 300, cssH = this.canvas.clientHeight || 110;
    this.cssW = cssW;
    for (const c of [this.canvas, this.cache]) { c.width = Math.round(cssW * dpr); c.height = Math.round(cssH * dpr); }
    const g = this.cache.getContext('2d');
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, cssW, cssH);
    const visible = this.series.filter((s) => !this.hidden.has(s.name));
    let lo = Infinity, hi = -Infinity;
    for (const s of visible) for (const v of s.y) if (Number.isFinite(v)) { if (v < lo) lo = v; if (v > hi) hi = v; }
    if (!Number.isFinite(lo)) { lo = 0; hi = 1; }
    const nonNegative = lo >= 0;
    if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) { hi += 0.5 * Math.max(1e-9, Math.abs(hi)); lo -= 0.5 * Math.max(1e-9, Math.abs(lo)); }
    const pad = 0.06 * (hi - lo); lo = nonNegative ? Math.max(0, lo - pad) : lo - pad; hi += pad;
    g.font = '10px system-ui, sans-serif';
    const labelW = Math.max(g.measureText(this.label(hi)).width, g.measureText(this.label(lo)).width) + 6;
    const x0 = labelW, x1 = cssW - 4, y0 = 4, y1 = cssH - 14;
    this.frame = { x0, x1, y0, y1, lo, hi };
    g.strokeStyle = '#c9ced6'; g.lineWidth = 1;
    g.strokeRect(x0 + 0.5, y0 + 0.5, x1 - x0, y1 - y0);
    if (lo < 0 && hi > 0) {
      const yz = Math.round(this.Y(0)) + 0.5;
      g.strokeStyle = '#e3e6ea'; g.beginPath(); g.moveTo(x0, yz); g.lineTo(x1, yz); g.stroke();
    }
    g.fillStyle = '#5b6470'; g.textAlign = 'right'; g.textBaseline = 'top';
    g.fillText(this.label(hi), x0 - 3, y0);
    g.textBaseline = 'bottom'; g.fillText(this.label(lo), x0 - 3, y1);
    g.textAlign = 'left'; g.textBaseline = 'top'; g.fillText(niceTime(this.t0) + ' s', x0, y1 + 2);
    g.textAlign = 'right'; g.fillText(niceTime(this.t1) + ' s', x1, y1 + 2);
    g.save();
    g.beginPath(); g.rect(x0, y0, x1 - x0, y1 - y0); g.clip();
    for (const s of visible) this.line(g, s);
    g.restore();
    this.cursor(this.cursorT);
  }

  label(v) {
    const a = Math.abs(v);
    const s = a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(1) : v.toPrecision(3);
    return s + (this.unit ? ' ' + this.unit : '');
  }

  X(t) { const f = this.frame; return f.x0 + (t - this.t0) / (this.t1 - this.t0) * (f.x1 - f.x0); }
  Y(v) { const f = this.frame; return f.y1 - (v - f.lo) / (f.hi - f.lo) * (f.y1 - f.y0); }

  // One series; more samples than pixels: the min and max of each pixel column.
  line(g, s) {
    g.strokeStyle = s.color; g.globalAlpha = s.alpha ?? 1; g.lineWidth = s.width ?? 1.2;
    g.beginPath();
    const n = s.t.length, w = this.frame.x1 - this.frame.x0;
    if (n > 2 * w) {
      let col = -1, mn = 0, mx = 0, first = true;
      const flush = () => {
        if (col < 0) return;
        const x = this.frame.x0 + col + 0.5;
        if (first) { g.moveTo(x, this.Y(mx)); first = false; } else g.lineTo(x, this.Y(mx));
        g.lineTo(x, this.Y(mn));
      };
      for (let i = 0; i < n; i++) {
        const v = s.y[i];
        if (!Number.isFinite(v)) continue;
        const c = Math.floor(this.X(s.t[i]) - this.frame.x0);
        if (c !== col) { flush(); col = c; mn = mx = v; } else { if (v < mn) mn = v; if (v > mx) mx = v; }
      }
      flush();
    } else {
      let pen = false;
      for (let i = 0; i < n; i++) {
        const v = s.y[i];
        if (!Number.isFinite(v)) { pen = false; continue; }
        const x = this.X(s.t[i]), y = this.Y(v);
        if (pen) g.lineTo(x, y); else { g.moveTo(x, y); pen = true; }
      }
    }
    g.stroke();
    g.globalAlpha = 1;
  }

  cursor(t) {
    this.cursorT = t;
    if (!this.frame) return;
    const g = this.canvas.getContext('2d');
    const dpr = window.devicePixelRatio || 1;
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.clearRect(0, 0, this.canvas.width, this.canvas.height);
    g.drawImage(this.cache, 0, 0);
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    const x = Math.round(this.X(Math.min(this.t1, Math.max(this.t0, t)))) + 0.5;
    g.strokeStyle = '#d62728'; g.lineWidth = 1;
    g.beginPath(); g.moveTo(x, this.frame.y0); g.lineTo(x, this.frame.y1); g.stroke();
    const main = this.series.find((s) => s.main && !this.hidden.has(s.name));
    if (main) {
      const v = rowAt(main.t, main.y, t);
      this.readout.textContent = v == null ? '' : this.label(v);
    } else this.readout.textContent = '';
  }
}

// ---------------------------------------------------------------------------------------
// The app

function main() {
  const data = window.NHDYN_DATA;
  api.timings.main = performance.now();
  const problems = checkData(data);
  buildPage(data);
  if (problems.length) {
    problems.forEach(fail);
    showNotice(problems[0], problems.join('\n'), true);
    rejectReady(new Error(problems.join('; ')));
    return;
  }
  try {
    start(data);
  } catch (e) {
    fail((e && e.stack) || String(e));
    showNotice('The page could not show the robot: ' + (e && e.message ? e.message : e), '', true);
    rejectReady(e);
  }
}

const ui = {};

function buildPage(data) {
  document.body.textContent = '';
  ui.view = el('div', { id: 'view' });
  ui.title = el('div', { id: 'title' });
  ui.notice = el('div', { id: 'notice', hidden: '' });
  ui.view.append(ui.title, ui.notice);
  ui.panel = el('aside', { id: 'panel' });
  ui.bar = el('div', { id: 'bar' });
  document.body.append(el('div', { id: 'app' }, ui.view, ui.panel, ui.bar));
  document.title = (data && data.title) || ((data && data.robot && data.robot.name ? data.robot.name + ' — ' : '') + 'nhdyn view');
}

function showNotice(text, detail, isError) {
  ui.notice.hidden = false;
  ui.notice.textContent = text;
  ui.notice.title = detail || text;
  ui.notice.classList.toggle('error', !!isError);
}

function start(data) {
  const runs = data.runs;
  const jointNames = data.robot.joint_names;
  const base = data.robot.base || { planar: false, joints: null };
  const up = new THREE.Vector3(...(data.up || [0, 0, 1])).normalize();
  const h1 = Math.abs(up.x) < 0.9 ? new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 1, 0);   // floor axes
  h1.addScaledVector(up, -h1.dot(up)).normalize();
  const h2 = new THREE.Vector3().crossVectors(up, h1);

  // --- three.js scene -----------------------------------------------------------------
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xeef1f5);
  const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 500);
  camera.up.copy(up);
  let renderer = null;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true });
  } catch (e) {
    fail('WebGL is not available: ' + (e && e.message ? e.message : e));
  }
  api.timings.rendererCreated = performance.now();
  if (renderer) {
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    ui.view.prepend(renderer.domElement);
  }

  const hemi = new THREE.HemisphereLight(0xffffff, 0x8a8f99, 1.5);
  hemi.position.copy(up);
  scene.add(hemi);
  const sun = new THREE.DirectionalLight(0xffffff, 1.3);
  scene.add(sun, sun.target);

  // --- robot --------------------------------------------------------------------------
  // Loading: embedded meshes parse synchronously; only textures (data: URLs) load later.
  let busy = false, whenIdle = null;
  const manager = new THREE.LoadingManager();
  manager.onStart = () => { busy = true; };
  manager.onLoad = () => { busy = false; needsRender = true; if (whenIdle) whenIdle(); };
  manager.onError = (url) => { api.notices.push('could not load ' + url.slice(0, 80)); };
  const meshes = data.robot.meshes || {};
  manager.setURLModifier((url) => {
    // Textures named by a mesh or a <material>: from the embedded map, never fetched.
    if (url.startsWith('data:') || url.startsWith('blob:')) return url;
    if (meshes[url] != null) return `data:${mimeOf(url)};base64,${meshes[url]}`;
    missingMeshes.push({ path: url, why: 'texture not in the page' });
    return BLANK_PNG;
  });
  const missingMeshes = [];
  api.timings.sceneStart = performance.now();
  const robot = loadRobot(data, manager, missingMeshes);
  api.timings.robotLoaded = performance.now();
  scene.add(robot);
  addStandIns(robot);
  const noVisuals = !hasVisualGeometry(robot);
  const skeleton = buildSkeleton(robot);

  for (const [name, value] of Object.entries(data.robot.locked || {})) {
    if (robot.joints[name]) robot.joints[name].setJointValue(value);
    else api.notices.push(`locked joint '${name}' is not in the URDF`);
  }

  // q's entries: the planar base's three go to the root link, the rest to URDF joints.
  const baseSlots = { x: -1, y: -1, heading: -1 };
  const jointSlots = [];
  const unknown = [];
  jointNames.forEach((name, i) => {
    if (base.planar && base.joints && base.joints.indexOf(name) >= 0) {
      baseSlots[['x', 'y', 'heading'][base.joints.indexOf(name)]] = i;
    } else if (robot.joints[name]) {
      jointSlots.push([robot.joints[name], i]);
    } else unknown.push(name);
  });
  if (base.planar && (baseSlots.x < 0 || baseSlots.y < 0 || baseSlots.heading < 0)) {
    throw new Error(`robot.base.planar is true but robot.base.joints ${JSON.stringify(base.joints)} are not three names of robot.joint_names`);
  }
  if (unknown.length) {
    api.notices.push(`q entries not in the URDF (not shown): ${unknown.join(', ')}`);
    console.warn('nhdyn view: q entries not in the URDF: ' + unknown.join(', '));
  }

  const zAxis = new THREE.Vector3(0, 0, 1);
  function applyQ(q) {
    if (base.planar) {
      robot.position.set(q[baseSlots.x], q[baseSlots.y], 0);
      robot.quaternion.setFromAxisAngle(zAxis, q[baseSlots.heading]);
    }
    for (const [joint, i] of jointSlots) joint.setJointValue(q[i]);
    robot.updateMatrixWorld(true);
  }

  // The link whose origin draws the trace: the root of a planar base, else the child link of
  // the heading joint (URDFs that carry their own base joints), else robot.base.link.
  let traceLink = null;
  if (base.link && robot.links[base.link]) traceLink = robot.links[base.link];
  else if (base.planar) traceLink = robot;
  else if (base.joints && robot.joints[base.joints[2]]) {
    traceLink = robot.joints[base.joints[2]].children.find((c) => c.isURDFLink) || null;
  }

  function baseWorld(out) {
    if (!traceLink) return out.set(0, 0, 0);
    return traceLink.getWorldPosition(out);
  }
  const onFloor = (p) => p.addScaledVector(up, -p.dot(up));

  // --- per-run geometry: trace, task path, reference -----------------------------------
  const runColor = (k) => new THREE.Color(PALETTE[k % PALETTE.length]);
  const world = new THREE.Group();
  scene.add(world);
  const lift = up.clone().multiplyScalar(0.002);   // lines just above the grid

  function traceOf(run) {
    if (run._trace !== undefined) return run._trace;
    if (!traceLink || run.t.length < 2) return (run._trace = null);
    const pts = new Float32Array(run.t.length * 3);
    const p = new THREE.Vector3();
    for (let i = 0; i < run.t.length; i++) {
      if (base.planar) p.set(run.q[i][baseSlots.x], run.q[i][baseSlots.y], 0);
      else { applyQ(run.q[i]); onFloor(baseWorld(p)); }
      p.add(lift);
      pts[3 * i] = p.x; pts[3 * i + 1] = p.y; pts[3 * i + 2] = p.z;
    }
    return (run._trace = pts);
  }

  function lineOf(points, material) {
    const g = new THREE.BufferGeometry();
    const arr = points instanceof Float32Array ? points : new Float32Array(points.flat());
    g.setAttribute('position', new THREE.BufferAttribute(arr, 3));
    const l = new THREE.Line(g, material);
    l.frustumCulled = false;
    return l;
  }

  // The trace as a flat ribbon on the floor (WebGL lines are one pixel wide); drawRange
  // 6 k shows it up to sample k.
  applyQ(runs[0].q[0]);
  const robotSize = new THREE.Box3().setFromObject(robot).getSize(new THREE.Vector3()).length() || 1;
  const ribbonWidth = Math.min(0.05, Math.max(0.008, 0.012 * robotSize));
  function ribbonOf(pts, material) {
    const n = pts.length / 3;
    const pos = new Float32Array(n * 6);
    const idx = [];
    const p = new THREE.Vector3(), a = new THREE.Vector3(), b = new THREE.Vector3(), d = new THREE.Vector3();
    const side = new THREE.Vector3().crossVectors(up, h1).normalize();
    for (let i = 0; i < n; i++) {
      a.fromArray(pts, 3 * Math.max(0, i - 1)); b.fromArray(pts, 3 * Math.min(n - 1, i + 1));
      d.subVectors(b, a);
      const s2 = new THREE.Vector3().crossVectors(up, d);
      if (s2.lengthSq() > 1e-16) side.copy(s2.normalize());
      p.fromArray(pts, 3 * i);
      p.addScaledVector(side, ribbonWidth / 2).toArray(pos, 6 * i);
      p.addScaledVector(side, -ribbonWidth).toArray(pos, 6 * i + 3);
      if (i + 1 < n) idx.push(2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 1, 2 * i + 3, 2 * i + 2);
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setIndex(idx);
    const m = new THREE.Mesh(g, material);
    m.frustumCulled = false;
    return m;
  }
  const basic = (color, opacity = 1) => new THREE.MeshBasicMaterial({ color, side: THREE.DoubleSide,
    transparent: opacity < 1, opacity, depthWrite: opacity >= 1 });

  const runObjects = runs.map((run, k) => {
    const o = { group: new THREE.Group(), trace: null, traceNow: null, path: null, ref: null };
    const tr = traceOf(run);
    if (tr) {
      o.trace = ribbonOf(tr, basic(TRACE_DIM));
      o.traceNow = ribbonOf(tr, basic(TRACE_COLOR));
      o.traceNow.renderOrder = 1;
      o.traceNow.position.addScaledVector(up, 0.0005);
      o.overlay = ribbonOf(tr, basic(runColor(k), 0.7));
      o.group.add(o.trace, o.traceNow);
    }
    const task = run.task || {};
    if (Array.isArray(task.reference) && task.reference.length > 1) {
      o.ref = lineOf(task.reference, new THREE.MeshBasicMaterial({ side: THREE.DoubleSide, color: REF_COLOR }));
      o.group.add(o.ref);
    }
    if (Array.isArray(task.path) && task.path.length > 1) {
      o.path = lineOf(task.path, new THREE.MeshBasicMaterial({ side: THREE.DoubleSide, color: PATH_COLOR }));
      o.pathOverlay = lineOf(task.path, new THREE.MeshBasicMaterial({ side: THREE.DoubleSide, color: runColor(k), transparent: true, opacity: 0.6 }));
      o.group.add(o.path);
    }
    world.add(o.group);
    return o;
  });
  const overlayGroup = new THREE.Group();
  runObjects.forEach((o) => { if (o.overlay) overlayGroup.add(o.overlay); if (o.pathOverlay) overlayGroup.add(o.pathOverlay); });
  world.add(overlayGroup);

  // Unlit markers without normals: the same shader program as every line and ribbon.
  const ball = (r) => { const g = new THREE.SphereGeometry(r, 16, 12); g.deleteAttribute('normal'); g.deleteAttribute('uv'); return g; };
  const markerR = new THREE.Mesh(ball(0.018), new THREE.MeshBasicMaterial({ color: PATH_COLOR, side: THREE.DoubleSide }));
  const markerRd = new THREE.Mesh(ball(0.012), new THREE.MeshBasicMaterial({ color: REF_COLOR, side: THREE.DoubleSide }));
  world.add(markerR, markerRd);

  // --- floor, axes, initial camera ------------------------------------------------------
  // Everything the camera should see: the robot at a few times of each run, traces, paths.
  const bounds = new THREE.Box3();
  runs.slice(0, 8).forEach((run) => {
    const n = run.t.length;
    for (let k = 0; k < Math.min(n, 9); k++) {
      applyQ(run.q[Math.round(k * (n - 1) / Math.max(1, Math.min(n, 9) - 1))]);
      bounds.union(new THREE.Box3().setFromObject(robot));
    }
  });
  applyQ(runs[0].q[0]);
  for (const run of runs) {
    const tr = traceOf(run);
    if (tr) for (let i = 0; i < tr.length; i += 3) bounds.expandByPoint(new THREE.Vector3(tr[i], tr[i + 1], tr[i + 2]));
    for (const key of ['path', 'reference']) {
      const pts = run.task && run.task[key];
      if (Array.isArray(pts)) for (const p of pts) if (p && p.every(Number.isFinite)) bounds.expandByPoint(new THREE.Vector3(...p));
    }
  }
  if (bounds.isEmpty()) bounds.set(new THREE.Vector3(-0.5, -0.5, 0), new THREE.Vector3(0.5, 0.5, 1));
  const center = bounds.getCenter(new THREE.Vector3());
  const radius = Math.max(0.3, bounds.getSize(new THREE.Vector3()).length() / 2);

  // Floor grid (0.25 m cells, 1 m lines darker) and the world axes, in plain line
  // materials (one shader program for every line and ribbon: fewer programs, faster start).
  const half = Math.ceil(radius + 1);
  const gc = onFloor(center.clone());
  const g0 = new THREE.Vector3().addScaledVector(h1, Math.round(gc.dot(h1))).addScaledVector(h2, Math.round(gc.dot(h2)));
  const minor = [], major = [];
  for (let k = -4 * half; k <= 4 * half; k++) {
    const list = k % 4 === 0 ? major : minor;
    for (const [u, v] of [[h1, h2], [h2, h1]]) {
      const a = g0.clone().addScaledVector(u, k / 4).addScaledVector(v, -half);
      const b = g0.clone().addScaledVector(u, k / 4).addScaledVector(v, half);
      list.push(a.x, a.y, a.z, b.x, b.y, b.z);
    }
  }
  const segs = (arr, color) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(arr), 3));
    return new THREE.LineSegments(g, new THREE.MeshBasicMaterial({ side: THREE.DoubleSide, color }));
  };
  const grid = new THREE.Group();
  grid.add(segs(minor, 0xd3d8de), segs(major, 0xa9b1bb));
  scene.add(grid);
  const axisLen = Math.min(0.3, radius * 0.3);
  const axes = new THREE.Group();
  [[1, 0, 0, 0xd62728], [0, 1, 0, 0x2ca02c], [0, 0, 1, 0x1f5fd6]].forEach(([x, y, z, c]) =>
    axes.add(segs([0, 0, 0, x * axisLen, y * axisLen, z * axisLen], c)));
  axes.position.copy(lift).multiplyScalar(2);
  scene.add(axes);

  const dir = new THREE.Vector3().addScaledVector(h1, 0.62).addScaledVector(h2, -0.78).addScaledVector(up, 0.55).normalize();
  camera.position.copy(center).addScaledVector(dir, radius * 2.7);
  camera.lookAt(center);
  sun.position.copy(center).addScaledVector(dir, 5).addScaledVector(up, 5);
  sun.target.position.copy(center);

  const st = { run: 0, t: runs[0].t[0], playing: false, speed: 1, follow: false, overlay: false, skeleton: noVisuals };
  let needsRender = true;
  let controls = null;
  if (renderer) {
    controls = new OrbitControls(camera, renderer.domElement);
    controls.target.copy(center);
    controls.enableDamping = false;
    controls.screenSpacePanning = true;
    controls.addEventListener('change', () => { needsRender = true; });
    controls.update();
  }

  // --- state ----------------------------------------------------------------------------
  const lastBase = new THREE.Vector3();
  const tmp = new THREE.Vector3();
  skeleton.forEach((m) => { m.visible = st.skeleton; });

  // --- the panel --------------------------------------------------------------------------
  const controlsBox = el('div', { class: 'box' });
  ui.panel.append(controlsBox);
  let runSelect = null;
  if (runs.length > 1) {
    runSelect = el('select', { id: 'run' });
    runs.forEach((r, k) => runSelect.append(el('option', { value: String(k), text: (r.success === false ? '✗ ' : '') + r.name })));
    runSelect.addEventListener('change', () => setRun(Number(runSelect.value)));
    controlsBox.append(el('label', { class: 'row' }, el('span', { text: 'run' }), runSelect));
  }
  const check = (label, key, onChange, title) => {
    const box = el('input', { type: 'checkbox', id: key });
    box.checked = st[key];
    box.addEventListener('change', () => { st[key] = box.checked; onChange(); needsRender = true; });
    controlsBox.append(el('label', { class: 'check', title: title || label }, box, label));
    return box;
  };
  if (runs.length > 1) check('overlay all runs', 'overlay', () => updateRunVisibility(), 'every run\'s base trace and task path, one colour per run');
  if (traceLink) check('follow base', 'follow', () => { baseWorld(lastBase); });
  check('frames', 'skeleton', () => skeleton.forEach((m) => { m.visible = st.skeleton; }), 'the links as rods between their frames');

  ui.legend = el('div', { class: 'keys' });
  if (traceLink) ui.legend.append(el('span', {}, el('i', { style: 'background:#e8402a' }), 'base trace'));
  if (runs.some((r) => r.task && r.task.path)) ui.legend.append(el('span', {}, el('i', { style: 'background:#ff8c00' }), 'task point r'));
  if (runs.some((r) => r.task && r.task.reference)) ui.legend.append(el('span', {}, el('i', { style: 'background:#1f5fd6' }), 'reference r_d'));
  controlsBox.append(ui.legend);

  const plotsBox = el('div', { class: 'box plots' });
  ui.panel.append(plotsBox);
  const seek = (t) => { pause(); setTime(t); };
  const hasCol = (key) => runs.some((r) => r.columns && Array.isArray(r.columns[key]) && r.columns[key].length);
  const errPlot = hasCol('error') ? new Plot(plotsBox, 'tracking error |r_d − r|', 'm', seek) : null;
  const tauPlot = hasCol('tau') ? new Plot(plotsBox, 'τ (applied)', '', seek) : null;

  const valuesBox = el('div', { class: 'box values' });
  ui.panel.append(valuesBox);
  const units = jointNames.map((name) => {
    if (base.planar && base.joints) {
      const k = base.joints.indexOf(name);
      if (k === 0 || k === 1) return 'm';
      if (k === 2) return 'rad';
    }
    const j = robot.joints[name];
    return j && j.jointType === 'prismatic' ? 'm' : 'rad';
  });
  const qCells = [];
  const qTable = el('table', {}, el('tr', {}, el('th', { text: 'q' }), el('th', { text: '' }), el('th', { text: '' })));
  jointNames.forEach((name, i) => {
    const v = el('td', { class: 'num' });
    qCells.push(v);
    qTable.append(el('tr', {}, el('td', { text: name }), v, el('td', { class: 'unit', text: units[i] })));
  });
  valuesBox.append(qTable);
  const etaTable = el('table');
  valuesBox.append(etaTable);
  let etaCells = [];
  function buildEtaTable() {
    etaTable.textContent = '';
    etaCells = [];
    const c = runs[st.run].columns || {};
    if (!Array.isArray(c.eta) || !c.eta.length) return;
    const names = c.eta_names || c.eta[0].map((_, i) => 'η' + (i + 1));
    etaTable.append(el('tr', {}, el('th', { text: 'η' }), el('th'), el('th')));
    names.forEach((name) => {
      const v = el('td', { class: 'num' });
      etaCells.push(v);
      etaTable.append(el('tr', {}, el('td', { text: name }), v, el('td', { class: 'unit' })));
    });
  }

  // --- the bar: play, slider, time, speed ---------------------------------------------
  const playBtn = el('button', { id: 'play', title: 'play / pause (space)', text: '▶' });
  const slider = el('input', { id: 'slider', type: 'range', step: 'any' });
  const timeLabel = el('span', { id: 'time' });
  const speedSel = el('select', { id: 'speed', title: 'playback speed' });
  for (const s of [0.1, 0.25, 0.5, 1, 2, 4, 10]) speedSel.append(el('option', { value: String(s), text: s + '×' }));
  speedSel.value = '1';
  ui.bar.append(playBtn, slider, timeLabel, speedSel);
  playBtn.addEventListener('click', () => (st.playing ? pause() : play()));
  slider.addEventListener('input', () => { pause(); setTime(Number(slider.value)); });
  speedSel.addEventListener('change', () => { st.speed = Number(speedSel.value); });
  window.addEventListener('keydown', (e) => {
    if (e.code === 'Space' && e.target === document.body) { e.preventDefault(); st.playing ? pause() : play(); }
  });

  function play() {
    const r = runs[st.run];
    if (r.t.length < 2) return;
    if (st.t >= r.t[r.t.length - 1]) setTime(r.t[0]);
    st.playing = true; playBtn.textContent = '❚❚'; lastFrame = performance.now();
  }
  function pause() { st.playing = false; playBtn.textContent = '▶'; }

  // --- run selection ---------------------------------------------------------------------
  function updateRunVisibility() {
    runObjects.forEach((o, k) => { o.group.visible = k === st.run; });
    overlayGroup.visible = st.overlay;
    const errSeries = [], tauSeries = [];
    const cur = runs[st.run];
    let t0 = cur.t[0], t1 = cur.t[cur.t.length - 1];
    runs.forEach((r, k) => {
      const c = r.columns || {};
      const isCur = k === st.run;
      if (!isCur && !st.overlay) return;
      t0 = Math.min(t0, r.t[0]); t1 = Math.max(t1, r.t[r.t.length - 1]);
      if (Array.isArray(c.error) && c.error.length) {
        errSeries.push({ name: r.name, t: r.t, y: c.error, color: isCur ? '#d62728' : PALETTE[k % PALETTE.length],
          alpha: isCur ? 1 : 0.55, width: isCur ? 1.6 : 1, main: isCur, legend: false });
      }
    });
    const c = cur.columns || {};
    if (Array.isArray(c.tau) && c.tau.length) {
      const names = c.tau_names || c.tau[0].map((_, i) => 'τ' + (i + 1));
      names.forEach((name, i) => tauSeries.push({ name, t: cur.t, y: c.tau.map((row) => row[i]),
        color: PALETTE[i % PALETTE.length], legend: true }));
    }
    if (errPlot) errPlot.set(errSeries.filter((s) => !s.main).concat(errSeries.filter((s) => s.main)), t0, t1);
    if (tauPlot) tauPlot.set(tauSeries, cur.t[0], cur.t[cur.t.length - 1]);
    needsRender = true;
  }

  function setRun(k) {
    if (!(k >= 0 && k < runs.length)) throw new Error(`nhdyn.setRun: no run ${k} (${runs.length} runs)`);
    st.run = k;
    if (runSelect) runSelect.value = String(k);
    const r = runs[k];
    slider.min = String(r.t[0]); slider.max = String(r.t[r.t.length - 1]);
    ui.bar.style.display = r.t.length > 1 ? '' : 'none';
    buildEtaTable();
    updateRunVisibility();
    setTime(Math.min(Math.max(st.t, r.t[0]), r.t[r.t.length - 1]));
    ui.title.textContent = (data.title || data.robot.name || 'robot') + (runs.length > 1 || r.t.length > 1 ? ' — ' + r.name : '');
  }

  // --- time --------------------------------------------------------------------------------
  function setTime(t) {
    const r = runs[st.run];
    if (!Number.isFinite(t)) throw new Error(`nhdyn.setTime: t = ${t} is not a number`);
    t = Math.min(Math.max(t, r.t[0]), r.t[r.t.length - 1]);
    st.t = t;
    const q = rowAt(r.t, r.q, t);
    applyQ(q);
    const i = lowerIndex(r.t, t);
    const o = runObjects[st.run];
    if (o.traceNow) o.traceNow.geometry.setDrawRange(0, 6 * i);
    const task = r.task || {};
    const rp = task.path ? rowAt(r.t, task.path, t) : null;
    const rd = task.reference ? rowAt(r.t, task.reference, t) : null;
    markerR.visible = !!(rp && rp.every(Number.isFinite));
    markerRd.visible = !!(rd && rd.every(Number.isFinite));
    if (markerR.visible) markerR.position.set(rp[0], rp[1], rp[2]);
    if (markerRd.visible) markerRd.position.set(rd[0], rd[1], rd[2]);
    if (st.follow && controls) {
      baseWorld(tmp);
      const d = tmp.clone().sub(lastBase);
      camera.position.add(d); controls.target.add(d); controls.update();
      lastBase.copy(tmp);
    }
    // panel
    q.forEach((v, k) => { qCells[k].textContent = fmt(v); });
    const c = r.columns || {};
    if (etaCells.length && Array.isArray(c.eta)) {
      const eta = rowAt(r.t, c.eta, t);
      etaCells.forEach((cell, k) => { cell.textContent = fmt(eta[k]); });
    }
    slider.value = String(t);
    timeLabel.textContent = `t = ${niceTime(t)} / ${niceTime(r.t[r.t.length - 1])} s`;
    if (errPlot) errPlot.cursor(t);
    if (tauPlot) tauPlot.cursor(t);
    render();
    return t;
  }

  // --- rendering ---------------------------------------------------------------------------
  function resize() {
    if (!renderer) return;
    const w = ui.view.clientWidth || 800, h = ui.view.clientHeight || 600;
    renderer.setSize(w, h, true);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    needsRender = true;
  }
  function render() {
    needsRender = false;
    if (renderer) renderer.render(scene, camera);
  }
  let lastFrame = performance.now();
  function frame(now) {
    if (st.playing) {
      const r = runs[st.run];
      const dt = Math.min(0.25, (now - lastFrame) / 1000) * st.speed;
      let t = st.t + dt;
      if (t > r.t[r.t.length - 1]) t = r.t[0];
      setTime(t);
    } else if (needsRender) render();
    lastFrame = now;
    requestAnimationFrame(frame);
  }
  window.addEventListener('resize', () => { resize(); if (errPlot) errPlot.redraw(); if (tauPlot) tauPlot.redraw(); render(); });

  // --- notices ----------------------------------------------------------------------------
  if (missingMeshes.length) {
    const uniq = [...new Map(missingMeshes.map((m) => [m.path, m])).values()];
    const text = `${uniq.length} mesh file${uniq.length > 1 ? 's' : ''} not in the page (${uniq[0].path}${uniq.length > 1 ? ', …' : ''}): drawn as stand-in boxes`;
    api.notices.unshift(text);
    console.warn('nhdyn view: meshes not in the page: ' + uniq.map((m) => `${m.path} (${m.why})`).join(', '));
    showNotice(text, uniq.map((m) => `${m.path}: ${m.why}`).join('\n'));
  } else if (api.notices.length) showNotice(api.notices[0], api.notices.join('\n'));
  if (!renderer) showNotice('WebGL is not available in this browser: no 3D view', '', true);

  // --- the test interface -------------------------------------------------------------------
  const reportNames = Array.isArray(data.link_names_to_report) && data.link_names_to_report.length
    ? data.link_names_to_report : Object.keys(robot.links);
  const missingReport = reportNames.filter((n) => !robot.links[n]);
  if (missingReport.length) fail(`link_names_to_report names links not in the URDF: ${missingReport.join(', ')}`);

  api.setTime = setTime;
  api.setRun = (k) => { setRun(k); return k; };
  api.play = play;
  api.pause = pause;
  api.linkPoses = () => {
    robot.updateMatrixWorld(true);
    const out = {};
    for (const n of reportNames) if (robot.links[n]) out[n] = Array.from(robot.links[n].matrixWorld.elements);
    return out;
  };
  api.q = () => rowAt(runs[st.run].t, runs[st.run].q, st.t).slice();
  api.state = () => ({
    run: st.run, runName: runs[st.run].name, t: st.t, playing: st.playing, follow: st.follow, overlay: st.overlay,
    skeleton: st.skeleton, webgl: !!renderer, links: Object.keys(robot.links).length,
    tracePoints: runObjects[st.run].traceNow ? runObjects[st.run].traceNow.geometry.drawRange.count / 6 : 0,
    standIns: (() => { let n = 0; robot.traverse((o) => { if (o.userData.nhdynStandIn) n++; }); return n; })(),
    notice: ui.notice.hidden ? '' : ui.notice.textContent,
    camera: { position: camera.position.toArray(), target: controls ? controls.target.toArray() : null },
    base: traceLink ? baseWorld(new THREE.Vector3()).toArray() : null,
  });
  api.render = render;
  // For tests and screenshots: show or hide parts of the scene ({robot, trace, task, grid}).
  api.setVisible = (parts) => {
    if ('robot' in parts) robot.visible = !!parts.robot;
    if ('trace' in parts) runObjects.forEach((o) => { for (const k of ['trace', 'traceNow']) if (o[k]) o[k].visible = !!parts.trace; });
    if ('task' in parts) { runObjects.forEach((o) => { for (const k of ['path', 'ref']) if (o[k]) o[k].visible = !!parts.task; }); markerR.visible = markerRd.visible = !!parts.task; }
    if ('grid' in parts) { grid.visible = axes.visible = !!parts.grid; }
    render();
  };
  api.renderInfo = () => (renderer ? { programs: renderer.info.programs.map((p) => p.cacheKey), calls: renderer.info.render.calls } : null);
  api.traceColor = '#' + new THREE.Color(TRACE_COLOR).getHexString();

  api.timings.built = performance.now();
  resize();
  setRun(0);
  api.timings.setRun = performance.now();
  setTime(runs[0].t[0]);
  api.timings.firstRender = performance.now();
  render();
  api.timings.secondRender = performance.now();
  requestAnimationFrame(frame);

  // Ready when the textures the loaders asked for (if any) have arrived.
  const finish = () => { render(); api.readyTime = performance.now(); resolveReady(api); };
  if (busy) whenIdle = finish; else finish();
}

main();
