// The service worker (public/sw.js): after one visit of the built site, the page starts and
// dances with the network gone, and a second visit downloads nothing. Guards the path by which
// the page gets onnxruntime's wasm and the models (the fetcher worker, web/engine/fetcher.ts,
// and offline.ts): whatever fetches them must be seen by the service worker, or the offline
// start breaks without any other test noticing.

import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { QUICK, ROOT, WAIT_MS, build, duet, launch, sleep, waitReady, waitSteps } from './harness.mjs';
import { serve } from '../../scripts/serve.mjs';

let server;
let browser;

before(async () => {
  await build('dist');
  server = await serve({ dir: join(ROOT, 'dist'), base: '/duet/' });
  browser = await launch(QUICK);
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

/** URLs the service worker has stored, once it holds the wasm and the two first models. */
async function cachedUrls(page, timeoutMs = WAIT_MS) {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    const urls = await page.evaluate(async () => {
      const all = [];
      for (const name of await caches.keys()) for (const request of await (await caches.open(name)).keys()) all.push(request.url);
      return all;
    });
    if ((urls.some((u) => u.endsWith('.wasm')) && urls.filter((u) => u.endsWith('.onnx')).length >= 2) || Date.now() > deadline) return urls;
    await sleep(250);
  }
}

test('after one visit: a repeat visit downloads nothing, and the page dances offline', async () => {
  const { page, context } = browser;
  const url = `${server.url}?seed=2`;
  await page.goto(url);
  await waitReady(page);
  const urls = await cachedUrls(page);
  assert.ok(urls.some((u) => u.endsWith('.wasm')), `the wasm is cached: ${urls.join(', ')}`);
  for (const model of ['leader.onnx', 'follower.onnx']) assert.ok(urls.some((u) => u.endsWith(model)), `${model} is cached`);

  await page.goto(url);
  await waitReady(page);
  // The page's own downloads, and the fetcher worker's (wasm, manifest, models: window.duet.workerFiles).
  const transferred = await page.evaluate(() =>
    [...performance.getEntriesByType('resource'), ...(window.duet.workerFiles ?? [])].reduce((sum, e) => sum + e.transferSize, 0),
  );
  const workerFiles = await page.evaluate(() => (window.duet.workerFiles ?? []).map((f) => f.url));
  assert.ok(workerFiles.some((u) => u.endsWith('.wasm')) && workerFiles.some((u) => u.endsWith('.onnx')), `the worker's downloads are listed: ${workerFiles}`);
  assert.equal(transferred, 0, 'repeat visit: nothing over the network');
  assert.equal(await page.evaluate(() => !!navigator.serviceWorker.controller), true, 'the worker controls the page');

  await context.setOffline(true);
  try {
    await page.reload();
    await waitReady(page);
    await waitSteps(page, 30);
    const state = await duet(page);
    assert.equal(state.error, null);
    assert.equal(await page.locator('#loading').isVisible(), false, 'loading bar gone');
  } finally {
    await context.setOffline(false);
  }
  assert.deepEqual(browser.consoleErrors, []);
});
