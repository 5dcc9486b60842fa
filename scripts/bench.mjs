// Benchmarks of the shipped page, three kinds, all through `npm run bench`:
//
// The page (default): builds dist/, serves it with `vite preview` (COOP/COEP on, so two WASM
// threads are possible) and loads it cold in headless Chromium, once per thread count. Prints, per
// run: simulation step time (median/p95 over the last 300 steps: features + both models + pose) and
// the networks' part of it (onnxruntime's runs), cold load to the first dancing frame on screen, and
// the page weight (raw and gzip) of everything the page downloaded to get there.
//
// The networks alone (--networks): the shipped networks in Node's onnxruntime-web (the page's
// WebAssembly build, one thread), nothing else running in the process: the median time of one run
// of each model and of a step's two runs (his, then hers), for each number of samples drawn at once.
// Beside the page's "networks" line (the same runs inside the dancing page) it tells how much of a
// step the networks need and how much the page around them costs them.
//
// A phone (--phone): the built site as a phone on a mobile network sees it, served by
// scripts/serve.mjs (precompressed files, COOP/COEP): first paint, the loading scene and the first
// dancing frame on screen for a cold and a repeat visit, the step at 4× CPU, frames per second, and
// where each visit's time went (phoneBench below says what each number is).
//
//   npm run bench                 # threads 1 and 2
//   node scripts/bench.mjs --seconds 20 --json
//   npm run bench -- --leading    # the same, T pressed every 2 s: every step leads her turn
//   npm run bench -- --threads 1 --dist /tmp/dist-old   # a site built before (A/B runs of two builds)
//   npm run bench -- --count-cost # each thread count also without the manifest's onCount, alternating:
//                                 # what choosing on the count costs a step, as a ratio in one run
//   npm run bench -- --viewport 320x240   # a smaller window: less software drawing beside the networks
//   npm run bench -- --networks           # the networks alone, in Node, samples 1 and 8 (a plain step,
//                                         # the choice on the count)
//   npm run bench -- --networks --samples 1,4,8,16 --runs 400 --models public/models
//   npm run bench -- --phone      # a phone on a mobile network
//   npm run bench -- --phone --boot-only                 # the two visits only
//   npm run bench -- --phone --boot-only --query threads=1   # extra URL settings
//   npm run bench -- --phone --boot-only --dist /tmp/dist-old   # a site built before (A/B runs)
//
// Timings on a 2-core machine with software WebGL vary by ±20 % between runs (the networks alone
// by about ±10 %): compare within one run.

import { existsSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { gzipSync } from 'node:zlib';
import { build, duet, launch, sleep, startServer, waitReady } from '../tests/e2e/harness.mjs';
import { serve } from './serve.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(`--${name}`);
  return i >= 0 ? args[i + 1] : fallback;
};
const seconds = Number(option('seconds', 14)); // >= 10 s so the 300-step window is full
const json = args.includes('--json');
const mb = (bytes) => `${(bytes / 1e6).toFixed(2)} MB`;

// ---------------------------------------------------------------------------------------------
// The page: step, cold load and page weight in headless Chromium, per thread count.
// ---------------------------------------------------------------------------------------------

/** Options of the page bench, parsed (and the window checked) only when that bench runs. */
function pageOptions() {
  // The page's window, WIDTHxHEIGHT (default: the harness's). On this machine WebGL is software
  // (SwiftShader) and shares the CPU with the networks: a small window draws less a frame (and more
  // frames), which tells whether the drawing is what slows the step (docs/measurements.md: it is not).
  const viewportOption = option('viewport', null);
  const viewport = viewportOption ? viewportOption.split('x').map(Number) : null;
  if (viewport && !(viewport.length === 2 && viewport.every((n) => Number.isInteger(n) && n >= 100))) {
    console.error(`--viewport ${viewportOption}: WIDTHxHEIGHT in pixels, each at least 100`);
    process.exit(2);
  }
  return {
    threadCounts: option('threads', '1,2').split(',').map(Number),
    // While a turn is led the leader's guard draws its samples every step (leaderGuard.keepPlan), so the
    // step costs more then: --leading presses T every 2 s (a request lasts 2.5 s) to time those steps.
    leading: args.includes('--leading'),
    // Both dancers choose each step among onCount.samples at once (web/mirror/on_count.ts): --count-cost
    // also runs the page with the manifest's onCount taken out, so the two step times share one machine state.
    countCost: args.includes('--count-cost'),
    viewport,
  };
}

/** Waits `ms`, pressing T every 2 s when `leading`. */
async function dance(page, ms, leading) {
  if (!leading) return sleep(ms);
  for (let t = 0; t < ms; t += 2000) {
    await page.keyboard.press('t');
    await sleep(Math.min(2000, ms - t));
  }
}

