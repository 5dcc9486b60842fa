// Shared helpers for the end-to-end tests and the bench: start a Vite server on a free port (and
// stop it by its own pid), launch the system Chromium through playwright-core with a fresh
// profile, and read the page's window.duet test hook. Tests assert on window.duet only, so they
// hold for the development simulation and for the real models alike.
//
// No test asserts how fast anything is: a test waits for what the page does (ready, steps taken,
// a message shown) for up to WAIT_MS and fails only if it never happens. How fast the page loads
// and steps is `npm run bench` (scripts/bench.mjs). Pictures the tests take go to SCREENS, a
// git-ignored folder, so that `npm test` leaves the working tree as it found it.

import { spawn } from 'node:child_process';
import { mkdirSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:net';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const ROOT = resolve(fileURLToPath(new URL('../..', import.meta.url)));
/**
 * How long a test waits for the page to do something before it fails (DUET_WAIT_MS, default 2
 * minutes). Generous on purpose: a machine busy with other work only makes the page slower, and a
 * slow page is not a failed test. A page that never does it still fails, after this long.
 */
export const WAIT_MS = Number(process.env.DUET_WAIT_MS ?? 120_000);
/** Where the tests' screenshots and film strips go (DUET_SCREENS; git-ignored runs/screens). */
export const SCREENS = resolve(process.env.DUET_SCREENS ?? join(ROOT, 'runs', 'screens'));

/** Save a picture (PNG bytes, or a PNG data URL) as SCREENS/`name`; returns its path. */
export function saveScreen(name, png) {
  mkdirSync(SCREENS, { recursive: true });
  const bytes = typeof png === 'string' ? Buffer.from(png.slice(png.indexOf(',') + 1), 'base64') : png;
  const path = join(SCREENS, name);
  writeFileSync(path, bytes);
  return path;
}
const VITE = join(ROOT, 'node_modules', 'vite', 'bin', 'vite.js');
const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';
export const CHROMIUM_ARGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
];

export function freePort() {
  return new Promise((resolvePort, reject) => {
    const server = createServer();
    server.once('error', reject);
    server.listen(0, '127.0.0.1', () => {
      const { port } = server.address();
      server.close(() => resolvePort(port));
    });
  });
}

/**
 * A folder (relative to ROOT, or absolute) that already holds `vite build` of this tree
 * (DUET_BUILT): scripts/test.sh builds the site once into `dist` for all the browser test files,
 * where each file built it again (a build is a minute of CPU on a busy 2-core machine). Unset (a
 * file run alone), each file builds its own.
 */
export const BUILT = process.env.DUET_BUILT ? resolve(ROOT, process.env.DUET_BUILT) : null;

/** Run `vite build` into `outDir` (nothing to do when `outDir` is BUILT). */
export function build(outDir = 'dist') {
  if (BUILT && resolve(ROOT, outDir) === BUILT) return Promise.resolve();
  return new Promise((resolveBuild, reject) => {
    const child = spawn(process.execPath, [VITE, 'build', '--outDir', outDir, '--emptyOutDir', '--logLevel', 'warn'], {
      cwd: ROOT,
      stdio: ['ignore', 'inherit', 'inherit'],
    });
    child.once('exit', (code) => (code === 0 ? resolveBuild() : reject(new Error(`vite build exited ${code}`))));
  });
}

/**
 * The built site in a folder the caller may serve but not change: BUILT when scripts/test.sh made
 * one, else a build into a new temporary folder. Returns { dir, remove() } (remove() deletes only
 * a folder made here).
 */
export async function builtSite(prefix = 'duet-dist-') {
  if (BUILT) return { dir: BUILT, remove: () => {} };
  const dir = mkdtempSync(join(tmpdir(), prefix));
  try {
    await build(dir);
  } catch (error) {
    rmSync(dir, { recursive: true, force: true });
    throw error;
  }
  return { dir, remove: () => rmSync(dir, { recursive: true, force: true }) };
}

/**
 * The address of a Vite dev server already running (DUET_DEV_URL, ending in '/'): scripts/test.sh
 * starts one (tests/e2e/devserver.mjs) for all the browser test files. Vite compiles the page's
 * hundreds of modules on their first request, in memory: a server of its own per file paid that
 * again in each file's first page (34 s to ready on a busy 2-core machine, 3-5 s on a warm
 * server). Unset (a file run alone), each file starts its own.
 */
export const DEV_URL = process.env.DUET_DEV_URL || null;

/**
 * Start `vite` (dev) or `vite preview` (built site) on a free port. `base` serves the site from a
 * sub-path (preview only). Returns { url, stop }; stop() kills exactly this process. A dev server
 * at '/' is DEV_URL's when that is set (`shared: true`; stop() leaves it running).
 */
