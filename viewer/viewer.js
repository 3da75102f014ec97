// dcr viewer: plays glTF files written by `dcr-scenes run … --gltf` (runs side by side, response
// events from extras.dcr) and `modal-bake export … --gltf [--onto ASSET]` (one animation per
// mode: the label "mode N — F Hz", the physical time of the mode's own oscillation, and the
// fixed vertices as dark points).
// Static page; three.js comes bundled in vendor/ (no network at run time).
import {
  AmbientLight, AnimationMixer, ArrowHelper, Box3, BufferAttribute, BufferGeometry, Color, DirectionalLight,
  HemisphereLight, LoopRepeat, PerspectiveCamera, Points, PointsMaterial, Scene, SRGBColorSpace, Vector3,
  WebGLRenderer,
  GLTFLoader, OrbitControls,
} from 'three-bundle';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const view = $('view');

const renderer = new WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.outputColorSpace = SRGBColorSpace;
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setScissorTest(true);
view.appendChild(renderer.domElement);

const scene = new Scene();
scene.background = new Color(0xeef0f2);
scene.add(new HemisphereLight(0xffffff, 0x99aabb, 1.4));
scene.add(new AmbientLight(0xffffff, 0.3));
const sun = new DirectionalLight(0xffffff, 1.8);
sun.position.set(3, 6, 4);
scene.add(sun);

const camera = new PerspectiveCamera(35, 1, 0.01, 2000);
const viewCam = new PerspectiveCamera(35, 1, 0.01, 2000);
const controls = new OrbitControls(camera, renderer.domElement);
controls.addEventListener('change', () => requestRender());

const FLASH_S = 0.25; // flash of a body receiving a response (s of simulated time)
const ARROW_S = 0.12; // arrow shown for this long after the response (s)

const state = {
  kind: null, root: null, mixer: null, action: null, duration: 0, time: 0,
  playing: params.get('paused') !== '1', speed: Number($('speed').value), h: 0, rows: 0,
  sides: [], layout: params.get('layout') || 'split', left: null, right: null,
  markers: params.get('markers') !== '0', modes: [], name: '',
  modeInfo: [], mode: -1, period: 1, fixedCount: 0,
};
$('layout').value = state.layout;
$('markers').checked = state.markers;
if (params.get('speed')) { state.speed = Number(params.get('speed')); }

function clearModel() {
  if (state.root) scene.remove(state.root);
  for (const s of state.sides) for (const a of s.arrows) a.arrow.parent?.remove(a.arrow);
  Object.assign(state, {
    kind: null, root: null, mixer: null, action: null, duration: 0, time: 0, sides: [], modes: [],
    modeInfo: [], mode: -1, period: 1, fixedCount: 0,
  });
}

function sideOf(label) { return state.sides.find((s) => s.label === label) || state.sides[0]; }

// Frames the elastic and moving bodies under `obj` (static scenery such as a large ground
// plane is left out), or all of `obj` when it has none.
function frame(obj, offset) {
  const box = new Box3();
  obj.traverse((o) => {
    if (o.userData && (o.userData.elastic || o.userData.dynamic)) box.expandByObject(o);
  });
  if (box.isEmpty()) box.setFromObject(obj);
  const size = box.getSize(new Vector3());
  const center = box.getCenter(new Vector3());
  if (offset) center.sub(offset);
  const dim = Math.max(size.x, size.y * 1.4, size.z, 1e-3);
  const dist = (0.44 * dim) / Math.tan((camera.fov * Math.PI) / 360);
  const az = (Number(params.get('az') || 0) * Math.PI) / 180; // camera azimuth about +y (deg)
  const dir = new Vector3(Math.sin(az), 0.42, Math.cos(az)).normalize();
  camera.position.copy(center).addScaledVector(dir, dist);
  camera.near = dist / 100;
  camera.far = dist * 100;
  controls.target.copy(center);
  controls.update();
}

