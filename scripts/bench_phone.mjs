// `npm run bench -- --phone`: the built site as a phone on a mobile network sees it. Serves dist/
// with scripts/serve.mjs (precompressed files, COOP/COEP) and drives headless Chromium with the
// throttling web performance audits use for phones: 4× slower CPU (Emulation.setCPUThrottlingRate),
// 9 Mbit/s down and 40 ms round trips (Network.emulateNetworkConditions), a 412 × 823 touch screen.
//
// Prints, for a cold first visit: first paint, the loading scene on screen (floor + standing pair
// + loading bar: first as index.html's picture of it, element timing "poster", then live,
// window.duet.sceneMs), the first dancing frame on screen (window.duet.firstFrameMs),
// both once the rendering update that paints them has run, not when their draw calls were issued
// (the software GPU of a headless browser spends 0.3-0.6 s on a first frame after that); the same
// for a repeat visit with the service worker warm; the model step median at 4× CPU; and frames per
// second drawing both dancers as skinned bodies and as ?bodies=sticks (skipped when the page has
// no window.duet.bodies). Then, for each visit, where the time went: the page's boot stages
// (window.duet.bootTimings: main.ts running, the manifest, the fetcher worker's downloads and wasm
// compilation, each session, the first step and the first drawn dancing frame), every
// WebAssembly compile/instantiate call, and every file with its timing and bytes (the fetcher
// worker's too, from window.duet.workerFiles).
//
//   npm run bench -- --phone --boot-only                 # the two visits only
//   npm run bench -- --phone --boot-only --query threads=1
//   npm run bench -- --phone --boot-only --dist /tmp/dist-old   # a site built before (A/B runs)
//
// CPU throttling applies to the page's main thread only (Chromium cannot throttle workers):
// onnxruntime's second thread, the fetcher worker and Chromium's software WebGL run at full
// speed, so the step and frame-rate numbers flatter a phone.

import { existsSync } from 'node:fs';
import { build, launch, sleep } from '../tests/e2e/harness.mjs';
import { serve } from './serve.mjs';

const PHONE = { viewport: { width: 412, height: 823 }, deviceScaleFactor: 1.75, isMobile: true, hasTouch: true };
const NETWORK = { offline: false, latency: 40, downloadThroughput: (9e6 / 8) | 0, uploadThroughput: (1.6e6 / 8) | 0 };
const TARGETS = { sceneMs: 1500, firstFrameMs: 6000, repeatMs: 2000, stepMs: 6 };

async function throttle(page) {
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('Network.enable');
  await cdp.send('Network.emulateNetworkConditions', NETWORK);
  await cdp.send('Emulation.setCPUThrottlingRate', { rate: 4 });
  return cdp;
}

