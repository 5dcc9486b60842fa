// End-to-end reliability: inputs the page cannot use end in a clear message (never a blank
// canvas), the page runs without cross-origin isolation and after a hidden tab, the
// Content-Security-Policy in index.html holds (no violation while loading and stepping), and a
// crafted URL changes nothing but falls back to defaults.
// Run: node --test tests/e2e/reliability.test.mjs   (needs /usr/bin/chromium and public/models/)
//
// Missing manifest and a same-length corrupt model are covered in app.test.mjs and not repeated.

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { createReadStream, statSync } from 'node:fs';
import { createServer } from 'node:http';
import { extname, join, normalize, sep } from 'node:path';
import {
  CHROMIUM_ARGS,
  QUICK,
  WAIT_MS,
  builtSite,
  distance,
  duet,
  launch,
  pixelVariance,
  sleep,
  startServer,
  waitReady,
  waitSteps,
} from './harness.mjs';

/**
 * How long the tab stays hidden. A real minute (DUET_HIDDEN_SECONDS=60) behaves exactly like the
 * 20 s default: the page counts any stall as at most 0.5 s (MAX_FRAME_SECONDS in web/ui/main.ts), so
 * the length of the gap does not change the outcome; 20 s keeps the default suite shorter.
 */
const HIDDEN_SECONDS = Number(process.env.DUET_HIDDEN_SECONDS ?? 20);
/** Luminance variance of a screenshot above which it is not blank (a flat page is ~0). */
const MIN_VARIANCE = 5;

/** Installed before any page script: collect CSP violations, dialogs cannot be seen from here. */
function watchViolations() {
  window.__violations = [];
  document.addEventListener(
    'securitypolicyviolation',
    (event) => window.__violations.push(`${event.effectiveDirective} blocked ${event.blockedURI} (${event.sourceFile}:${event.lineNumber})`),
    true,
  );
}

/**
 * Installed before any page script: record every element of a markup-injection kind (or with an
 * on* handler attribute) that scripts add. Starts once the parser is done with index.html, which
 * is before the page's module scripts run.
 */
function watchInjectedElements() {
  window.__injected = [];
  const observer = new MutationObserver((records) => {
    for (const record of records) {
      if (record.type === 'attributes' && /^on/i.test(record.attributeName)) window.__injected.push(`${record.attributeName} on ${record.target.tagName}`);
      for (const node of record.addedNodes) {
        if (node.nodeType !== 1) continue;
        const elements = [node, ...node.querySelectorAll('*')];
        for (const element of elements) {
          if (/^(IMG|SCRIPT|IFRAME|OBJECT|EMBED|FRAME)$/i.test(element.tagName) || [...element.attributes].some((a) => /^on/i.test(a.name))) {
            window.__injected.push(element.outerHTML.slice(0, 200));
          }
        }
      }
    }
  });
  document.addEventListener('readystatechange', () => {
    if (document.readyState === 'interactive') observer.observe(document, { childList: true, subtree: true, attributes: true });
  });
}

/**
 * Installed before any page script: a switchable "hidden tab". Headless Chromium keeps every tab
 * visible (window minimizing, a second tab in front and Page.setWebLifecycleState 'frozen' all
 * leave rAF running there), so this does what a browser does for a hidden tab: visibilityState
 * reads 'hidden', a visibilitychange event fires, and animation frames stop until the tab is
 * shown again (then visibilitychange fires first and the held frame callbacks run).
 */
function installTabSwitch() {
  let hidden = false;
  const held = [];
  const realRequest = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = (callback) => {
    if (!hidden) return realRequest(callback);
    held.push(callback);
    return 0;
  };
  Object.defineProperty(Document.prototype, 'visibilityState', { configurable: true, get: () => (hidden ? 'hidden' : 'visible') });
  Object.defineProperty(Document.prototype, 'hidden', { configurable: true, get: () => hidden });
  window.__tab = {
    hide() {
      hidden = true;
      document.dispatchEvent(new Event('visibilitychange'));
    },
    show() {
      hidden = false;
      document.dispatchEvent(new Event('visibilitychange'));
      for (const callback of held.splice(0)) realRequest(callback);
    },
  };
}