function setupScene(gltf, dcr) {
  const root = gltf.scene;
  state.kind = 'scene_run';
  state.h = dcr.h;
  state.rows = dcr.rows;
  for (const sd of dcr.sides) {
    const node = root.getObjectByName(sd.node);
    if (!node) throw new Error(`side node ${sd.node} missing`);
    const offset = new Vector3(...sd.offset);
    const bodies = new Map();
    node.traverse((o) => {
      if (o.isMesh && o.parent) {
        o.material = o.material.clone(); // own material: the flash is per body
        const body = o.userData.body ?? o.parent.userData.body;
        bodies.set(body ?? o.name, o);
      }
    });
    node.children.forEach((c) => {
      if (c.userData.body !== undefined) c.traverse((o) => { if (o.isMesh) bodies.set(c.userData.body, o); });
    });
    const events = (sd.events || []).slice(0, 4000);
    const maxJ = Math.max(1e-12, ...events.map((e) => Math.hypot(...e.impulse)));
    const arrows = events.map((e) => {
      const j = Math.hypot(...e.impulse);
      const dir = new Vector3(...e.impulse).normalize();
      const len = 0.05 + 0.25 * (j / maxJ);
      const arrow = new ArrowHelper(dir, new Vector3(...e.point), len, 0xff2222, 0.35 * len, 0.2 * len);
      arrow.traverse((o) => { if (o.material) { o.material.depthTest = false; o.renderOrder = 10; } });
      arrow.visible = false;
      node.add(arrow);
      return { arrow, time: e.time };
    });
    state.sides.push({ label: sd.label, dcr: sd.dcr, node, offset, bodies, events, arrows });
  }
  const labels = state.sides.map((s) => s.label);
  for (const id of ['left', 'right']) {
    $(id).innerHTML = labels.map((l) => `<option>${l}</option>`).join('');
  }
  state.left = labels.includes(params.get('left')) ? params.get('left') : labels[0];
  state.right = labels.includes(params.get('right')) ? params.get('right') : labels[Math.min(1, labels.length - 1)];
  $('left').value = state.left;
  $('right').value = state.right;
  const clip = gltf.animations.find((a) => a.name === 'run') || gltf.animations[0];
  state.mixer = new AnimationMixer(root);
  if (clip) {
    state.action = state.mixer.clipAction(clip);
    state.action.play();
    state.duration = clip.duration;
  }
  frame(sideOf(state.left).node, sideOf(state.left).offset);
  const ev = state.sides.map((s) => `${s.label}: ${s.events.length} responses`).join(', ');
  $('info').textContent = `${dcr.scene} — ${state.rows} rows, h = ${state.h} s; ${ev}`;
}

// "mode N — F Hz" (F: one decimal from 1 Hz, three significant digits below).
function modeTitle(i, hz) {
  return `mode ${i + 1} — ${hz >= 1 ? hz.toFixed(1) : hz.toPrecision(3)} Hz`;
}

// The fixed vertices (extras.dcr.fixed_vertices) as dark points on the surface mesh.
// The asset vertices a bake held fixed (extras.dcr.fixed_vertices: indices into the vertex list
// the reader appended, placement after placement) as red points on their meshes. With
// extras.dcr.placements (a glTF asset kept by `export --onto`) each index is found in its
// primitive through the loader's object ↔ glTF associations; else in the first mesh.
function showFixed(gltf, dcr) {
  const fixed = dcr.fixed_vertices;
  if (!fixed?.length) return 0;
  const meshes = [];
  gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
  const locate = (v) => {
    if (!dcr.placements) return [meshes[0], v];
    const p = dcr.placements.find((q) => v >= q.first_vertex && v < q.first_vertex + q.vertices);
    if (!p) return [null, v];
    const o = meshes.find((m) => {
      const a = gltf.parser.associations.get(m);
      return a && a.meshes === p.mesh && a.primitives === p.primitive;
    });
    return [o, v - p.first_vertex];
  };
  const byMesh = new Map();
  for (const v of fixed) {
    const [o, k] = locate(v);
    if (!o) continue;
    if (!byMesh.has(o)) byMesh.set(o, []);
    byMesh.get(o).push(k);
  }
  let shown = 0;
  for (const [mesh, list] of byMesh) {
    const pos = mesh.geometry.getAttribute('position');
    const xyz = new Float32Array(3 * list.length);
    list.forEach((v, k) => xyz.set([pos.getX(v), pos.getY(v), pos.getZ(v)], 3 * k));
    const g = new BufferGeometry();
    g.setAttribute('position', new BufferAttribute(xyz, 3));
    const pts = new Points(g, new PointsMaterial({ color: 0xcc2200, size: 7, sizeAttenuation: false, depthTest: true }));
    pts.name = 'fixed vertices';
    mesh.add(pts);
    shown += list.length;
  }
  return shown;
}