/** Load `url` and wait for the first dancing frame; the page's own timings, ms from navigation. */
async function visit(page, url, timeoutMs = 90_000) {
  await page.goto(url, { waitUntil: 'commit' });
  await page.waitForFunction(() => window.duet && (window.duet.firstFrameMs || window.duet.error), null, { timeout: timeoutMs, polling: 50 });
  return page.evaluate(async () => {
    // index.html's picture of the loading scene (elementtiming="poster"): when it was painted.
    const posterMs = await new Promise((resolve) => {
      const observer = new PerformanceObserver((list) => {
        const entry = list.getEntries().find((e) => e.identifier === 'poster');
        if (entry) resolve(entry.renderTime || entry.loadTime);
      });
      observer.observe({ type: 'element', buffered: true });
      setTimeout(() => resolve(null), 200); // never painted: the live scene came first
    });
    const paint = Object.fromEntries(performance.getEntriesByType('paint').map((e) => [e.name, e.startTime]));
    // The runtime worker's downloads (wasm, models) are in its own resource timing, not the page's.
    const workerFiles = window.duet.workerFiles ?? [];
    const transferred = performance.getEntriesByType('resource').reduce((sum, e) => sum + e.transferSize, 0) +
      workerFiles.reduce((sum, f) => sum + f.transferSize, 0) +
      (performance.getEntriesByType('navigation')[0]?.transferSize ?? 0);
    return {
      error: window.duet.error,
      firstPaintMs: paint['first-paint'] ?? null,
      firstContentfulPaintMs: paint['first-contentful-paint'] ?? null,
      posterMs,
      sceneMs: window.duet.sceneMs ?? null,
      firstFrameMs: window.duet.firstFrameMs,
      download: window.duet.download ?? null,
      transferredBytes: transferred,
      controlled: !!navigator.serviceWorker?.controller,
      threads: window.duet.threads,
      boot: { ...(window.duet.bootTimings ?? {}) },
      wasmCalls: window.__benchWasmCalls ?? [],
      navigation: (({ responseStart, responseEnd, domContentLoadedEventEnd }) => ({ responseStart, responseEnd, domContentLoadedEventEnd }))(performance.getEntriesByType('navigation')[0] ?? {}),
      resources: [
        ...performance.getEntriesByType('resource').map((e) => ({
          name: e.name.replace(location.origin, ''),
          startTime: e.startTime,
          responseStart: e.responseStart,
          responseEnd: e.responseEnd,
          transferSize: e.transferSize,
          encodedBodySize: e.encodedBodySize,
        })),
        ...workerFiles.map((f) => ({
          name: `${f.url.replace(location.origin, '')} (worker)`,
          startTime: f.start,
          responseStart: f.firstByte,
          responseEnd: f.end,
          transferSize: f.transferSize,
          encodedBodySize: f.encodedBodySize,
        })),
      ],
    };
  });
}

/**
 * Before any script of the page: time every WebAssembly compile and instantiate call, so that the
 * boot breakdown shows wasm compilation apart from session creation (onnxruntime does both inside
 * its first InferenceSession.create). Measurement only: the page works the same without it.
 */
function wasmTimingScript() {
  const calls = (window.__benchWasmCalls = []);
  for (const name of ['compile', 'instantiate', 'compileStreaming', 'instantiateStreaming']) {
    const original = WebAssembly[name];
    if (!original) continue;
    WebAssembly[name] = function (...args) {
      const call = { name, start: performance.now(), end: null, module: args[0] instanceof WebAssembly.Module };
      calls.push(call);
      const result = original.apply(this, args);
      result.then(() => (call.end = performance.now()), () => (call.end = -1));
      return result;
    };
  }
}

/** Stage timings (window.duet.bootTimings) and each downloaded file, for one visit. */
function printBreakdown(visit) {
  const s = (ms) => (ms === null || ms === undefined ? '    —  ' : `${(ms / 1000).toFixed(2)} s`.padStart(7));
  const { boot, navigation } = visit;
  console.log(`  html: response ${s(navigation.responseStart)} – ${s(navigation.responseEnd)}, DOMContentLoaded ${s(navigation.domContentLoadedEventEnd)}`);
  const spans = new Map();
  const points = [];
  for (const [key, at] of Object.entries(boot)) {
    const m = /^(.*):(start|end)$/.exec(key);
    if (m) spans.set(m[1], { ...spans.get(m[1]), [m[2]]: at });
    else points.push([key, at]);
  }
  const lines = [
    ...points.map(([name, at]) => [at, `  ${name.padEnd(26)} ${s(at)}`]),
    ...[...spans].map(([name, { start, end }]) => [start, `  ${name.padEnd(26)} ${s(start)} – ${s(end)}  (${end !== undefined ? `${Math.round(end - start)} ms` : 'unfinished'})`]),
    ...visit.wasmCalls.map((c) => [c.start, `  WebAssembly.${c.name}${c.module ? '(Module)' : ''}`.padEnd(28) + ` ${s(c.start)} – ${s(c.end)}  (${Math.round(c.end - c.start)} ms)`]),
  ];
  for (const [, line] of lines.sort((a, b) => a[0] - b[0])) console.log(line);
  console.log('  resources (start – first byte – end, bytes over the wire / encoded body):');
  for (const r of [...visit.resources].sort((a, b) => a.startTime - b.startTime)) {
    console.log(`    ${r.name.slice(0, 48).padEnd(48)} ${s(r.startTime)} ${s(r.responseStart)} ${s(r.responseEnd)}  ${(r.transferSize / 1e3).toFixed(0).padStart(6)} kB / ${(r.encodedBodySize / 1e3).toFixed(0).padStart(6)} kB`);
  }
}