export async function startServer({ mode = 'dev', base = '/', outDir = 'dist' } = {}) {
  if (mode === 'dev' && base === '/' && DEV_URL) return { url: DEV_URL, stop: async () => {}, log: () => '', shared: true };
  const port = await freePort();
  const args = mode === 'dev' ? [VITE] : [VITE, 'preview', '--outDir', outDir];
  args.push('--host', '127.0.0.1', '--port', String(port), '--strictPort');
  if (base !== '/') args.push('--base', base);
  const child = spawn(process.execPath, args, { cwd: ROOT, stdio: ['ignore', 'pipe', 'pipe'] });
  let log = '';
  child.stdout.on('data', (d) => (log += d));
  child.stderr.on('data', (d) => (log += d));
  const url = `http://127.0.0.1:${port}${base}`;
  const stop = () =>
    new Promise((done) => {
      if (child.exitCode !== null) return done();
      child.once('exit', () => done());
      process.kill(child.pid, 'SIGTERM');
    });
  const deadline = Date.now() + WAIT_MS;
  for (;;) {
    if (child.exitCode !== null) throw new Error(`vite ${mode} exited early:\n${log}`);
    try {
      const response = await fetch(url);
      if (response.ok) break;
    } catch {
      // not listening yet
    }
    if (Date.now() > deadline) {
      await stop();
      throw new Error(`vite ${mode} did not answer on ${url}:\n${log}`);
    }
    await sleep(100);
  }
  return { url, stop, log: () => log };
}

/**
 * Launch options of a test that takes no picture: the canvas drawn at half the CSS resolution
 * (devicePixelRatio 0.5; the page draws at min(devicePixelRatio, 2)). Headless Chromium draws
 * WebGL in software, and at full resolution the drawing took most of the CPU a dancing page had
 * (on a busy 2-core machine, 1280x800: 8-14 steps a second at 1, 20 at 0.5, 28 at 0.25), so a
 * test that waits for so many steps of dance waited mostly for pictures nobody looks at. Layout
 * is in CSS pixels and unchanged. Tests that save pictures (docs/testing.md, Pictures) and the
 * bench launch at deviceScaleFactor 1 or the phone's own.
 */
export const QUICK = { deviceScaleFactor: 0.5 };

/**
 * Launch Chromium with a fresh user-data-dir. `options` are Playwright context options
 * (viewport, isMobile, hasTouch, ...). Returns { context, page, consoleErrors, close }.
 */
export async function launch(options = {}) {
  const profile = mkdtempSync(join(tmpdir(), 'duet-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    args: CHROMIUM_ARGS,
    viewport: { width: 1280, height: 800 },
    ...options,
  });
  // Playwright's own waits (clicks, locators, navigation) are as patient as the tests' own.
  context.setDefaultTimeout(WAIT_MS);
  context.setDefaultNavigationTimeout(WAIT_MS);
  await context.addInitScript(recordToasts);
  const page = context.pages()[0] ?? (await context.newPage());
  const consoleErrors = [];
  page.on('console', (message) => {
    if (message.type() === 'error') consoleErrors.push(message.text());
  });
  page.on('pageerror', (error) => consoleErrors.push(String(error)));
  const close = async () => {
    await context.close();
    rmSync(profile, { recursive: true, force: true });
  };
  return { context, page, consoleErrors, close };
}

/**
 * Installed before any page script: every toast the page shows is kept in window.__toasts
 * ({ kind, text }), so a test sees a message even when it came and went (a toast stays 5-9 s, and
 * a busy machine can take longer than that to look).
 */
function recordToasts() {
  window.__toasts = [];
  const seen = new WeakSet();
  const look = (node) => {
    if (!(node instanceof Element)) return;
    for (const toast of node.matches('.toast') ? [node] : node.querySelectorAll('.toast')) {
      if (seen.has(toast)) continue;
      seen.add(toast);
      const kind = [...toast.classList].find((c) => c.startsWith('toast-'))?.slice(6) ?? '';
      window.__toasts.push({ kind, text: toast.textContent });
    }
  };
  new MutationObserver((records) => {
    for (const record of records) for (const node of record.addedNodes) look(node);
  }).observe(document, { childList: true, subtree: true });
}

/**
 * The text of a toast of `kind` ('error', 'info' or null for any) matching `pattern`, waited for
 * up to WAIT_MS. Each toast answers one wait: a second wait for the same words needs a new toast.
 */
export async function waitToast(page, pattern, kind = 'error') {
  const handle = await page.waitForFunction(
    ({ source, flags, kind }) => {
      const re = new RegExp(source, flags);
      const i = (window.__toasts ?? []).findIndex((t) => (!kind || t.kind === kind) && re.test(t.text));
      return i >= 0 && window.__toasts.splice(i, 1)[0].text;
    },
    { source: pattern instanceof RegExp ? pattern.source : pattern.replace(/[.*+?^${}()|[\]\\]/g, '\\$&'), flags: pattern instanceof RegExp ? pattern.flags : '', kind },
    { timeout: WAIT_MS, polling: 50 },
  );
  return handle.jsonValue();
}

/** A snapshot of window.duet (plain data). */
export function duet(page) {
  return page.evaluate(() => JSON.parse(JSON.stringify(window.duet ?? null)));
}