/** A new tab in `browser`'s context that records console errors and dialogs. */
async function openPage(browser) {
  const page = await browser.context.newPage();
  const consoleErrors = [];
  const dialogs = [];
  page.on('console', (message) => message.type() === 'error' && consoleErrors.push(message.text()));
  page.on('pageerror', (error) => consoleErrors.push(String(error)));
  page.on('dialog', (dialog) => {
    dialogs.push(`${dialog.type()}: ${dialog.message()}`);
    dialog.dismiss().catch(() => undefined);
  });
  await page.addInitScript(watchViolations);
  return { page, consoleErrors, dialogs };
}

/**
 * Wait for the error overlay and check it says what went wrong: a visible alert whose heading
 * matches `title` and whose text matches `detail`, the same message on window.duet.error, the page
 * not ready, and a screenshot that is not blank.
 */
async function expectMessage(t, page, title, detail, timeoutMs = WAIT_MS) {
  const started = Date.now();
  await page.waitForFunction(() => window.duet?.error, null, { timeout: timeoutMs, polling: 50 });
  const state = await duet(page);
  assert.equal(state.ready, false, 'no simulation runs after the error');
  const overlay = page.locator('.error-overlay[role="alert"]');
  assert.ok(await overlay.isVisible(), 'error overlay is visible');
  const heading = await overlay.locator('h2').textContent();
  const text = await overlay.textContent();
  assert.match(heading, title);
  assert.match(text, detail);
  assert.match(text, /Reload the page/);
  assert.ok(state.error.startsWith(heading), `window.duet.error "${state.error}" starts with the heading`);
  const variance = await pixelVariance(page, await page.screenshot());
  assert.ok(variance > MIN_VARIANCE, `screenshot variance ${variance.toFixed(1)} (blank page?)`);
  t.diagnostic(`message after ${Date.now() - started} ms: "${state.error}" (screenshot variance ${variance.toFixed(1)})`);
  return { state, heading, text, variance };
}

/** Route the manifest through `edit(manifest)`. */
function editManifest(page, edit) {
  return page.route('**/models/manifest.json', async (route) => {
    const response = await route.fetch();
    const manifest = await response.json();
    edit(manifest);
    const headers = { ...response.headers() };
    delete headers['content-length'];
    await route.fulfill({ response, headers, body: JSON.stringify(manifest) });
  });
}

/** Answer follower.onnx with its first half only. */
function truncateFollower(page) {
  return page.route('**/models/follower.onnx', async (route) => {
    const response = await route.fetch();
    const body = await response.body();
    await route.fulfill({ status: 200, contentType: 'application/octet-stream', body: body.subarray(0, Math.floor(body.length / 2)) });
  });
}

let server;
let browser;

