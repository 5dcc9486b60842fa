// A new version of the site deployed over the old one, at one address, with one browser profile
// (tests/e2e/deploy.mjs): every visit after a deploy dances the version that is up, whole; a tab
// left open across the deploy keeps dancing and says to reload; a start that stalls restarts by
// itself. scripts/deploy_trials.mjs runs the same visits by the hundred (docs/reliability.md).
//
// Before the fix (sw.js took over at once on install), a visit after a deploy hung in 1 of 12
// visits on this machine beside another test run, and the next navigation never committed.

import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { QUICK, WAIT_MS, launch, waitReady, waitSteps, waitToast } from './harness.mjs';
import { twoBuilds, visit, waitCached } from './deploy.mjs';

let dir;
let site;
let browser;

before(async () => {
  dir = mkdtempSync(join(tmpdir(), 'duet-deploy-'));
  site = await twoBuilds(dir);
  browser = await launch(QUICK);
});

after(async () => {
  await browser?.close();
  await site?.stop();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

test('every visit after a deploy dances the version that is up, on one thread or two', async () => {
  const { page } = browser;
  const first = await visit(page, `${site.url}?seed=1`, WAIT_MS);
  assert.equal(first.outcome, 'danced', JSON.stringify(first));
  assert.ok(await waitCached(page, first.version), 'the first visit is cached');
  const seen = new Set([first.version]);
  let up = 'a';
  for (let i = 1; i <= 4; i++) {
    up = up === 'a' ? 'b' : 'a';
    site.deploy(up);
    const result = await visit(page, `${site.url}?seed=${i}${i % 2 ? '&threads=1' : ''}`, WAIT_MS);
    assert.equal(result.outcome, 'danced', `visit ${i} after deploying ${up}: ${JSON.stringify(result)}`);
    assert.equal(result.build, result.models, `visit ${i}: the page's build and its manifest are one version`);
    assert.equal(result.recovered, 0, `visit ${i}: danced without the watchdog`);
    seen.add(result.version);
    // The new version's worker takes over once the page dances, and keeps what it downloaded.
    assert.ok(await waitCached(page, result.version), `visit ${i}: version ${result.version} cached`);
    const controller = await page.evaluate(() => navigator.serviceWorker.controller?.scriptURL ?? null);
    assert.ok(controller?.endsWith(`v=${result.version}`), `visit ${i}: the worker of ${result.version} controls the page (${controller})`);
    // The old version's cache goes when the new worker has activated (a moment after it took over).
    const only = await page.waitForFunction((name) => caches.keys().then((names) => names.length === 1 && names[0] === name), `duet-${result.version}`, { timeout: WAIT_MS }).then(() => true, () => false);
    assert.ok(only, `visit ${i}: the old version's cache is gone (${await page.evaluate(() => caches.keys())})`);
  }
  assert.equal(seen.size, 2, 'two versions were deployed');
});

test('a tab left open across a deploy dances on and says to reload; another partner is refused', async () => {
  const { context } = browser;
  const old = browser.page;
  const oldVersion = await old.evaluate(() => window.duet.version);
  // The other build goes up, and a second tab visits it: its worker takes over both tabs.
  site.deploy(site.up() === 'a' ? 'b' : 'a');
  const fresh = await context.newPage();
  const result = await visit(fresh, `${site.url}?seed=7`, WAIT_MS);
  assert.equal(result.outcome, 'danced', JSON.stringify(result));
  assert.notEqual(result.version, oldVersion, 'the second tab runs the new version');
  await old.bringToFront(); // the visitor goes back to the tab left open
  await waitToast(old, 'duet was updated', null);
  await waitSteps(old, 10); // the old tab dances on
  // The baseline's model was never loaded in the old tab: the server now has other models.
  assert.equal(await old.evaluate(() => window.duet.model), 'ours');
  const menu = old.locator('.lil-gui select').first();
  await menu.selectOption({ label: await menu.locator('option').nth(1).textContent() });
  await waitToast(old, 'cannot be loaded for this one', null);
  const state = await old.evaluate(() => ({ error: window.duet.error, model: window.duet.model, frame: window.duet.frame }));
  assert.equal(state.error, null, 'no fatal error in the old tab');
  assert.equal(state.model, 'ours', 'the partner dancing dances on');
  await waitSteps(old, 1); // and the dance goes on
  await fresh.close();
});

test('a start that stands still restarts by itself and dances', async () => {
  const { page } = browser;
  // The wasm and the models never come on this visit (a link that stopped answering): no progress.
  // Once the page says it starts again, requests go through: the held ones stay held (so the
  // stalled page cannot finish in the moment before its reload), the reloaded page's are answered.
  let held = 0;
  let holding = true;
  const hold = (route) => {
    if (!holding) return route.continue();
    held++;
    return new Promise(() => {}); // never answered
  };
  // On the context: the fetcher worker's downloads are not the page's own requests.
  await browser.context.route('**/*.onnx', hold);
  await browser.context.route('**/*.wasm', hold);
  await page.evaluate(() => caches.keys().then((names) => Promise.all(names.map((n) => caches.delete(n)))));
  await page.evaluate(() => navigator.serviceWorker.getRegistration().then((r) => r?.unregister()));
  await page.goto(`${site.url}?seed=3`);
  // The watchdog waits 20 s without progress, then reloads; the second start is let through.
  await page.waitForEvent('console', { predicate: (m) => m.text().includes('starting again'), timeout: WAIT_MS });
  holding = false;
  // The restarted page (it counts its restart) dances, or says why not.
  await page.waitForFunction(() => window.duet?.recovered > 0 && (window.duet.ready || window.duet.error), null, { timeout: WAIT_MS, polling: 100 });
  const state = await page.evaluate(() => ({ error: window.duet.error, recovered: window.duet.recovered }));
  assert.ok(held >= 1, 'the first start was held');
  assert.equal(state.error, null);
  assert.equal(state.recovered, 1, 'one restart');
  await waitReady(page);
  assert.equal(await page.evaluate(() => sessionStorage.getItem('duet:restarts')), null, 'the count is cleared once it dances');
  await browser.context.unroute('**/*.onnx', hold);
  await browser.context.unroute('**/*.wasm', hold);
});