// Mode shapes: one animation per mode. In a kept asset (`export --onto ASSET.glb`) the asset's
// own animations come first; extras.dcr.modes[i].animation names each mode's, and its morph
// target is found by its name (mesh.extras.targetNames) after the asset's own targets.
function setupModes(gltf, dcr) {
  state.kind = 'modes';
  const indexed = dcr.modes?.length && dcr.modes.every((m) => Number.isInteger(m.animation));
  state.modes = indexed ? dcr.modes.map((m) => gltf.animations[m.animation]) : gltf.animations;
  state.modeInfo = state.modes.map((a, i) => {
    const m = dcr.modes?.[i] || {};
    return { name: m.frequency_hz ? modeTitle(i, m.frequency_hz) : a.name, hz: m.frequency_hz || 0, target: m.name };
  });
  state.period = dcr.period_s || 1;
  state.mixer = new AnimationMixer(gltf.scene);
  $('mode').innerHTML = state.modeInfo.map((m, i) => `<option value="${i}">${m.name}</option>`).join('');
  state.fixedCount = showFixed(gltf, dcr);
  const want = Number(params.get('mode') || 1) - 1;
  selectMode(Math.max(0, Math.min(want, state.modes.length - 1)));
  frame(gltf.scene, null);
  const fixed = state.fixedCount ? `; ${state.fixedCount} fixed vertices (red points)` : '; free-free';
  $('info').textContent = `${dcr.modes.length} modes, largest displacement ${dcr.scale} × diagonal (${(dcr.scale * dcr.diagonal_m).toPrecision(3)} m)${fixed}`;
}

// Viridis (as the PNG contact sheet): displacement magnitude of the selected mode as colour.
const VIRIDIS = [[0.267, 0.005, 0.329], [0.283, 0.141, 0.458], [0.254, 0.265, 0.530], [0.207, 0.372, 0.553],
  [0.164, 0.471, 0.558], [0.128, 0.567, 0.551], [0.135, 0.659, 0.518], [0.478, 0.821, 0.319], [0.993, 0.906, 0.144]];
function viridis(t) {
  const x = Math.min(Math.max(t, 0), 1) * (VIRIDIS.length - 1);
  const i = Math.min(Math.floor(x), VIRIDIS.length - 2), f = x - i;
  // sRGB table → linear vertex colours (the renderer converts back on output).
  return VIRIDIS[i].map((a, k) => ((a + f * (VIRIDIS[i + 1][k] - a) + 0.055) / 1.055) ** 2.4);
}
function colourByMode(i) {
  state.root.traverse((o) => {
    const targets = o.isMesh && o.geometry.morphAttributes.position;
    const name = state.modeInfo[i]?.target;
    const k = name !== undefined && o.morphTargetDictionary && name in o.morphTargetDictionary
      ? o.morphTargetDictionary[name] : i;
    if (!targets || !targets[k]) return;
    const d = targets[k];
    const mag = new Float32Array(d.count);
    let peak = 0;
    for (let v = 0; v < d.count; v++) { mag[v] = Math.hypot(d.getX(v), d.getY(v), d.getZ(v)); peak = Math.max(peak, mag[v]); }
    const rgb = new Float32Array(3 * d.count);
    for (let v = 0; v < d.count; v++) rgb.set(viridis(peak > 0 ? mag[v] / peak : 0), 3 * v);
    o.geometry.setAttribute('color', new BufferAttribute(rgb, 3));
    if (!o.material.vertexColors) { o.material = o.material.clone(); o.material.vertexColors = true; o.material.color.set(0xffffff); }
  });
}

function selectMode(i) {
  if (!state.modes[i]) return;
  colourByMode(i);
  state.mixer.stopAllAction();
  state.action = state.mixer.clipAction(state.modes[i]);
  state.action.setLoop(LoopRepeat, Infinity).play();
  state.duration = state.modes[i].duration;
  state.mode = i;
  $('mode').value = String(i);
  applyTime();
}

function setupGeneric(gltf) {
  state.kind = 'generic';
  state.mixer = new AnimationMixer(gltf.scene);
  if (gltf.animations[0]) {
    state.action = state.mixer.clipAction(gltf.animations[0]);
    state.action.play();
    state.duration = gltf.animations[0].duration;
  }
  frame(gltf.scene, null);
}

function setup(gltf, name) {
  clearModel();
  state.root = gltf.scene;
  state.name = name;
  scene.add(gltf.scene);
  const dcr = gltf.parser.json.extras?.dcr;
  if (dcr?.kind === 'scene_run') setupScene(gltf, dcr);
  else if (dcr?.kind === 'modes' || dcr?.kind === 'modes_onto') setupModes(gltf, dcr);
  else setupGeneric(gltf);
  document.querySelectorAll('.scene-only').forEach((e) => e.classList.toggle('hidden', state.kind !== 'scene_run'));
  document.querySelectorAll('.modes-only').forEach((e) => e.classList.toggle('hidden', state.kind !== 'modes'));
  $('drop').classList.add('hidden');
  document.title = `dcr viewer — ${name}`;
  if (params.get('t')) state.time = Number(params.get('t'));
  applyTime();
}