/** Wait until window.duet.ready (or an error); returns milliseconds from now (for diagnostics only). */
export async function waitReady(page, timeoutMs = WAIT_MS) {
  const started = Date.now();
  await page.waitForFunction(() => window.duet && (window.duet.ready || window.duet.error), null, {
    timeout: timeoutMs,
    polling: 20,
  });
  const state = await duet(page);
  if (state.error) throw new Error(`page reported an error: ${state.error}`);
  return Date.now() - started;
}

/** Wait until the simulation has taken `steps` more steps. */
export async function waitSteps(page, steps, timeoutMs = WAIT_MS) {
  const start = (await duet(page)).frame;
  await page.waitForFunction((target) => window.duet.frame >= target, start + steps, { timeout: timeoutMs, polling: 20 });
}

/**
 * Once Space (or the pause button) has paused the dance and the steps under way have ended: the
 * frame then. Polls every 0.5 s until two reads agree.
 */
export async function pausedStill(page) {
  await page.waitForFunction(() => window.duet.paused === true, null, { timeout: WAIT_MS, polling: 20 });
  for (let frame = (await duet(page)).frame; ; ) {
    await sleep(500);
    const now = (await duet(page)).frame;
    if (now === frame) return now;
    frame = now;
  }
}

/**
 * Press R (both dancers back to the start) and return the state R left, then dance on. R waits in
 * the page's queue behind the steps under way, and on a busy machine one batch of steps can outlast
 * any fixed wait (and the first batch after it can be a second of dance): so the dance is paused
 * first, R lands on an idle queue (it has run by the time the key is in), the state is read while
 * the dance stands at the start (two frames drawn, so the places on the screen are the start's
 * too), and then the dance resumes.
 */
export async function reset(page) {
  await page.keyboard.press('Space');
  await pausedStill(page);
  await page.keyboard.press('r');
  await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
  const state = await duet(page);
  await page.keyboard.press('Space');
  await page.waitForFunction(() => window.duet.paused === false, null, { timeout: WAIT_MS, polling: 20 });
  return state;
}

export const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/**
 * How far the leader's spot moved over `steps` simulation steps while `hold()` is in effect.
 * Counted in steps, not wall time, so a slow machine (the page dances in slow motion there) moves
 * him as far as a fast one.
 */
export async function displacement(page, steps, hold = async () => {}, release = async () => {}) {
  // The leader's spot (window.duet.anchor), which the keys and the thumb carry: he dances around
  // it, and his own hips covered 0.87 m idle against 1.32 m steered in one CI run of built.test
  // (60 steps held), where the spot stays put unless steered.
  const start = await reset(page);
  await hold();
  await waitSteps(page, steps);
  await release();
  const end = await duet(page);
  return { start: [...start.anchor], end: [...end.anchor], moved: distance(start.anchor, end.anchor) };
}

/**
 * A screenshot (PNG bytes) decoded in the page (no image library needed), on a canvas `scale`
 * times its size (smoothed): a handle for the caller's own evaluate().
 */
export function pngCanvas(page, png, scale = 1) {
  return page.evaluateHandle(
    async ({ src, scale }) => {
      const image = new Image();
      image.src = src;
      await image.decode();
      const canvas = document.createElement('canvas');
      canvas.width = Math.round(image.naturalWidth * scale);
      canvas.height = Math.round(image.naturalHeight * scale);
      const context = canvas.getContext('2d');
      context.imageSmoothingQuality = 'high';
      context.drawImage(image, 0, 0, canvas.width, canvas.height);
      return canvas;
    },
    { src: `data:image/png;base64,${png.toString('base64')}`, scale },
  );
}

/** Check that a screenshot is not blank: the variance of its luminance. */
export async function pixelVariance(page, png) {
  const canvas = await pngCanvas(page, png);
  return canvas.evaluate((canvas) => {
    const { data } = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height);
    let sum = 0;
    let sumSquares = 0;
    const n = data.length / 4;
    for (let i = 0; i < data.length; i += 4) {
      const y = 0.299 * data[i] + 0.587 * data[i + 1] + 0.114 * data[i + 2];
      sum += y;
      sumSquares += y * y;
    }
    const mean = sum / n;
    return sumSquares / n - mean * mean;
  });
}

/** Touch drag through the DevTools protocol (Playwright has no touch-move API). */
export async function touchDrag(page, from, to, steps = 8) {
  const cdp = await page.context().newCDPSession(page);
  const point = (x, y) => [{ x, y, id: 1, radiusX: 8, radiusY: 8, force: 1 }];
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: point(from[0], from[1]) });
  for (let i = 1; i <= steps; i++) {
    const x = from[0] + ((to[0] - from[0]) * i) / steps;
    const y = from[1] + ((to[1] - from[1]) * i) / steps;
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: point(x, y) });
  }
  return {
    release: async () => {
      await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
      await cdp.detach();
    },
  };
}