/** One cold load of the page at `url` with `threads`, steered for `seconds`: its timings and downloads. */
async function pageRun(url, threads, { leading, viewport }, withoutCount = false) {
  // A fresh profile: a cold load, nothing cached.
  const browser = await launch(viewport ? { viewport: { width: viewport[0], height: viewport[1] } } : {});
  const { page } = browser;
  if (withoutCount) {
    // The manifest as shipped, less onCount: each dancer takes its one sample (the worker's fetch too).
    await browser.context.route('**/models/manifest.json', async (route) => {
      const response = await route.fetch();
      const manifest = await response.json();
      delete manifest.onCount;
      await route.fulfill({ response, json: manifest });
    });
  }
  const downloads = new Map();
  page.on('response', async (response) => {
    try {
      const body = await response.body();
      downloads.set(response.url(), { bytes: body.length, gzip: gzipSync(body).length });
    } catch {
      // redirects and aborted requests have no body
    }
  });
  try {
    await page.goto(`${url}?seed=1&threads=${threads}`);
    await waitReady(page, 60_000);
    // Ready comes when the models are; the first dancing frame is on screen a paint later.
    await page.waitForFunction(() => window.duet.firstFrameMs, null, { timeout: 30_000, polling: 20 });
    const ready = await duet(page);
    // Snapshot what the page needed to react, before any lazily loaded extras.
    await sleep(200);
    const files = [...downloads.entries()];
    const transferred = await page.evaluate(() =>
      performance.getEntriesByType('resource').reduce((sum, e) => sum + e.transferSize, 0) +
      (performance.getEntriesByType('navigation')[0]?.transferSize ?? 0),
    );

    // Step time while steering, as a person would.
    await page.keyboard.down('ArrowUp');
    await dance(page, (seconds * 1000) / 2, leading);
    await page.keyboard.up('ArrowUp');
    await page.keyboard.down('ArrowLeft');
    await dance(page, (seconds * 1000) / 2, leading);
    await page.keyboard.up('ArrowLeft');
    const state = await duet(page);
    if (state.error) throw new Error(state.error);
    const fps = await page.evaluate(
      () =>
        new Promise((resolve) => {
          let frames = 0;
          const start = performance.now();
          const tick = () => (++frames, performance.now() - start < 2000 ? requestAnimationFrame(tick) : resolve((frames * 1000) / (performance.now() - start)));
          requestAnimationFrame(tick);
        }),
    );
    return {
      threads: state.threads,
      requestedThreads: threads,
      onCount: !withoutCount,
      counted: state.counted ?? 0,
      crossOriginIsolated: await page.evaluate(() => crossOriginIsolated),
      stepMs: state.stepMs,
      networkMs: state.networkMs,
      stepsPerSecond: state.frame / seconds,
      fps,
      coldLoadMs: ready.firstFrameMs,
      modelBytes: state.modelBytes,
      pageBytes: files.reduce((sum, [, f]) => sum + f.bytes, 0),
      pageGzipBytes: files.reduce((sum, [, f]) => sum + f.gzip, 0),
      transferredBytes: transferred,
      files: Object.fromEntries(files.map(([u, f]) => [new URL(u).pathname, f])),
      consoleErrors: browser.consoleErrors,
    };
  } finally {
    await browser.close();
  }
}

/** The built site to serve: --dist DIR (built before, for A/B runs of two builds), else a fresh build in dist/. */
async function site() {
  const dist = option('dist', null);
  if (!dist) await build('dist');
  else if (!existsSync(`${dist}/index.html`)) throw new Error(`--dist ${dist}: no index.html there (build one with: npx vite build --outDir ${dist})`);
  return dist ?? 'dist';
}

