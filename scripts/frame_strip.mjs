// Frames of a scene-run GLB in the viewer (headless Debian Chromium), stacked into one JPEG
// (or PNG when OUT ends in .png).
// Usage: node scripts/frame_strip.mjs FILE.glb OUT.jpg [--after-response S1,S2,...] [--times T1,...]
//        [--width PX] [--height PX] [--scale F] [--query 'az=60&...'] (extra viewer URL parameters)
// --after-response: times (s) after the on side's first response (negative = before it;
// `end` = the end of the run);
// --times: absolute times (s). Needs `npm ci` in viewer/ and Debian's chromium.
import { writeFileSync } from 'node:fs';
import { basename } from 'node:path';
import { serve, launch, openViewer } from '../viewer/test/harness.mjs';

const args = process.argv.slice(2);
const opt = (name, def) => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : def; };
const [file, out] = args;
if (!file || !out) {
  console.error('usage: node scripts/frame_strip.mjs FILE.glb OUT.jpg [--after-response 0,0.1] [--times 0.5] [--width 1200] [--height 460] [--scale 0.5]');
  process.exit(2);
}
const width = Number(opt('--width', 1200)), height = Number(opt('--height', 460)), scale = Number(opt('--scale', 0.5));
const server = await serve({ [basename(file)]: file });
const browser = await launch({ width, height });
try {
  const { page, errors } = await openViewer(browser.ctx, server.url, `file=/files/${basename(file)}&paused=1${opt('--query', '') ? '&' + opt('--query') : ''}`);
  const info = await page.evaluate(() => window.dcrViewer.info());
  let times;
  if (opt('--times')) times = opt('--times').split(',').map(Number);
  else {
    const ev = await page.evaluate(() => window.dcrViewer.events(window.dcrViewer.info().sides[0].label));
    const t0 = ev.length ? Math.min(...ev.map((e) => e.time)) : info.duration / 2;
    times = opt('--after-response', '0,0.1,0.25').split(',')
      .map((d) => (d === 'end' ? info.duration : Math.min(info.duration, Math.max(0, t0 + Number(d)))));
  }
  const frames = [];
  for (const t of times) {
    await page.evaluate((t) => window.dcrViewer.setTime(t), t);
    frames.push(await page.evaluate(() => document.querySelector('#view canvas').toDataURL('image/png')));
  }
  const fmt = out.endsWith('.png') ? 'image/png' : 'image/jpeg';
  const jpeg = await page.evaluate(async ({ frames, times, scale, fmt }) => {
    const imgs = await Promise.all(frames.map((src) => new Promise((ok) => { const i = new Image(); i.onload = () => ok(i); i.src = src; })));
    const w = Math.round(imgs[0].width * scale), h = Math.round(imgs[0].height * scale);
    const c = document.createElement('canvas');
    c.width = w; c.height = h * imgs.length;
    const g = c.getContext('2d');
    imgs.forEach((img, k) => {
      g.drawImage(img, 0, k * h, w, h);
      g.font = 'bold 15px sans-serif';
      g.fillStyle = 'rgba(0,0,0,0.65)';
      g.fillRect(w - 108, k * h + 4, 104, 22);
      g.fillStyle = '#fff';
      g.textAlign = 'center';
      g.fillText(`t = ${times[k].toFixed(2)} s`, w - 56, k * h + 20);
      g.fillStyle = 'rgba(0,0,0,0.65)';
      g.fillRect(4, k * h + 4, 64, 22); g.fillRect(w / 2 + 4, k * h + 4, 70, 22);
      g.fillStyle = '#fff'; g.textAlign = 'left';
      g.fillText('dcr on', 10, k * h + 20); g.fillText('dcr off', w / 2 + 10, k * h + 20);
    });
    return c.toDataURL(fmt, 0.85);
  }, { frames, times, scale, fmt });
  writeFileSync(out, Buffer.from(jpeg.split(',')[1], 'base64'));
  if (errors.length) throw new Error(`viewer errors: ${errors.join('; ')}`);
  console.log(`wrote ${out} (${times.length} frames at t = ${times.map((t) => t.toFixed(2)).join(', ')} s)`);
} finally {
  await browser.close();
  await server.close();
}
