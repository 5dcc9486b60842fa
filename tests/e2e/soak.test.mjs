// Browser soak: the built site (vite preview, COOP/COEP on, as shipped) in headless Chromium,
// steered with random arrow keys that change every 0.5-3 s, for DUET_SOAK_SECONDS (default 120,
// `npm run soak:browser` runs 600). Once a second it checks that the page reports no error and
// that the follower is within 3 m of the leader; at the end, that the simulation kept stepping,
// that nothing was logged as an error, and that memory did not grow:
//   - the main thread's JS heap after forced garbage collection (CDP HeapProfiler.collectGarbage,
//     then Runtime.getHeapUsage), start = after a 10 s warm-up, end = after the soak;
//   - onnxruntime's WebAssembly memory (it only ever grows, so a tensor that is never freed shows
//     up here and not in the JS heap);
//   - DOM nodes and JS event listeners (CDP Performance.getMetrics).
// The numbers are printed as test diagnostics ("# heap ...") so they can be quoted.
//
// Run: node --test tests/e2e/soak.test.mjs        DUET_SOAK_SECONDS=600 for the long one.

import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { QUICK, WAIT_MS, builtSite, distance, duet, launch, sleep, startServer, waitReady } from './harness.mjs';

const SOAK_SECONDS = Number(process.env.DUET_SOAK_SECONDS ?? 120);
const WARMUP_SECONDS = 10;
const SAMPLE_MS = 1000;
/** Also measure the heap (after GC) this often, to print its trend: a leak climbs steadily. */
const TRACE_MS = 30_000;
/** Seed of the steering sequence (DUET_SOAK_SEED), so a failing run can be repeated. */
const STEER_SEED = Number(process.env.DUET_SOAK_SEED ?? 1);
const MAX_PARTNER_DISTANCE = 3;
/**
 * JS heap growth allowed from start to end: 10 %, or 1 MiB when that is more. The heap here is only
 * about 6 MiB after a collection (three.js scene, ORT's JS side, the panel), so 10 % is ~0.6 MiB,
 * and that much is a bounded warm-up, not a leak: measured here over 600 s, the heap after GC went
 * 6.00 → 6.26 → 6.30 → 6.34 → 6.39 → 6.48 → 6.49 → 6.52 → 6.55 MiB in the first 4 minutes (most
 * likely V8's lazily compiled and optimised code and type feedback, which lives on the heap and
 * grows as new paths first run: key combinations, guards, HUD values) and then stayed within
 * 6.53-6.61 MiB for the last 5 minutes
 * (+601 KiB = 9.8 % in all, right at the 10 % line). So the floor, and for runs of 5 minutes or
 * more a second check on the second half alone, where a real leak (something kept per step: 30
 * steps/s) keeps climbing: 100 bytes per step is 0.9 MiB over the second half of 10 minutes.
 */
const MAX_HEAP_GROWTH = 0.1;
const HEAP_GROWTH_FLOOR_BYTES = 1 << 20;
/** Growth allowed over the second half of a soak of at least LATE_CHECK_SECONDS. */
const LATE_GROWTH_BYTES = 256 << 10;
const LATE_CHECK_SECONDS = 300;
/**
 * The WebAssembly memory only ever grows, in steps of about a fifth (16.00 -> 19.25 MiB). Since the
 * leader of the evening of 2026-11-27 it took one such step during two full `npm test` runs (both on
 * a loaded machine) and none in a run of this file alone; the cause is not found (the guards'
 * batches are warmed up when the sessions are made, so it is not their first run). One step is
 * allowed; a leak (something kept per step, 30 steps a second) takes step after step.
 */
const MAX_WASM_GROWTH = 0.25;
/** The simulation must step at least this often (slow motion on a loaded machine is fine). */
const MAX_STALL_MS = WAIT_MS;
/**
 * Steps the soak dances at the least: a third of real time. On a busy machine the page dances in
 * slow motion; the soak then goes on past SOAK_SECONDS until it has danced these (a wait on the
 * page, not a check of its speed: `npm run bench` measures that).
 */
const MIN_STEPS = SOAK_SECONDS * 10;
const ARROWS = ['ArrowUp', 'ArrowDown', 'ArrowLeft', 'ArrowRight'];