function parse(buffer, name) {
  return new Promise((resolve, reject) => {
    new GLTFLoader().parse(buffer, '', (gltf) => {
      try { setup(gltf, name); resolve(); } catch (e) { reject(e); }
    }, reject);
  });
}

async function loadUrl(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  await parse(await r.arrayBuffer(), url.split('/').pop());
}

function fail(e) {
  console.error(e);
  $('info').textContent = `error: ${e.message || e}`;
}

// Time: the animation, markers and flashes at state.time.
function applyTime() {
  if (state.duration > 0) {
    if (state.kind === 'modes' || state.kind === 'generic') state.time %= state.duration;
    state.time = Math.min(Math.max(state.time, 0), state.duration);
  }
  if (state.mixer) state.mixer.setTime(state.time);
  const t = state.time;
  for (const s of state.sides) {
    for (const a of s.arrows) a.arrow.visible = state.markers && t >= a.time - 1e-9 && t < a.time + ARROW_S;
    const flash = new Map();
    if (state.markers) {
      for (const e of s.events) {
        const age = t - e.time;
        if (age >= -1e-9 && age < FLASH_S) flash.set(e.body, Math.max(flash.get(e.body) || 0, 1 - age / FLASH_S));
      }
    }
    for (const [body, mesh] of s.bodies) {
      const k = flash.get(body) || 0;
      mesh.material.emissive?.setRGB(1.0 * k, 0.8 * k, 0.0);
    }
  }
  $('time').value = state.duration > 0 ? String(state.time / state.duration) : '0';
  const row = state.h > 0 ? Math.round(state.time / state.h) : null;
  $('clock').textContent = clockText(row);
  requestRender();
}

// Clock: simulated time for a run; for a mode, the physical time of its own oscillation (the
// animation plays one period of the mode, T = 1/F, in `period_s` of animation time).
function clockText(row) {
  const m = state.kind === 'modes' ? state.modeInfo[state.mode] : null;
  if (m && m.hz > 0) {
    const T = 1 / m.hz;
    const t = (state.time / state.period) * T;
    return `t = ${fmtSeconds(t)} of T = ${fmtSeconds(T)} (physical)`;
  }
  return `t = ${state.time.toFixed(3)} s` + (row !== null ? ` (row ${row})` : '');
}
function fmtSeconds(t) {
  if (t === 0) return '0 s';
  if (t < 1e-3) return `${(t * 1e6).toPrecision(3)} µs`;
  if (t < 1) return `${(t * 1e3).toPrecision(3)} ms`;
  return `${t.toPrecision(3)} s`;
}

// Viewports: split = one per chosen side with the same camera relative to each side's offset.
function viewports() {
  const w = view.clientWidth, h = view.clientHeight;
  if (state.kind === 'scene_run' && state.layout === 'split' && state.sides.length > 1) {
    const half = Math.floor(w / 2);
    return [
      { label: state.left, x: 0, y: 0, w: half, h },
      { label: state.right, x: half, y: 0, w: w - half, h },
    ];
  }
  return [{ label: null, x: 0, y: 0, w, h }];
}

function cameraFor(vp) {
  viewCam.copy(camera);
  viewCam.aspect = vp.w / vp.h;
  if (vp.label !== null && state.sides.length) {
    viewCam.position.add(sideOf(vp.label).offset);
  }
  viewCam.updateProjectionMatrix();
  viewCam.updateMatrixWorld();
  return viewCam;
}

let tags = [];
function render() {
  const w = view.clientWidth, h = view.clientHeight;
  const size = renderer.getSize(new Vector3());
  if (size.x !== w || size.y !== h) renderer.setSize(w, h);
  const vps = viewports();
  tags.forEach((t) => t.remove());
  tags = [];
  for (const vp of vps) {
    for (const s of state.sides) s.node.visible = vp.label === null || s.label === vp.label;
    const cam = cameraFor(vp);
    renderer.setViewport(vp.x, h - vp.y - vp.h, vp.w, vp.h);
    renderer.setScissor(vp.x, h - vp.y - vp.h, vp.w, vp.h);
    renderer.render(scene, cam);
    if (vp.label === null && state.kind === 'modes' && state.modeInfo[state.mode]) {
      const tag = document.createElement('div');
      tag.className = 'tag';
      tag.id = 'mode-tag';
      tag.textContent = state.modeInfo[state.mode].name;
      tag.style.left = `${vp.x + 8}px`;
      view.appendChild(tag);
      tags.push(tag);
    }
    if (vp.label !== null) {
      const tag = document.createElement('div');
      tag.className = 'tag';
      tag.textContent = `dcr ${vp.label}`;
      tag.style.left = `${vp.x + 8}px`;
      view.appendChild(tag);
      tags.push(tag);
    }
  }
  for (const s of state.sides) s.node.visible = true;
}