before(async () => {
  server = await startServer({ mode: 'dev' });
  browser = await launch(QUICK);
  // Warm the dev server's module transforms (as app.test.mjs does) so timeouts measure the page.
  await browser.page.goto(`${server.url}?seed=1`);
  await waitReady(browser.page).catch(() => undefined);
  // Headless tabs all stay "visible": a page left running would keep stepping beside every test.
  await browser.page.goto('about:blank');
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

describe('bad inputs show a clear message, not a blank canvas', () => {
  test('truncated model file (half of follower.onnx)', async (t) => {
    const { page } = await openPage(browser);
    await truncateFollower(page);
    await page.goto(`${server.url}?seed=1`);
    const { state } = await expectMessage(t, page, /model file is corrupt/i, /follower\.onnx has \d+ bytes, manifest\.json says \d+/);
    assert.match(state.error, /follower\.onnx/);
    await page.close();
  });

  test('truncated model file whose size the manifest agrees with: the runtime refuses it', async (t) => {
    const { page } = await openPage(browser);
    await truncateFollower(page);
    await editManifest(page, (manifest) => {
      manifest.models.follower.bytes = Math.floor(manifest.models.follower.bytes / 2);
    });
    await page.goto(`${server.url}?seed=1`);
    await expectMessage(t, page, /model file is corrupt|does not match/i, /follower\.onnx/);
    await page.close();
  });

  test('manifest of another version', async (t) => {
    const { page } = await openPage(browser);
    await editManifest(page, (manifest) => {
      manifest.version = 2;
    });
    await page.goto(`${server.url}?seed=1`);
    await expectMessage(t, page, /manifest does not match this page/i, /manifest version 2, this page reads version 1/);
    await page.close();
  });

  test('manifest of another feature layout', async (t) => {
    const { page } = await openPage(browser);
    let expected = null; // the page's own input size: the shipped manifest's (it grows with the features)
    await editManifest(page, (manifest) => {
      expected = manifest.layout.input;
      manifest.layout.input = 600;
    });
    await page.goto(`${server.url}?seed=1`);
    const { text } = await expectMessage(t, page, /manifest does not match this page/i, /layout\.input is 600, this page expects \d+/);
    assert.match(text, new RegExp(`this page expects ${expected}\\D`));
    await page.close();
  });

  test('manifest whose block layout differs (same sizes, two blocks swapped)', async (t) => {
    const { page } = await openPage(browser);
    await editManifest(page, (manifest) => {
      const blocks = manifest.layout.followerInput;
      [blocks[0], blocks[1]] = [blocks[1], blocks[0]];
    });
    await page.goto(`${server.url}?seed=1`);
    await expectMessage(t, page, /manifest does not match this page/i,
      /layout\.followerInput block 1 is "partner_trajectory_future" \(24\), this page expects "partner_trajectory_past" \(24\)/);
    await page.close();
  });

  test('model file missing (404)', async (t) => {
    const { page } = await openPage(browser);
    await page.route('**/models/follower.onnx', (route) => route.fulfill({ status: 404, body: 'not found' }));
    await page.goto(`${server.url}?seed=1`);
    await expectMessage(t, page, /model file is missing/i, /models\/follower\.onnx: answered 404/);
    await page.close();
  });

  test("onnxruntime's loader served as text/plain: the message names the host's MIME type, not a model", async (t) => {
    const { page } = await openPage(browser);
    // The loader itself, not the dev server's `?url` module that only names it.
    const loader = (url) => /ort-wasm-simd-threaded[^/]*\.mjs$/.test(url.pathname) && !url.searchParams.has('url');
    await page.route(loader, async (route) => {
      const response = await route.fetch();
      await route.fulfill({ response, headers: { ...response.headers(), 'content-type': 'text/plain' } });
    });
    await page.goto(`${server.url}?seed=1`);
    const { text } = await expectMessage(t, page, /wrong type/i, /ort-wasm-simd-threaded.*\.mjs comes as "text\/plain".*text\/javascript/);
    assert.doesNotMatch(text, /corrupt/i);
    await page.close();
  });

  test('WebGL unavailable (getContext returns null)', async (t) => {
    const { page } = await openPage(browser);
    await page.addInitScript(() => {
      const getContext = HTMLCanvasElement.prototype.getContext;
      HTMLCanvasElement.prototype.getContext = function (kind, ...rest) {
        return /webgl/i.test(kind) ? null : getContext.call(this, kind, ...rest);
      };
    });
    await page.goto(`${server.url}?seed=1`);
    await expectMessage(t, page, /WebGL is not available/, /hardware acceleration/);
    await page.close();
  });

  test('WebGL disabled in the browser (--disable-webgl --disable-3d-apis)', async (t) => {
    const noGl = await launch({ args: [...CHROMIUM_ARGS, '--disable-webgl', '--disable-3d-apis'], ...QUICK });
    try {
      const { page } = await openPage(noGl);
      await page.goto(`${server.url}?seed=1`);
      await expectMessage(t, page, /WebGL is not available/, /hardware acceleration/);
    } finally {
      await noGl.close();
    }
  });
});

/** Serve `root` under `prefix` as a plain static host does: no COOP/COEP, no CSP header. */
async function plainStaticServer(root, prefix = '/duet/') {
  const types = {
    '.html': 'text/html; charset=utf-8',
    '.js': 'text/javascript',
    '.mjs': 'text/javascript',
    '.css': 'text/css',
    '.json': 'application/json',
    '.wasm': 'application/wasm',
    '.onnx': 'application/octet-stream',
  };
  const http = createServer((request, response) => {
    const path = decodeURIComponent(new URL(request.url, 'http://x').pathname);
    if (!path.startsWith(prefix)) return response.writeHead(404).end();
    let file = normalize(join(root, path.slice(prefix.length)));
    if (!file.startsWith(root + sep) && file !== root) return response.writeHead(403).end();
    try {
      if (statSync(file).isDirectory()) file = join(file, 'index.html');
      const size = statSync(file).size;
      response.writeHead(200, { 'Content-Type': types[extname(file)] ?? 'application/octet-stream', 'Content-Length': size });
      createReadStream(file).pipe(response);
    } catch {
      response.writeHead(404).end();
    }
  });
  await new Promise((done) => http.listen(0, '127.0.0.1', done));
  const url = `http://127.0.0.1:${http.address().port}${prefix}`;
  return { url, stop: () => new Promise((done) => http.close(done)) };
}

/** Ready, on one thread, not isolated, and stepping: the shared checks of the two hosts below. */
async function expectOneThread(t, page, url) {
  const started = Date.now();
  await page.goto(url);
  await waitReady(page);
  const readyMs = Date.now() - started;
  await waitSteps(page, 60);
  const state = await duet(page);
  assert.equal(state.error, null);
  assert.equal(await page.evaluate(() => crossOriginIsolated), false, 'page is not cross-origin isolated');
  assert.equal(state.threads, 1);
  // Steering still works on one thread.
  const before = await duet(page);
  await page.keyboard.down('ArrowUp');
  await waitSteps(page, 45);
  await page.keyboard.up('ArrowUp');
  // His spot (window.duet.anchor), which the keys carry; his own hips dance around it (harness.displacement).
  const moved = distance(before.anchor, (await duet(page)).anchor);
  assert.ok(moved > 0.3, `ArrowUp moved the leader's spot ${moved.toFixed(2)} m in 45 steps`);
  assert.deepEqual(await page.evaluate(() => window.__violations), []);
  t.diagnostic(`ready in ${readyMs} ms, threads ${state.threads}, step median ${state.stepMs.median.toFixed(2)} ms, ArrowUp moved ${moved.toFixed(2)} m in 45 steps`);
}

describe('without cross-origin isolation the page runs on one thread', () => {
  test('dev server with COOP/COEP stripped from the page', async (t) => {
    const { page, consoleErrors } = await openPage(browser);
    await page.route(
      (url) => url.pathname === '/',
      async (route) => {
        const response = await route.fetch();
        const headers = { ...response.headers() };
        delete headers['cross-origin-opener-policy'];
        delete headers['cross-origin-embedder-policy'];
        await route.fulfill({ response, headers });
      },
    );
    await expectOneThread(t, page, `${server.url}?seed=4`);
    // A document answered through page.route has no network address, so Chromium's local-network
    // checks block Vite's own hot-reload websocket to 127.0.0.1. That is the dev tooling under
    // this interception, not the page (the plain static host below must have no errors at all).
    const viteSocket = /WebSocket connection to 'ws:\/\/127\.0\.0\.1|\[vite\] failed to connect to websocket/;
    assert.deepEqual(consoleErrors.filter((text) => !viteSocket.test(text)), []);
    await page.close();
  });

  test('built site on a plain static server (no headers at all), from a sub-path', async (t) => {
    const site = await builtSite();
    let plain;
    try {
      plain = await plainStaticServer(site.dir);
      const { page, consoleErrors } = await openPage(browser);
      await expectOneThread(t, page, `${plain.url}?seed=4`);
      assert.deepEqual(consoleErrors, []);
      await page.close();
    } finally {
      await plain?.stop();
      site.remove();
    }
  });
});

describe('hidden tab', () => {
  test(`hidden for ${HIDDEN_SECONDS} s: no catch-up, no jump, frames resume`, { timeout: HIDDEN_SECONDS * 1000 + 5 * WAIT_MS }, async (t) => {
    const { page, consoleErrors } = await openPage(browser);
    await page.addInitScript(installTabSwitch);
    await page.goto(`${server.url}?seed=5`);
    await waitReady(page);
    await waitSteps(page, 30);

    // Read in the same task that hides the tab: on a busy machine a second read could come a
    // second of dance later.
    const before = await page.evaluate(() => {
      window.__tab.hide();
      return JSON.parse(JSON.stringify(window.duet));
    });
    assert.equal(await page.evaluate(() => document.visibilityState), 'hidden');
    await sleep(HIDDEN_SECONDS * 1000);
    const hidden = await duet(page);
    // Once hidden, the page works off the backlog it has and that of the animation frame already
    // scheduled, each capped at 0.5 s of dance (15 steps), and then stands still. A page stepping
    // on a timer would have taken HIDDEN_SECONDS × 30.
    assert.ok(hidden.frame - before.frame <= 31, `${hidden.frame - before.frame} steps while hidden`);

    const shownAt = Date.now();
    await page.evaluate(() => window.__tab.show());
    await waitSteps(page, 1);
    const shown = await duet(page);
    const wallSeconds = (Date.now() - shownAt) / 1000;
    // Real time since showing, plus the page's 0.5 s allowance for a stall, at 30 steps/s (+ slack):
    // a page that made up for the hidden span would take HIDDEN_SECONDS × 30 steps here.
    const allowed = Math.ceil((wallSeconds + 0.5) * 30) + 5;
    assert.ok(shown.frame - hidden.frame <= allowed, `${shown.frame - hidden.frame} steps right after showing (allowed ${allowed})`);
    // The gap itself: from the last state while hidden (the simulation stood still) to the first
    // state after showing. (Not from `before`: the up to 15 steps of the frame already under way
    // would count too, and a dancing follower covers up to ~1.4 m in 20 steps, measured here.)
    const leaderJump = distance(hidden.leader.root, shown.leader.root);
    const followerJump = distance(hidden.follower.root, shown.follower.root);
    t.diagnostic(
      `steps: ${hidden.frame - before.frame} while hidden ${HIDDEN_SECONDS} s, ${shown.frame - hidden.frame} in the first ${wallSeconds.toFixed(2)} s shown; ` +
        `leader moved ${leaderJump.toFixed(2)} m, follower ${followerJump.toFixed(2)} m across the gap ` +
        `(${distance(before.leader.root, shown.leader.root).toFixed(2)} m and ${distance(before.follower.root, shown.follower.root).toFixed(2)} m since just before hiding)`,
    );
    assert.ok(leaderJump < 1, `leader moved ${leaderJump.toFixed(2)} m across the hidden span`);
    assert.ok(followerJump < 1, `follower moved ${followerJump.toFixed(2)} m across the hidden span`);

    // And it dances on.
    await waitSteps(page, 60);
    const later = await duet(page);
    assert.equal(later.error, null);
    assert.ok(distance(later.leader.root, later.follower.root) < 3, 'partners stay together');
    assert.deepEqual(consoleErrors, []);
    await page.close();
  });
});

describe('Content-Security-Policy and crafted URLs', () => {
  test('no CSP violation while loading, stepping, with ghosts, and switching to compare', async () => {
    const { page, consoleErrors } = await openPage(browser);
    await page.goto(`${server.url}?seed=2&ghosts=3&intentions=1`);
    await waitReady(page);
    const csp = await page.evaluate(() => document.querySelector('meta[http-equiv="Content-Security-Policy"]')?.content ?? '');
    assert.match(csp, /script-src 'self' 'wasm-unsafe-eval'/);
    assert.doesNotMatch(csp, /'unsafe-eval'/);
    await page.keyboard.down('ArrowLeft');
    await waitSteps(page, 45);
    await page.keyboard.up('ArrowLeft');
    // A model loaded later (the CCM follower) goes through the same policy.
    await page.locator('.lil-gui select').first().selectOption({ label: 'both, side by side' });
    await page.waitForFunction(() => window.duet.model === 'compare', null, { timeout: WAIT_MS });
    await waitSteps(page, 60);
    assert.equal((await duet(page)).error, null);
    assert.deepEqual(await page.evaluate(() => window.__violations), []);
    assert.deepEqual(consoleErrors, []);
    await page.close();
  });

  test('a CSP violation is caught by this test (the check is live)', async () => {
    // Guards the test above against passing vacuously: an inline script must be refused and seen.
    const { page } = await openPage(browser);
    await page.goto(`${server.url}?seed=2`);
    await waitReady(page);
    await page.evaluate(() => {
      const script = document.createElement('script');
      script.textContent = 'window.__ran = true';
      document.body.appendChild(script);
    });
    await page.waitForFunction(() => window.__violations.length > 0, null, { timeout: WAIT_MS });
    assert.equal(await page.evaluate(() => window.__ran ?? false), false, 'inline script did not run');
    assert.match((await page.evaluate(() => window.__violations))[0], /script-src/);
    await page.close();
  });

  test('a crafted URL leaves the page on defaults and injects nothing', async () => {
    const { page, consoleErrors, dialogs } = await openPage(browser);
    await page.addInitScript(watchInjectedElements);
    const query =
      '?temperature=<script>alert(1)</script>&model=%3Cimg%20src=x%20onerror=alert(1)%3E&seed=1e999&camera=NaN,NaN,NaN';
    await page.goto(`${server.url}${query}`);
    await waitReady(page);
    await waitSteps(page, 60);
    const state = await duet(page);
    assert.equal(state.error, null);
    assert.equal(state.model, 'ours', 'unknown model falls back to ours');
    for (const key of ['leader', 'follower']) {
      assert.ok(state[key].root.every(Number.isFinite), `${key} root is finite (camera NaN did not leak in)`);
    }
    // The panel shows the defaults: the manifest's temperature and the 'ours' follower.
    const defaultTemperature = (await (await fetch(`${server.url}models/manifest.json`)).json()).defaultTemperature;
    const panel = await page.evaluate(() => {
      // "variety" is the temperature (URL key temperature).
      const controller = [...document.querySelectorAll('.lil-gui .lil-controller')].find((c) => c.querySelector('.lil-name')?.textContent === 'variety');
      const select = document.querySelector('.lil-gui select');
      return {
        temperature: controller?.querySelector('input')?.value, model: select?.selectedOptions[0]?.textContent,
        note: document.querySelector('.about-details')?.textContent,
      };
    });
    assert.equal(Number(panel.temperature), defaultTemperature);
    assert.equal(panel.model, 'reads your intention');
    // The help's details fold says what the intention adds on this data (docs/results.md).
    assert.match(panel.note ?? '', /cross-validation.*CCM/);
    // Nothing from the URL became markup: no element added, no dialog, no text of it in the DOM.
    assert.deepEqual(await page.evaluate(() => window.__injected), []);
    const html = await page.evaluate(() => document.documentElement.outerHTML);
    assert.doesNotMatch(html, /alert\(1\)|onerror|<img/i);
    await sleep(500);
    assert.deepEqual(dialogs, []);
    assert.deepEqual(await page.evaluate(() => window.__violations), []);
    assert.deepEqual(consoleErrors, []);
    // The observer is live: an element added now is seen.
    await page.evaluate(() => document.body.append(Object.assign(document.createElement('img'), { alt: 'probe' })));
    await page.waitForFunction(() => window.__injected.length === 1, null, { timeout: WAIT_MS });
    await page.close();
  });
});