async function pageBench() {
  const options = pageOptions();
  const { threadCounts, leading, countCost, viewport } = options;
  const server = await startServer({ mode: 'preview', outDir: await site() });
  const results = [];
  try {
    for (const threads of threadCounts) {
      results.push(await pageRun(server.url, threads, options));
      if (countCost) results.push(await pageRun(server.url, threads, options, true));
    }
  } finally {
    await server.stop();
  }

  if (json) {
    console.log(JSON.stringify(results, null, 1));
    return;
  }
  for (const r of results) {
    const count = countCost ? (r.onCount ? `, on the count (${r.counted} dancer-steps chosen)` : ', without onCount') : '';
    console.log(`\nthreads ${r.threads} (asked ${r.requestedThreads}, cross-origin isolated: ${r.crossOriginIsolated})${leading ? ', T every 2 s' : ''}${count}`);
    console.log(`  step            median ${r.stepMs.median.toFixed(2)} ms   p95 ${r.stepMs.p95.toFixed(2)} ms`);
    console.log(`  ... networks    median ${r.networkMs.median.toFixed(2)} ms   p95 ${r.networkMs.p95.toFixed(2)} ms (onnxruntime's runs in each step; the rest is the page's own work)`);
    console.log(`  cold load       ${(r.coldLoadMs / 1000).toFixed(2)} s to the first dancing frame on screen`);
    console.log(`  models          ${mb(r.modelBytes)}`);
    console.log(`  page weight     ${mb(r.pageBytes)} raw, ${mb(r.pageGzipBytes)} gzip (${mb(r.transferredBytes)} sent by vite preview)`);
    console.log(`  display         ${r.fps.toFixed(1)} fps (software WebGL in headless Chromium${viewport ? `, a ${viewport.join('x')} window` : ''})`);
    if (r.consoleErrors.length) console.log(`  console errors: ${r.consoleErrors.join(' | ')}`);
  }
  if (countCost) {
    for (let i = 0; i + 1 < results.length; i += 2) {
      const [on, off] = [results[i], results[i + 1]];
      console.log(`\nchoosing on the count, ${on.threads} thread${on.threads === 1 ? '' : 's'}: step median ${(on.stepMs.median / off.stepMs.median).toFixed(2)}x the step without it (${on.stepMs.median.toFixed(2)} / ${off.stepMs.median.toFixed(2)} ms)`);
    }
  }
  const largest = Object.entries(results[0].files).sort((a, b) => b[1].gzip - a[1].gzip).slice(0, 6);
  console.log('\nlargest downloads (gzip):');
  for (const [path, f] of largest) console.log(`  ${mb(f.gzip).padStart(9)}  ${path}`);
}

// ---------------------------------------------------------------------------------------------
// --networks: the shipped networks alone, in Node.
// ---------------------------------------------------------------------------------------------

// Between two steps the page draws, plays sound and builds features: by the next step the networks'
// weights (4 MB of int8) are no longer in the CPU's caches. A walk over CACHE_SWEEP bytes between two
// steps does the same here ("caches swept"); back to back, the weights stay in the caches.
const CACHE_SWEEP = 64 << 20;
let sweep = null; // allocated by the first sweep: only --networks needs its 64 MB
function sweepCaches() {
  sweep ??= new Float64Array(CACHE_SWEEP / 8);
  for (let i = 0; i < sweep.length; i += 8) sweep[i] += 1; // one touch per 64-byte line
}

const median = (a) => a.sort((x, y) => x - y)[a.length >> 1];

/** The manifest in `dir` and a session for the follower and the leader, with each one's input width. */
async function loadNetworks(ort, dir) {
  let manifest;
  try {
    manifest = JSON.parse(readFileSync(join(dir, 'manifest.json'), 'utf8'));
  } catch (error) {
    console.error(`error: ${join(dir, 'manifest.json')}: ${error.message}`);
    process.exit(2);
  }
  // The input width of each role, from the manifest's layout (the blocks the page writes).
  const width = (blocks) => blocks.reduce((sum, [, n]) => sum + n, 0);
  const widths = { leader: width(manifest.layout.leaderInput), follower: width(manifest.layout.followerInput) };
  const models = {};
  for (const name of ['follower', 'leader']) {
    const entry = manifest.models[name];
    const session = await ort.InferenceSession.create(readFileSync(join(dir, entry.file)), { executionProviders: ['wasm'], graphOptimizationLevel: 'all' });
    models[name] = { entry, session, width: widths[entry.role] ?? widths.follower };
  }
  return { manifest, models };
}

/** One run of model `name` drawing k samples, as a function: a neutral input (the normalized mean)
 *  and uniform noise, as the page's runs get. */
function runOf(ort, { manifest, models }, name, k) {
  const { entry, session, width } = models[name];
  const noise = entry.channels * entry.classes;
  const feeds = {
    input: new ort.Tensor('float32', new Float32Array(width), [1, width]),
    temperature: new ort.Tensor('float32', new Float32Array([manifest.defaultTemperature]), [1]),
    noise: new ort.Tensor('float32', new Float32Array(k * noise).map(() => Math.random()), [k, noise]),
  };
  const fetches = entry.intention ? ['output', 'intention'] : ['output'];
  return async () => {
    const outputs = await session.run(feeds, fetches);
    for (const tensor of Object.values(outputs)) tensor.dispose();
  };
}

/** Median ms of `body` over `runs` calls (after 30 to let onnxruntime plan its buffers), the caches
 *  swept before each call when `swept`. */
async function timeRuns(body, runs, swept) {
  for (let i = 0; i < 30; i++) await body();
  const times = [];
  for (let i = 0; i < runs; i++) {
    if (swept) sweepCaches();
    const started = performance.now();
    await body();
    times.push(performance.now() - started);
  }
  return median(times);
}

