// The viewer in a real browser (Debian Chromium, headless, through playwright-core):
// - every .glb this test writes passes the Khronos glTF-Validator with 0 errors;
// - the dinner run (on vs off, split view) renders (a non-blank canvas, no console errors);
// - at the step after the pot lands the plates' pixels differ between the on and off sides,
//   while the same comparison finds them identical one step before the first response and
//   with the response off on both sides (the controls);
// - a mode-shape GLB plays: the surface moves between two times of its animation;
// - a mode's label reads "mode N — F Hz", the clock the physical time of the mode's own
//   period, and a clamped base's fixed vertices are drawn;
// - in an asset kept by `export --onto ASSET.glb` the modes are dcr's animations after the
//   asset's own, the selected one moves the surface, and the fixed vertices are drawn.
// Needs target/release/dcr-scenes and modal-bake (cargo build --release; under $CARGO_TARGET_DIR
// when set) and `npm ci` here.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, writeFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { validateFile } from './validate.mjs';
import { ROOT, serve, launch, openViewer, canvasPixels, pixelStats } from './harness.mjs';

const OUT = join(ROOT, 'out', 'browser-test');
// Cargo's target folder: $CARGO_TARGET_DIR when set (relative to the repository root, where
// .ci/run runs cargo), else target/.
const bin = (name) => join(resolve(ROOT, process.env.CARGO_TARGET_DIR || 'target'), 'release', name);
let server, browser;
const files = {};

before(async () => {
  mkdirSync(OUT, { recursive: true });
  for (const b of ['dcr-scenes', 'modal-bake']) {
    assert.ok(existsSync(bin(b)), `${bin(b)} missing: cargo build --release -p dcr-scenes -p modal-bake`);
  }
  files['dinner.glb'] = join(OUT, 'dinner.glb');
  execFileSync(bin('dcr-scenes'), ['run', 'dinner', '--dcr', 'both', '--seconds', '0.8',
    '--out', join(OUT, 'dinner'), '--gltf', files['dinner.glb']], { cwd: ROOT, stdio: ['ignore', 'ignore', 'inherit'] });
  files['table_modes.glb'] = join(OUT, 'table_modes.glb');
  execFileSync(bin('modal-bake'), ['export', join(ROOT, 'out', 'bases', 'table.modes'), '--modes', '8',
    '--gltf', files['table_modes.glb']], { cwd: ROOT, stdio: ['ignore', 'ignore', 'inherit'] });
  const beam = join(OUT, 'beam.modes');
  execFileSync(bin('modal-bake'), ['bake', join(ROOT, 'data', 'meshes', 'beam.msh'), '-o', beam, '--fixed', 'clamp',
    '--modes', '4'], { cwd: ROOT, stdio: ['ignore', 'ignore', 'inherit'] });
  files['beam_modes.glb'] = join(OUT, 'beam_modes.glb');
  execFileSync(bin('modal-bake'), ['export', beam, '--gltf', files['beam_modes.glb']],
    { cwd: ROOT, stdio: ['ignore', 'ignore', 'inherit'] });
  // The plain export as an asset of its own (a mesh with 4 animations and 4 morph targets):
  // `--onto` keeps them and adds 2 modes after them.
  files['beam_kept.glb'] = join(OUT, 'beam_kept.glb');
  execFileSync(bin('modal-bake'), ['export', beam, '--modes', '2', '--gltf', files['beam_kept.glb'],
    '--onto', files['beam_modes.glb']], { cwd: ROOT, stdio: ['ignore', 'ignore', 'inherit'] });
  server = await serve(files);
  browser = await launch({ width: 1280, height: 600 });
});

after(async () => {
  await browser?.close();
  await server?.close();
});

test('every written .glb passes the Khronos glTF-Validator', async () => {
  for (const [name, path] of Object.entries(files)) {
    const r = await validateFile(path);
    const errs = r.issues.messages.filter((m) => m.severity === 0).map((m) => `${m.code} ${m.pointer}: ${m.message}`);
    assert.equal(r.issues.numErrors, 0, `${name}: ${errs.join('\n')}`);
  }
});

