// Smoke test of the production build: `vite build`, then `vite preview` serving dist/ from a
// sub-path (/duet/), as a static host would. Checks that the wasm, the ORT worker threads and the
// models all load from relative URLs, and that the page steers.

import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { QUICK, build, displacement, duet, launch, pixelVariance, startServer, waitReady, waitSteps } from './harness.mjs';

let server;
let browser;

before(async () => {
  await build('dist');
  server = await startServer({ mode: 'preview', base: '/duet/', outDir: 'dist' });
  browser = await launch(QUICK);
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

test('built site from a sub-path: ready on two threads, steers, no console errors', async (t) => {
  // How fast the built site loads is `npm run bench` (cold load to the first dancing frame).
  const { page } = browser;
  const started = Date.now();
  await page.goto(`${server.url}?seed=1`);
  await waitReady(page);
  t.diagnostic(`ready after ${Date.now() - started} ms (a figure, not a check: npm run bench)`);
  await waitSteps(page, 30);

  const state = await duet(page);
  assert.equal(state.error, null);
  assert.equal(await page.evaluate(() => crossOriginIsolated), true, 'COOP/COEP headers make the page cross-origin isolated');
  assert.equal(state.threads, 2);

  const idle = await displacement(page, 60);
  const up = await displacement(
    page,
    60,
    () => page.keyboard.down('ArrowUp'),
    () => page.keyboard.up('ArrowUp'),
  );
  assert.ok(up.moved >= idle.moved + 0.5, `ArrowUp moved ${up.moved.toFixed(2)} m, idle ${idle.moved.toFixed(2)} m`);

  const variance = await pixelVariance(page, await page.screenshot());
  assert.ok(variance > 20, `screenshot variance ${variance.toFixed(1)}`);
  assert.deepEqual(browser.consoleErrors, []);
});