/** Entries the service worker has stored, once it holds the wasm and the models (or after 60 s). */
async function waitOfflineCache(page) {
  const deadline = Date.now() + 60_000;
  for (;;) {
    const urls = await page.evaluate(async () => {
      const all = [];
      for (const name of await caches.keys()) for (const r of await (await caches.open(name)).keys()) all.push(r.url);
      return all;
    });
    const wasm = urls.some((u) => u.endsWith('.wasm'));
    const models = urls.filter((u) => u.endsWith('.onnx')).length;
    if ((wasm && models >= 2) || Date.now() > deadline) return urls;
    await sleep(250);
  }
}

async function framesPerSecond(page, url, ms = 4000) {
  await page.goto(url);
  await page.waitForFunction(() => window.duet && (window.duet.ready || window.duet.error), null, { timeout: 90_000, polling: 50 });
  const bodies = await page.evaluate(() => window.duet.bodies ?? null);
  await sleep(1000);
  // Frames the page drew (window.duet.drawn): it skips the draw of an animation frame in which it
  // waits for the models, so animation frames alone would overstate it.
  const fps = await page.evaluate(
    (duration) =>
      new Promise((resolve) => {
        const drawn = () => window.duet.drawn ?? 0;
        const start = performance.now();
        const first = drawn();
        let frames = 0;
        const tick = () => {
          frames++;
          if (performance.now() - start < duration) return requestAnimationFrame(tick);
          const elapsed = performance.now() - start;
          resolve((((window.duet.drawn === undefined ? frames : drawn() - first)) * 1000) / elapsed);
        };
        requestAnimationFrame(tick);
      }),
    ms,
  );
  return { bodies, fps };
}

export async function benchPhone({ json = false, seconds = 14, breakdown = true, bootOnly = false, query = '', dist = null } = {}) {
  if (!dist) await build('dist');
  else if (!existsSync(`${dist}/index.html`)) throw new Error(`--dist ${dist}: no index.html there (build one with: npx vite build --outDir ${dist})`);
  const server = await serve({ dir: dist ?? 'dist' });
  const browser = await launch(PHONE);
  const result = {};
  try {
    const { page } = browser;
    await page.addInitScript(wasmTimingScript);
    await throttle(page);
    const url = `${server.url}?seed=1${query ? `&${query}` : ''}`;
    result.cold = await visit(page, url);
    result.cached = (await waitOfflineCache(page)).length;
    result.repeat = await visit(page, url);
    if (!bootOnly) {
      // Step time at 4× CPU while steering, on the warm page.
      await page.keyboard.down('ArrowUp');
      await sleep((seconds * 1000) / 2);
      await page.keyboard.up('ArrowUp');
      await sleep((seconds * 1000) / 2);
      result.stepMs = await page.evaluate(() => window.duet.stepMs);
      result.networkMs = await page.evaluate(() => window.duet.networkMs);

      result.fps = {
        skinned: await framesPerSecond(page, url),
        sticks: await framesPerSecond(page, `${url}&bodies=sticks`),
      };
    }
  } finally {
    result.consoleErrors = browser.consoleErrors;
    await browser.close();
    await server.stop();
  }
  return printResult(result, { json, breakdown });
}