let pending = false;
function requestRender() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => { pending = false; render(); });
}

let last = performance.now();
function tick(now) {
  const dt = Math.min((now - last) / 1000, 0.1);
  last = now;
  if (state.playing && state.duration > 0) {
    state.time += dt * state.speed;
    if (state.time > state.duration) state.time = state.kind === 'scene_run' ? 0 : state.time % state.duration;
    applyTime();
  }
  requestAnimationFrame(tick);
}
requestAnimationFrame(tick);

// Controls.
function setPlaying(p) { state.playing = p; $('play').textContent = p ? 'Pause' : 'Play'; }
setPlaying(state.playing);
$('play').onclick = () => setPlaying(!state.playing);
$('time').oninput = (e) => { state.time = Number(e.target.value) * state.duration; applyTime(); };
$('speed').onchange = (e) => { state.speed = Number(e.target.value); };
$('layout').onchange = (e) => { state.layout = e.target.value; if (state.kind === 'scene_run') frameForLayout(); requestRender(); };
$('left').onchange = (e) => { state.left = e.target.value; requestRender(); };
$('right').onchange = (e) => { state.right = e.target.value; requestRender(); };
$('markers').onchange = (e) => { state.markers = e.target.checked; applyTime(); };
$('mode').onchange = (e) => selectMode(Number(e.target.value));
window.addEventListener('resize', requestRender);
window.addEventListener('keydown', (e) => {
  if (e.code === 'Space' && e.target.tagName !== 'INPUT') { setPlaying(!state.playing); e.preventDefault(); }
  if (e.code === 'ArrowRight' && state.h) { state.time += state.h; applyTime(); }
  if (e.code === 'ArrowLeft' && state.h) { state.time -= state.h; applyTime(); }
});
$('open').onchange = async (e) => {
  const f = e.target.files[0];
  if (f) await parse(await f.arrayBuffer(), f.name).catch(fail);
};
window.addEventListener('dragover', (e) => e.preventDefault());
window.addEventListener('drop', async (e) => {
  e.preventDefault();
  const f = e.dataTransfer.files[0];
  if (f) await parse(await f.arrayBuffer(), f.name).catch(fail);
});

function frameForLayout() {
  if (state.layout === 'together') frame(state.root, null);
  else frame(sideOf(state.left).node, sideOf(state.left).offset);
}

// A small API for scripts and the browser test.
window.dcrViewer = {
  ready: params.get('file') ? loadUrl(params.get('file')).catch((e) => { fail(e); throw e; }) : Promise.resolve(),
  load: (url) => loadUrl(url),
  setTime(t) { state.time = t; applyTime(); render(); },
  setPlaying,
  renderNow: render,
  info: () => ({
    kind: state.kind, name: state.name, duration: state.duration, h: state.h, rows: state.rows,
    layout: state.layout, left: state.left, right: state.right, time: state.time,
    sides: state.sides.map((s) => ({ label: s.label, dcr: s.dcr, events: s.events.length, bodies: [...s.bodies.keys()] })),
    modes: state.modes.map((a) => a.name),
    modeNames: state.modeInfo.map((m) => m.name),
    mode: state.mode, fixed: state.fixedCount,
    clock: $('clock').textContent, tag: document.getElementById('mode-tag')?.textContent ?? null,
  }),
  events: (label) => sideOf(label)?.events ?? [],
  viewports,
  // Screen rectangle (CSS pixels, top-left origin) of a body of a side in viewport i.
  screenRect(label, body, i) {
    const s = sideOf(label);
    const mesh = s?.bodies.get(body);
    if (!mesh) return null;
    const vp = viewports()[i];
    const cam = cameraFor(vp);
    const box = new Box3().setFromObject(mesh);
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) {
      const p = new Vector3(x, y, z).project(cam);
      const px = vp.x + ((p.x + 1) / 2) * vp.w, py = vp.y + ((1 - p.y) / 2) * vp.h;
      x0 = Math.min(x0, px); x1 = Math.max(x1, px); y0 = Math.min(y0, py); y1 = Math.max(y1, py);
    }
    return { x: x0, y: y0, w: x1 - x0, h: y1 - y0 };
  },
};
