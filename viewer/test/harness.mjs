// Shared by the browser test and the picture scripts: a static server on 127.0.0.1 for the
// viewer plus extra files, and headless Debian Chromium through playwright-core.
import { createServer } from 'node:http';
import { mkdtemp, readFile, rm } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import { extname, join, normalize, resolve } from 'node:path';
import { chromium } from 'playwright-core';

export const VIEWER = resolve(new URL('..', import.meta.url).pathname);
export const ROOT = resolve(VIEWER, '..');
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.glb': 'model/gltf-binary', '.json': 'application/json' };

// Serves viewer/ at / and each `extra` file at /files/NAME. Resolves to { url, close }.
export async function serve(extra = {}) {
  const server = createServer(async (req, res) => {
    try {
      const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
      let file;
      if (path.startsWith('/files/')) file = extra[path.slice(7)];
      else {
        const p = normalize(join(VIEWER, path === '/' ? 'index.html' : path));
        if (p.startsWith(VIEWER) && !p.includes('node_modules')) file = p;
      }
      if (!file) { res.writeHead(404).end(); return; }
      const body = await readFile(file);
      res.writeHead(200, { 'content-type': TYPES[extname(file)] || 'application/octet-stream' }).end(body);
    } catch {
      res.writeHead(404).end();
    }
  });
  await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
  const { port } = server.address();
  return { url: `http://127.0.0.1:${port}`, close: () => new Promise((ok) => server.close(ok)) };
}

// Headless Chromium with the flags this machine needs and a new, empty profile.
export async function launch(viewport = { width: 1280, height: 600 }) {
  const profile = await mkdtemp(join(tmpdir(), 'dcr-chromium-'));
  const ctx = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    viewport,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  return { ctx, close: async () => { await ctx.close(); await rm(profile, { recursive: true, force: true }); } };
}

// Opens the viewer on `query`, collecting console errors and page errors.
export async function openViewer(ctx, base, query) {
  const page = await ctx.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(`${base}/index.html?${query}`);
  await page.evaluate(() => window.dcrViewer.ready);
  return { page, errors };
}

// RGBA bytes of a rectangle of the WebGL canvas (CSS px = device px at scale 1).
export async function canvasPixels(page, r) {
  return page.evaluate((r) => {
    const c = document.querySelector('#view canvas');
    const g = document.createElement('canvas');
    g.width = c.width; g.height = c.height;
    const ctx = g.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const x = Math.max(0, Math.floor(r.x)), y = Math.max(0, Math.floor(r.y));
    const w = Math.max(1, Math.min(c.width - x, Math.ceil(r.w))), h = Math.max(1, Math.min(c.height - y, Math.ceil(r.h)));
    return Array.from(ctx.getImageData(x, y, w, h).data);
  }, r);
}

// Counts, inside the page, the pixels of `r` (canvas px) that differ between the current
// frame and the snapshot `key` taken earlier (or, without a snapshot, from the background
// colour of the top-left pixel); `save` stores the current frame under `key`.
export async function pixelStats(page, { r, key, save, against }) {
  return page.evaluate(({ r, key, save, against }) => {
    const c = document.querySelector('#view canvas');
    const g = document.createElement('canvas');
    g.width = c.width; g.height = c.height;
    const ctx = g.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const data = ctx.getImageData(0, 0, c.width, c.height).data;
    window.__snaps = window.__snaps || {};
    if (save) window.__snaps[key] = data;
    const ref = against ? window.__snaps[against] : null;
    const rr = r || { x: 0, y: 0, w: c.width, h: c.height };
    let n = 0;
    for (let y = Math.max(0, rr.y | 0); y < Math.min(c.height, rr.y + rr.h); y++) {
      for (let x = Math.max(0, rr.x | 0); x < Math.min(c.width, rr.x + rr.w); x++) {
        const i = 4 * (y * c.width + x);
        const b = ref ? [ref[i], ref[i + 1], ref[i + 2]] : [data[0], data[1], data[2]];
        if (Math.abs(data[i] - b[0]) + Math.abs(data[i + 1] - b[1]) + Math.abs(data[i + 2] - b[2]) > 30) n++;
      }
    }
    return n;
  }, { r, key, save, against });
}