function printResult(result, { json, breakdown }) {
  if (json) {
    console.log(JSON.stringify(result, null, 1));
    return result;
  }
  const s = (ms) => (ms === null || ms === undefined ? '   —  ' : `${(ms / 1000).toFixed(2)} s`);
  const mark = (value, target) => (value !== null && value !== undefined && value <= target ? 'ok' : 'MISSED');
  const { cold, repeat } = result;
  console.log('\nphone profile: CPU 4× slower, 9 Mbit/s down, 40 ms RTT, 412×823 @1.75, scripts/serve.mjs (br/gzip, COOP/COEP)');
  console.log(`first visit (${(cold.transferredBytes / 1e6).toFixed(2)} MB over the wire, ${cold.threads} threads)`);
  console.log(`  first paint              ${s(cold.firstPaintMs)}  (first contentful ${s(cold.firstContentfulPaintMs)})`);
  // On screen: once the rendering update that paints the frame has run (web/engine/boot.ts,
  // afterPaint). Drawn: when the page issued the frame's draw calls (the software GPU still
  // compiles and rasterizes it after that); step: the first dancing pose computed.
  // The loading scene is on screen first as index.html's picture of it (scripts/poster.mjs), then
  // live: a visitor sees whichever came first; both are printed.
  const shown = (visit) => [visit.posterMs, visit.sceneMs].filter((ms) => ms !== null && ms !== undefined).sort((a, b) => a - b)[0] ?? null;
  const drawn = (visit) => `(picture ${s(visit.posterMs)}, live scene ${s(visit.sceneMs)}, drawn ${s(visit.boot.scene)})`;
  const danced = (visit) => `(step ${s(visit.boot['first-step'])}, drawn ${s(visit.boot['first-drawn'])})`;
  console.log(`  loading scene on screen  ${s(shown(cold))}  target ≤ ${s(TARGETS.sceneMs)}  ${mark(shown(cold), TARGETS.sceneMs)}  ${drawn(cold)}`);
  console.log(`  first dancing frame      ${s(cold.firstFrameMs)}  target ≤ ${s(TARGETS.firstFrameMs)}  ${mark(cold.firstFrameMs, TARGETS.firstFrameMs)}  ${danced(cold)}`);
  console.log(`repeat visit (service worker ${repeat.controlled ? 'in control' : 'NOT in control'}, ${result.cached} files cached, ${(repeat.transferredBytes / 1e6).toFixed(2)} MB over the wire)`);
  console.log(`  first paint              ${s(repeat.firstPaintMs)}`);
  console.log(`  loading scene on screen  ${s(shown(repeat))}  ${drawn(repeat)}`);
  console.log(`  first dancing frame      ${s(repeat.firstFrameMs)}  target ≤ ${s(TARGETS.repeatMs)}  ${mark(repeat.firstFrameMs, TARGETS.repeatMs)}  ${danced(repeat)}`);
  if (!result.stepMs) {
    printBreakdowns(result, breakdown);
    return result;
  }
  console.log(`model step at 4× CPU       median ${result.stepMs.median.toFixed(2)} ms, p95 ${result.stepMs.p95.toFixed(2)} ms  target ≤ ${TARGETS.stepMs} ms  ${mark(result.stepMs.median, TARGETS.stepMs)}`);
  console.log(`  ... networks             median ${result.networkMs.median.toFixed(2)} ms, p95 ${result.networkMs.p95.toFixed(2)} ms (onnxruntime's runs in each step)`);
  const { skinned, sticks } = result.fps;
  if (!skinned.bodies) {
    console.log('drawing both dancers       skipped: this page has no window.duet.bodies (no skinned bodies / ?bodies=sticks switch yet)');
  } else {
    console.log(`drawing both dancers       ${skinned.bodies}: ${skinned.fps.toFixed(1)} fps   ${sticks.bodies}: ${sticks.fps.toFixed(1)} fps  (4× CPU, software WebGL)`);
  }
  printBreakdowns(result, breakdown);
  return result;
}

function printBreakdowns({ cold, repeat, consoleErrors }, breakdown) {
  if (breakdown) {
    console.log('\nfirst visit, stage by stage (ms since navigation):');
    printBreakdown(cold);
    console.log('\nrepeat visit, stage by stage:');
    printBreakdown(repeat);
  }
  if (cold.error || repeat.error) console.log(`page error: ${cold.error ?? repeat.error}`);
  if (consoleErrors.length) console.log(`console errors: ${consoleErrors.join(' | ')}`);
}