// Pixels of the union of the plates' screen rectangles in viewport 0 and the same rectangle
// in viewport 1 (split view: same camera relative to each side, so the same place).
async function plateRegions(page) {
  const rects = await page.evaluate(() => {
    const v = window.dcrViewer;
    const i = v.info();
    const side = v.info().left;
    const plates = i.sides.find((s) => s.label === side).bodies.filter((b) => b.startsWith('plate'));
    return { plates: plates.map((b) => v.screenRect(side, b, 0)), vps: v.viewports() };
  });
  const pad = 4;
  const x0 = Math.min(...rects.plates.map((r) => r.x)) - pad, y0 = Math.min(...rects.plates.map((r) => r.y)) - pad;
  const x1 = Math.max(...rects.plates.map((r) => r.x + r.w)) + pad, y1 = Math.max(...rects.plates.map((r) => r.y + r.h)) + pad;
  const region = { x: x0, y: y0, w: x1 - x0, h: y1 - y0 };
  assert.ok(region.w > 50 && region.h > 10 && x1 <= rects.vps[0].w, `plates region ${JSON.stringify(region)}`);
  const left = await canvasPixels(page, region);
  const right = await canvasPixels(page, { ...region, x: region.x + rects.vps[1].x });
  return { left, right, region };
}

function changedPixels(a, b) {
  assert.equal(a.length, b.length);
  let n = 0;
  for (let i = 0; i < a.length; i += 4) {
    if (Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]) > 30) n += 1;
  }
  return n;
}

test('dinner: renders, and the plates differ on vs off at the step after the pot lands (with controls)', async () => {
  const { page, errors } = await openViewer(browser.ctx, server.url, 'file=/files/dinner.glb&paused=1&markers=0');
  const info = await page.evaluate(() => window.dcrViewer.info());
  assert.equal(info.kind, 'scene_run');
  assert.deepEqual(info.sides.map((s) => s.label), ['on', 'off']);
  assert.ok(info.sides[0].events > 0 && info.sides[1].events === 0, JSON.stringify(info.sides));

  // The pot lands: the first response to a plate (trajectory row r, applied at t = r·h).
  const events = await page.evaluate(() => window.dcrViewer.events('on'));
  const r = Math.min(...events.filter((e) => e.body.startsWith('plate')).map((e) => e.row));
  assert.ok(r > 3 && r < info.rows - 2, `first plate response at row ${r}`);

  // Non-blank: the canvas is not one colour.
  await page.evaluate((t) => window.dcrViewer.setTime(t), 0);
  const vp = await page.evaluate(() => window.dcrViewer.viewports());
  const drawn = await pixelStats(page, {});
  const total = (vp[1].x + vp[1].w) * vp[0].h;
  assert.ok(drawn > 0.05 * total, `only ${drawn} of ${total} pixels drawn`);

  const at = async (row) => {
    await page.evaluate((t) => window.dcrViewer.setTime(t), row * info.h);
    return plateRegions(page);
  };
  // Control 1: one step before the first response both runs are the same.
  const before = await at(r - 1);
  const nBefore = changedPixels(before.left, before.right);
  // The step after the pot lands: the plates were kicked on the left side only.
  const afterLanding = await at(r + 1);
  const nAfter = changedPixels(afterLanding.left, afterLanding.right);
  await page.screenshot({ path: join(OUT, 'dinner_after_landing.png') });
  writeFileSync(join(OUT, 'dinner_regions.json'), JSON.stringify({ row: r, nBefore, nAfter, region: afterLanding.region }));
  assert.equal(nBefore, 0, `plates differ before any response: ${nBefore} pixels`);
  assert.ok(nAfter >= 20, `plates barely differ on vs off at row ${r + 1}: ${nAfter} pixels`);
  assert.deepEqual(errors, []);
  await page.close();

  // Control 2: the response off on both sides: the same region matches at the same step.
  const ctl = await openViewer(browser.ctx, server.url, 'file=/files/dinner.glb&paused=1&markers=0&left=off&right=off');
  await ctl.page.evaluate((t) => window.dcrViewer.setTime(t), (r + 1) * info.h);
  const same = await plateRegions(ctl.page);
  assert.equal(changedPixels(same.left, same.right), 0, 'off vs off differs');
  assert.deepEqual(ctl.errors, []);
  await ctl.page.close();
});

test('dinner: response markers flash the receiving plates at their step', async () => {
  const { page, errors } = await openViewer(browser.ctx, server.url, 'file=/files/dinner.glb&paused=1&markers=1&left=on&right=on');
  const info = await page.evaluate(() => window.dcrViewer.info());
  const events = await page.evaluate(() => window.dcrViewer.events('on'));
  const r = Math.min(...events.filter((e) => e.body.startsWith('plate')).map((e) => e.row));
  await page.evaluate((t) => window.dcrViewer.setTime(t), r * info.h);
  const lit = await plateRegions(page);
  await page.evaluate((t) => window.dcrViewer.setTime(t), (r - 1) * info.h);
  const dark = await plateRegions(page);
  assert.ok(changedPixels(lit.left, dark.left) > 100, 'no flash or arrow at the response step');
  assert.deepEqual(errors, []);
  await page.close();
});