/** Installed before any page script: remember the WebAssembly memories the page creates (ORT's
 *  threaded build creates its memory in JS), so the test can read their size. */
function watchWasmMemory() {
  window.__wasmMemories = [];
  WebAssembly.Memory = new Proxy(WebAssembly.Memory, {
    construct(target, args, newTarget) {
      const memory = Reflect.construct(target, args, newTarget);
      window.__wasmMemories.push(memory);
      return memory;
    },
  });
}

let site;
let server;
let browser;

before(async () => {
  site = await builtSite('duet-soak-');
  server = await startServer({ mode: 'preview', outDir: site.dir });
  browser = await launch(QUICK);
});

after(async () => {
  await browser?.close();
  await server?.stop();
  site?.remove();
});

const mb = (bytes) => `${(bytes / 2 ** 20).toFixed(2)} MiB`;

test(`soak: ${SOAK_SECONDS} s of random steering in Chromium`, { timeout: (SOAK_SECONDS + WARMUP_SECONDS) * 3000 + 5 * WAIT_MS }, async (t) => {
  const { page, consoleErrors } = browser;
  await page.addInitScript(watchWasmMemory);
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('Performance.enable');
  /** Memory after forcing garbage collection (twice: the first can leave finalizable objects). */
  const memory = async () => {
    await cdp.send('HeapProfiler.collectGarbage');
    await cdp.send('HeapProfiler.collectGarbage');
    const heap = await cdp.send('Runtime.getHeapUsage');
    const metrics = Object.fromEntries((await cdp.send('Performance.getMetrics')).metrics.map((m) => [m.name, m.value]));
    const wasm = await page.evaluate(() => window.__wasmMemories.reduce((sum, m) => sum + m.buffer.byteLength, 0));
    return { heap: heap.usedSize, heapTotal: heap.totalSize, wasm, nodes: metrics.Nodes, listeners: metrics.JSEventListeners };
  };

  let random = STEER_SEED >>> 0 || 1;
  const next = () => (random = (Math.imul(random, 1103515245) + 12345) >>> 0) / 2 ** 32;
  let held = [];
  let changeAt = 0;
  let changes = 0;
  /** New random arrows (none, one or two) when their time is up; next change in 0.5-3 s. */
  const steer = async (now) => {
    if (now < changeAt) return;
    for (const key of held) await page.keyboard.up(key);
    const count = Math.floor(next() * 3);
    held = [...new Set(Array.from({ length: count }, () => ARROWS[Math.floor(next() * ARROWS.length)]))];
    for (const key of held) await page.keyboard.down(key);
    changeAt = now + 500 + next() * 2500;
    changes++;
  };

  await page.goto(`${server.url}?seed=11`);
  await waitReady(page);
  const warmupEnd = Date.now() + WARMUP_SECONDS * 1000;
  while (Date.now() < warmupEnd) {
    await steer(Date.now());
    await sleep(100);
  }
  const start = await memory();
  const first = await duet(page);
  t.diagnostic(`start (after ${WARMUP_SECONDS} s warm-up, ${first.frame} steps, ${first.threads} threads): heap ${mb(start.heap)} (total ${mb(start.heapTotal)}), wasm ${mb(start.wasm)}, ${start.nodes} nodes, ${start.listeners} listeners`);

  const began = Date.now();
  const end = began + SOAK_SECONDS * 1000;
  let worst = 0;
  let samples = 0;
  let last = first;
  let lastProgress = began;
  let nextSample = began;
  let nextTrace = began + TRACE_MS;
  const trace = [{ at: 0, heap: start.heap, wasm: start.wasm }];
  while (Date.now() < end || last.frame - first.frame < MIN_STEPS) {
    const now = Date.now();
    await steer(now);
    if (now >= nextSample) {
      nextSample += SAMPLE_MS;
      const state = await duet(page);
      samples++;
      assert.equal(state.error, null, `page error after ${((now - began) / 1000).toFixed(0)} s`);
      const apart = distance(state.leader.root, state.follower.root);
      worst = Math.max(worst, apart);
      assert.ok(apart < MAX_PARTNER_DISTANCE, `follower ${apart.toFixed(2)} m from the leader after ${((now - began) / 1000).toFixed(0)} s`);
      if (state.frame > last.frame) lastProgress = now;
      assert.ok(now - lastProgress < MAX_STALL_MS, `no step for ${((now - lastProgress) / 1000).toFixed(0)} s`);
      last = state;
    }
    if (now >= nextTrace) {
      nextTrace += TRACE_MS;
      const m = await memory();
      trace.push({ at: now - began, heap: m.heap, wasm: m.wasm });
    }
    await sleep(Math.max(10, Math.min(100, nextSample - Date.now(), changeAt - Date.now())));
  }
  for (const key of held) await page.keyboard.up(key);
  const seconds = (Date.now() - began) / 1000;
  const final = await duet(page);
  const stop = await memory();

  const steps = final.frame - first.frame;
  const growth = stop.heap - start.heap;
  const allowed = Math.max(MAX_HEAP_GROWTH * start.heap, HEAP_GROWTH_FLOOR_BYTES);
  t.diagnostic(
    `end (after ${seconds.toFixed(0)} s, ${steps} steps = ${(steps / seconds).toFixed(1)}/s, ${changes} steering changes, ${samples} samples): ` +
      `heap ${mb(stop.heap)} (total ${mb(stop.heapTotal)}), wasm ${mb(stop.wasm)}, ${stop.nodes} nodes, ${stop.listeners} listeners`,
  );
  trace.push({ at: seconds * 1000, heap: stop.heap, wasm: stop.wasm });
  t.diagnostic(`heap every ${TRACE_MS / 1000} s (MiB): ${trace.map(({ heap }) => (heap / 2 ** 20).toFixed(2)).join(' ')}`);
  t.diagnostic(`wasm every ${TRACE_MS / 1000} s (MiB): ${trace.map(({ wasm }) => (wasm / 2 ** 20).toFixed(2)).join(' ')}`);
  // Heap at the trace point closest to half-time, for the second-half check.
  const half = trace.reduce((best, p) => (Math.abs(p.at - (seconds * 500)) < Math.abs(best.at - seconds * 500) ? p : best));
  const lateGrowth = stop.heap - half.heap;
  t.diagnostic(`heap growth over the last ${(seconds - half.at / 1000).toFixed(0)} s: ${(lateGrowth / 1024).toFixed(0)} KiB`);
  t.diagnostic(
    `heap growth ${(growth / 1024).toFixed(0)} KiB = ${((100 * growth) / start.heap).toFixed(1)} % (allowed ${(allowed / 1024).toFixed(0)} KiB); ` +
      `wasm growth ${(stop.wasm - start.wasm) / 1024} KiB; worst partner distance ${worst.toFixed(2)} m; step median ${final.stepMs.median.toFixed(2)} ms, p95 ${final.stepMs.p95.toFixed(2)} ms`,
  );

  assert.equal(final.error, null);
  assert.ok(steps >= MIN_STEPS, `only ${steps} steps`);
  assert.ok(samples >= Math.min(10, SOAK_SECONDS), `only ${samples} samples`);
  assert.ok(growth < allowed, `JS heap grew ${(growth / 1024).toFixed(0)} KiB (${mb(start.heap)} -> ${mb(stop.heap)})`);
  if (SOAK_SECONDS >= LATE_CHECK_SECONDS) {
    assert.ok(lateGrowth < LATE_GROWTH_BYTES, `JS heap grew ${(lateGrowth / 1024).toFixed(0)} KiB over the second half (still climbing: a leak?)`);
  }
  assert.ok(start.wasm > 0, 'the WebAssembly memory was found');
  assert.ok(stop.wasm <= start.wasm * (1 + MAX_WASM_GROWTH), `WebAssembly memory grew ${mb(start.wasm)} -> ${mb(stop.wasm)}`);
  assert.ok(stop.nodes <= start.nodes + 20, `DOM nodes ${start.nodes} -> ${stop.nodes}`);
  assert.ok(stop.listeners <= start.listeners + 20, `event listeners ${start.listeners} -> ${stop.listeners}`);
  assert.deepEqual(consoleErrors, []);
});