async function networksBench() {
  const dir = option('models', 'public/models');
  const samples = option('samples', '1,8').split(',').map(Number);
  const runs = Number(option('runs', 300));
  if (!samples.every((k) => Number.isInteger(k) && k >= 1) || !(runs >= 10)) {
    console.error('usage: npm run bench -- --networks [--samples 1,8] [--runs N (>= 10)] [--models DIR]');
    process.exit(2);
  }
  // Loaded here only: the page and phone benches run onnxruntime in the browser, not in Node.
  const ort = await import('onnxruntime-web/wasm');
  ort.env.wasm.numThreads = 1;
  ort.env.logLevel = 'error';
  const networks = await loadNetworks(ort, dir);

  console.log(`the networks alone (Node ${process.versions.node}, onnxruntime-web ${ort.env.versions.web}, 1 thread), median of ${runs} runs, ms:`);
  console.log(`  ${'samples'.padEnd(8)} ${'follower'.padStart(9)} ${'leader'.padStart(9)} ${'a step (both)'.padStart(14)} ${'... caches swept'.padStart(17)}`);
  for (const k of samples) {
    const follower = runOf(ort, networks, 'follower', k);
    const leader = runOf(ort, networks, 'leader', k);
    const step = async () => {
      await leader();
      await follower();
    };
    const cells = [await timeRuns(follower, runs, false), await timeRuns(leader, runs, false), await timeRuns(step, runs, false), await timeRuns(step, runs, true)];
    console.log(`  ${String(k).padEnd(8)} ${cells[0].toFixed(3).padStart(9)} ${cells[1].toFixed(3).padStart(9)} ${cells[2].toFixed(3).padStart(14)} ${cells[3].toFixed(3).padStart(17)}`);
  }
}

// ---------------------------------------------------------------------------------------------
// --phone: the built site as a phone on a mobile network sees it.
//
// Serves dist/ with scripts/serve.mjs (precompressed files, COOP/COEP) and drives headless Chromium
// with the throttling web performance audits use for phones: 4× slower CPU
// (Emulation.setCPUThrottlingRate), 9 Mbit/s down and 40 ms round trips
// (Network.emulateNetworkConditions), a 412 × 823 touch screen.
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
// worker's too, from window.duet.workerFiles). --boot-only stops after the two visits.
//
// CPU throttling applies to the page's main thread only (Chromium cannot throttle workers):
// onnxruntime's second thread, the fetcher worker and Chromium's software WebGL run at full
// speed, so the step and frame-rate numbers flatter a phone.
// ---------------------------------------------------------------------------------------------

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

async function phoneBench() {
  const bootOnly = args.includes('--boot-only');
  const query = option('query', '');
  const server = await serve({ dir: await site() });
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
  if (json) console.log(JSON.stringify(result, null, 1));
  else printPhone(result);
}

function printPhone(result) {
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
  if (result.stepMs) {
    console.log(`model step at 4× CPU       median ${result.stepMs.median.toFixed(2)} ms, p95 ${result.stepMs.p95.toFixed(2)} ms  target ≤ ${TARGETS.stepMs} ms  ${mark(result.stepMs.median, TARGETS.stepMs)}`);
    console.log(`  ... networks             median ${result.networkMs.median.toFixed(2)} ms, p95 ${result.networkMs.p95.toFixed(2)} ms (onnxruntime's runs in each step)`);
    const { skinned, sticks } = result.fps;
    if (!skinned.bodies) {
      console.log('drawing both dancers       skipped: this page has no window.duet.bodies (no skinned bodies / ?bodies=sticks switch yet)');
    } else {
      console.log(`drawing both dancers       ${skinned.bodies}: ${skinned.fps.toFixed(1)} fps   ${sticks.bodies}: ${sticks.fps.toFixed(1)} fps  (4× CPU, software WebGL)`);
    }
  }
  console.log('\nfirst visit, stage by stage (ms since navigation):');
  printBreakdown(cold);
  console.log('\nrepeat visit, stage by stage:');
  printBreakdown(repeat);
  if (cold.error || repeat.error) console.log(`page error: ${cold.error ?? repeat.error}`);
  if (result.consoleErrors.length) console.log(`console errors: ${result.consoleErrors.join(' | ')}`);
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

// ---------------------------------------------------------------------------------------------

if (args.includes('--networks')) {
  await networksBench();
} else if (args.includes('--phone')) {
  await phoneBench();
  process.exit(0); // at once: nothing the phone bench opened (server sockets, the CDP session) may keep Node waiting
} else {
  await pageBench();
}