test('mode-shape GLB: one animation per mode, and the surface moves', async () => {
  const { page, errors } = await openViewer(browser.ctx, server.url, 'file=/files/table_modes.glb&paused=1&mode=4');
  const info = await page.evaluate(() => window.dcrViewer.info());
  assert.equal(info.kind, 'modes');
  assert.equal(info.modes.length, 8);
  assert.match(info.modes[0], /^mode_01_\d+\.\dHz$/);
  await page.evaluate(() => window.dcrViewer.setTime(0));
  await pixelStats(page, { key: 'rest', save: true });
  await page.evaluate(() => window.dcrViewer.setTime(0.25));
  const moved = await pixelStats(page, { against: 'rest' });
  await page.screenshot({ path: join(OUT, 'table_mode4.png') });
  assert.ok(moved > 200, `mode 4 moves only ${moved} pixels`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('mode labels: "mode N — F Hz", physical time of the mode, fixed vertices shown', async () => {
  const { page, errors } = await openViewer(browser.ctx, server.url, 'file=/files/beam_modes.glb&paused=1&mode=2');
  const doc = JSON.parse(execFileSync('node', ['-e', `
    const b = require('fs').readFileSync(process.argv[1]);
    const n = b.readUInt32LE(12);
    process.stdout.write(b.subarray(20, 20 + n).toString());`, files['beam_modes.glb']]).toString());
  const dcr = doc.extras.dcr;
  const hz = dcr.modes[1].frequency_hz;
  await page.evaluate(() => window.dcrViewer.setTime(0.25));
  const info = await page.evaluate(() => window.dcrViewer.info());
  assert.equal(info.kind, 'modes');
  assert.equal(info.mode, 1);
  assert.equal(info.tag, `mode 2 — ${hz.toFixed(1)} Hz`);
  assert.equal(info.modeNames[0], `mode 1 — ${dcr.modes[0].frequency_hz.toFixed(1)} Hz`);
  // A quarter of the animation's period is a quarter of the mode's physical period 1/F.
  const m = info.clock.match(/^t = ([0-9.]+) ms of T = ([0-9.]+) ms \(physical\)$/);
  assert.ok(m, info.clock);
  const T = 1000 / hz;
  assert.ok(Math.abs(Number(m[2]) - T) <= 0.01 * T, `${info.clock} vs T = ${T} ms`);
  assert.ok(Math.abs(Number(m[1]) - T / 4) <= 0.01 * T, `${info.clock} vs t = ${T / 4} ms`);
  // The clamped end's surface vertices are drawn as points (and the base has some).
  assert.ok(dcr.fixed_vertices.length > 0);
  assert.equal(info.fixed, dcr.fixed_vertices.length);
  await page.screenshot({ path: join(OUT, 'beam_mode2.png') });
  assert.deepEqual(errors, []);
  await page.close();
});

test('a kept glTF asset: the modes after its own animations, moving, fixed vertices shown', async () => {
  const { page, errors } = await openViewer(browser.ctx, server.url, 'file=/files/beam_kept.glb&paused=1&mode=1');
  const doc = JSON.parse(execFileSync('node', ['-e', `
    const b = require('fs').readFileSync(process.argv[1]);
    const n = b.readUInt32LE(12);
    process.stdout.write(b.subarray(20, 20 + n).toString());`, files['beam_kept.glb']]).toString());
  const dcr = doc.extras.dcr;
  assert.equal(doc.animations.length, 6);
  assert.deepEqual(dcr.modes.map((m) => m.animation), [4, 5]);
  const info = await page.evaluate(() => window.dcrViewer.info());
  assert.equal(info.kind, 'modes');
  assert.deepEqual(info.modes, [doc.animations[4].name, doc.animations[5].name]);
  assert.equal(info.modeNames[0], `mode 1 — ${dcr.modes[0].frequency_hz.toFixed(1)} Hz`);
  await page.evaluate(() => window.dcrViewer.setTime(0));
  await pixelStats(page, { key: 'rest', save: true });
  await page.evaluate(() => window.dcrViewer.setTime(0.25));
  const moved = await pixelStats(page, { against: 'rest' });
  assert.ok(moved > 200, `mode 1 moves only ${moved} pixels`);
  assert.ok(dcr.fixed_vertices.length > 0);
  assert.equal(info.fixed, dcr.fixed_vertices.length);
  await page.screenshot({ path: join(OUT, 'beam_kept_mode1.png') });
  assert.deepEqual(errors, []);
  await page.close();
});
