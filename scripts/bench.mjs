// Browser benchmark of the shipped page: builds dist/, serves it with `vite preview` (COOP/COEP
// on, so two WASM threads are possible) and loads it cold in headless Chromium, once per thread
// count. Prints, per run: simulation step time (median/p95 over the last 300 steps: features +
// both models + pose) and the networks' part of it (onnxruntime's runs), cold load to the first
// dancing frame on screen, and the page weight (raw and gzip) of everything the page downloaded
// to get there.
//
//   npm run bench                 # threads 1 and 2
//   node scripts/bench.mjs --seconds 20 --json
//   npm run bench -- --leading    # the same, T pressed every 2 s: every step leads her turn
//   npm run bench -- --count-cost # each thread count also without the manifest's onCount, alternating:
//                                 # what choosing on the count costs a step, as a ratio in one run
//   npm run bench -- --viewport 320x240   # a smaller window: less software drawing beside the networks
//   node scripts/bench_networks.mjs       # the networks alone, in Node, for the same runs
//   npm run bench -- --phone      # a phone on a mobile network: see scripts/bench_phone.mjs
//   npm run bench -- --phone --boot-only --query threads=1   # only the two visits, extra URL settings
//
// Timings on a 2-core machine with software WebGL vary by ±20 % between runs.

import { gzipSync } from 'node:zlib';
import { build, duet, launch, sleep, startServer, waitReady } from '../tests/e2e/harness.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(`--${name}`);
  return i >= 0 ? args[i + 1] : fallback;
};
const seconds = Number(option('seconds', 14)); // >= 10 s so the 300-step window is full
const threadCounts = option('threads', '1,2').split(',').map(Number);
const json = args.includes('--json');
// While a turn is led the leader's guard draws its samples every step (leaderGuard.keepPlan), so the
// step costs more then: --leading presses T every 2 s (a request lasts 2.5 s) to time those steps.
const leading = args.includes('--leading');
// Both dancers choose each step among onCount.samples at once (web/mirror/on_count.ts): --count-cost
// also runs the page with the manifest's onCount taken out, so the two step times share one machine state.
const countCost = args.includes('--count-cost');
// The page's window, WIDTHxHEIGHT (default: the harness's). On this machine WebGL is software
// (SwiftShader) and shares the CPU with the networks: a small window draws less a frame (and more
// frames), which tells whether the drawing is what slows the step (docs/measurements.md: it is not).
const viewportOption = option('viewport', null);
const viewport = viewportOption ? viewportOption.split('x').map(Number) : null;
if (viewport && !(viewport.length === 2 && viewport.every((n) => Number.isInteger(n) && n >= 100))) {
  console.error(`--viewport ${viewportOption}: WIDTHxHEIGHT in pixels, each at least 100`);
  process.exit(2);
}

/** Waits `ms`, pressing T every 2 s when --leading. */
async function dance(page, ms) {
  if (!leading) return sleep(ms);
  for (let t = 0; t < ms; t += 2000) {
    await page.keyboard.press('t');
    await sleep(Math.min(2000, ms - t));
  }
}

const mb = (bytes) => `${(bytes / 1e6).toFixed(2)} MB`;

async function run(url, threads, withoutCount = false) {
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
    await dance(page, (seconds * 1000) / 2);
    await page.keyboard.up('ArrowUp');
    await page.keyboard.down('ArrowLeft');
    await dance(page, (seconds * 1000) / 2);
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

if (args.includes('--phone')) {
  const { benchPhone } = await import('./bench_phone.mjs');
  await benchPhone({ json, seconds, bootOnly: args.includes('--boot-only'), query: option('query', ''), dist: option('dist', null) });
  process.exit(0);
}

await build('dist');
const server = await startServer({ mode: 'preview', outDir: 'dist' });
const results = [];
try {
  for (const threads of threadCounts) {
    results.push(await run(server.url, threads));
    if (countCost) results.push(await run(server.url, threads, true));
  }
} finally {
  await server.stop();
}

if (json) {
  console.log(JSON.stringify(results, null, 1));
} else {
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
