// End-to-end tests of the page on the Vite dev server, in headless Chromium.
// Run: npm run test:e2e   (node --test; needs /usr/bin/chromium and models in public/models/)
//
// Every assertion reads window.duet (the DuetHook in web/engine/types.ts), never the page's internals.

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import {
  QUICK,
  WAIT_MS,
  displacement,
  distance,
  duet,
  launch,
  pixelVariance,
  reset,
  saveScreen,
  sleep,
  startServer,
  touchDrag,
  waitReady,
  waitSteps,
} from './harness.mjs';

const HOLD_STEPS = 90; // 3 s of dance
const MIN_VARIANCE = 20; // luminance variance of a screenshot; a blank canvas is ~0

let server;

before(async () => {
  server = await startServer({ mode: 'dev' });
  // The dev server transforms modules on first request; warm it so the tests below see the page,
  // not Vite's first compile (which can reload a page mid-test). The shared one (DUET_DEV_URL)
  // is warm already.
  if (server.shared) return;
  const warm = await launch(QUICK);
  await warm.page.goto(`${server.url}?seed=1`);
  await waitReady(warm.page).catch(() => undefined);
  await warm.close();
});

after(async () => {
  await server?.stop();
});

describe('desktop', () => {
  // The tests that take no picture dance in a browser that draws at half resolution (QUICK); the
  // two that save a picture (screenshot-desktop.png, screenshot-hands.png) in one at full
  // resolution, each loading its own page.
  let quick;
  let page;
  let browser;
  /** The full-resolution browser's page (launched by the first test that takes a picture). */
  const fullPage = async () => {
    browser ??= await launch({ viewport: { width: 1280, height: 800 } });
    return browser.page;
  };

  before(async () => {
    quick = await launch({ viewport: { width: 1280, height: 800 }, ...QUICK });
    page = quick.page;
  });

  after(async () => {
    await quick?.close();
    await browser?.close();
  });

  test('becomes ready and dances without errors', async (t) => {
    // How fast it gets there is `npm run bench` (cold load to the first dancing frame), not a test.
    const started = Date.now();
    await page.goto(`${server.url}?seed=1`);
    await waitReady(page);
    t.diagnostic(`ready after ${Date.now() - started} ms (a figure, not a check: npm run bench)`);
    await waitSteps(page, 30);
    const state = await duet(page);
    assert.equal(state.error, null);
    assert.equal(state.model, 'ours');
    assert.ok(state.stepMs.median > 0, 'step time is measured');
    // Its networks' part: every step runs both networks, and a step holds its runs (so, step by
    // step, its median cannot pass the step's).
    assert.ok(state.networkMs.median > 0 && state.networkMs.median <= state.stepMs.median, `networks ${state.networkMs.median} ms of a ${state.stepMs.median} ms step`);
    for (const key of ['leader', 'follower']) {
      assert.equal(state[key].root.length, 2);
      assert.ok(state[key].root.every(Number.isFinite) && Number.isFinite(state[key].heading), `${key} is finite`);
    }
  });

  test('holding ArrowUp for 3 s of dance moves the leader at least 1 m further than idling', async () => {
    const idle = await displacement(page, HOLD_STEPS);
    const up = await displacement(
      page,
      HOLD_STEPS,
      () => page.keyboard.down('ArrowUp'),
      () => page.keyboard.up('ArrowUp'),
    );
    assert.ok(up.moved >= idle.moved + 1, `ArrowUp moved ${up.moved.toFixed(2)} m, idle ${idle.moved.toFixed(2)} m`);
  });

  test('ArrowLeft and ArrowRight end on opposite sides', async () => {
    const left = await displacement(
      page,
      HOLD_STEPS,
      () => page.keyboard.down('ArrowLeft'),
      () => page.keyboard.up('ArrowLeft'),
    );
    const right = await displacement(
      page,
      HOLD_STEPS,
      () => page.keyboard.down('ArrowRight'),
      () => page.keyboard.up('ArrowRight'),
    );
    // Both runs start from the reset pose: their moves must point away from each other.
    const l = [left.end[0] - left.start[0], left.end[1] - left.start[1]];
    const r = [right.end[0] - right.start[0], right.end[1] - right.start[1]];
    const dot = l[0] * r[0] + l[1] * r[1];
    assert.ok(dot < 0, `left move (${l.map((v) => v.toFixed(2))}) and right move (${r.map((v) => v.toFixed(2))}) point the same way`);
    assert.ok(distance(left.end, right.end) > 1, `left and right end ${distance(left.end, right.end).toFixed(2)} m apart`);
  });

  test('the follower stays within 3 m of the leader through 60 s of random steering', async () => {
    // 4× speed: 60 simulated seconds (1800 steps, every one running the real models) in ~15 s
    // on a quiet machine; on a busy one it takes longer, and the test waits for the steps. In the
    // half-resolution browser (QUICK): it takes no picture.
    await steerAtRandom(page);
    // The tests after this one dance in the full-resolution browser: this page would dance on
    // beside them, at 4x, for nothing.
    await page.goto('about:blank');
  });

  async function steerAtRandom(page) {
    await page.goto(`${server.url}?seed=7&speed=4`);
    await waitReady(page);
    await reset(page);
    const start = (await duet(page)).frame;
    const keys = ['ArrowUp', 'ArrowDown', 'ArrowLeft', 'ArrowRight', 'KeyW', 'KeyA', 'KeyS', 'KeyD'];
    let random = 12345;
    const next = () => (random = (random * 1103515245 + 12345) % 2147483648) / 2147483648;
    let held = [];
    let worst = 0;
    let changeAt = 0;
    // A page that stops stepping fails here; a slow one is waited for.
    let progress = { frame: start, at: Date.now() };
    for (;;) {
      const state = await duet(page);
      assert.equal(state.error, null);
      worst = Math.max(worst, distance(state.leader.root, state.follower.root));
      if (state.frame - start >= 1800) break;
      if (state.frame > progress.frame) progress = { frame: state.frame, at: Date.now() };
      assert.ok(Date.now() - progress.at < WAIT_MS, `no step for ${WAIT_MS / 1000} s (${state.frame - start} of 1800 taken)`);
      if (state.frame >= changeAt) {
        // New random keys every 0.5-2 simulated seconds; sometimes none (idle).
        for (const key of held) await page.keyboard.up(key);
        held = [];
        const count = Math.floor(next() * 3);
        for (let i = 0; i < count; i++) held.push(keys[Math.floor(next() * keys.length)]);
        held = [...new Set(held)];
        for (const key of held) await page.keyboard.down(key);
        changeAt = state.frame + 15 + Math.floor(next() * 45);
      }
      await sleep(50);
    }
    for (const key of held) await page.keyboard.up(key);
    assert.ok(worst < 3, `follower was ${worst.toFixed(2)} m from the leader`);
  }

  test('screenshot is not blank', async () => {
    const page = await fullPage();
    await page.goto(`${server.url}?seed=3&intentions=1`);
    await waitReady(page);
    await page.keyboard.down('ArrowUp');
    await waitSteps(page, 45);
    await page.keyboard.up('ArrowUp');
    await waitSteps(page, 10);
    const png = await page.screenshot();
    saveScreen('screenshot-desktop.png', png);
    const variance = await pixelVariance(page, png);
    assert.ok(variance > MIN_VARIANCE, `screenshot variance ${variance.toFixed(1)}`);
  });

  test('hands meet: the contact layer draws the closest hands together (screenshot-hands.png)', async () => {
    const page = await fullPage();
    await page.goto(`${server.url}?seed=1`);
    await waitReady(page);
    await waitSteps(page, 90); // past the start pose: the dancers have moved on their own
    // The layer completes holds the networks nearly make (from 20 cm, fully at 10 cm): wait for
    // hands that came within about 15 cm of each other (hold weight 0.5), for up to 90 s of dance.
    // Lead as a person would (a few steps one way, then another): an idle leader seldom brings
    // its hands that close.
    let hold = 0, most = 0, turn = 0;
    const keys = ['ArrowUp', 'ArrowLeft', 'ArrowDown', 'ArrowRight'];
    const first = (await duet(page)).frame;
    const danced = async () => (await duet(page)).frame - first;
    while ((await danced()) < 90 * 30 && hold < 0.5) {
      const key = keys[turn++ % keys.length];
      await page.keyboard.down(key);
      const from = await danced();
      while ((await danced()) - from < 36 && hold < 0.5) {
        await sleep(30);
        hold = await page.evaluate(() => window.duet.hold);
        most = Math.max(most, hold);
      }
      await page.keyboard.up(key);
    }
    assert.ok(hold >= 0.5, `the hands never met in 90 s of dance (largest hold ${most.toFixed(2)})`);
    await page.keyboard.press('Space'); // pause on the held frame for the picture
    // Orbit a quarter turn so the pair is seen from the side, hands between them.
    await page.mouse.move(640, 420);
    await page.mouse.down();
    await page.mouse.move(900, 420, { steps: 12 });
    await page.mouse.up();
    await sleep(300);
    const png = await page.screenshot();
    saveScreen('screenshot-hands.png', png);
    await page.keyboard.press('Space');
  });

  test('no console errors', () => {
    assert.deepEqual(quick.consoleErrors, []);
    assert.deepEqual(browser?.consoleErrors ?? [], []);
  });
});

describe('phone', () => {
  let browser;
  let page;

  before(async () => {
    // Half resolution (QUICK): a phone's 3 draws at 2 (the page's cap), and software WebGL made
    // the touch-steering checks wait minutes for their steps. These pictures check the layout,
    // in CSS pixels; docs/ shows framing.test.mjs's phone pictures, not these.
    browser = await launch({ viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, ...QUICK });
    page = browser.page;
  });

  after(async () => {
    await browser?.close();
  });

  test('a touch drag steers the leader', async () => {
    await page.goto(`${server.url}?seed=1`);
    await waitReady(page);
    const idle = await displacement(page, HOLD_STEPS);
    // Thumb down in the lower half, drag 80 px up ("away from the camera"), hold.
    let drag;
    const steered = await displacement(
      page,
      HOLD_STEPS,
      async () => {
        drag = await touchDrag(page, [195, 600], [195, 520]);
      },
      () => drag.release(),
    );
    assert.ok(steered.moved >= idle.moved + 1, `drag moved ${steered.moved.toFixed(2)} m, idle ${idle.moved.toFixed(2)} m`);
    // The page itself must not have scrolled or zoomed.
    const viewport = await page.evaluate(() => [window.scrollY, window.visualViewport?.scale ?? 1]);
    assert.deepEqual(viewport, [0, 1]);
  });

  test('plain words: every control is explained in the help, research terms only in its details fold', async () => {
    await page.goto(`${server.url}?seed=1`);
    await waitReady(page);
    await page.locator('.help-button').click();
    await page.locator('.help-overlay').waitFor({ state: 'visible', timeout: WAIT_MS });
    const seen = await page.evaluate(() => {
      const help = document.querySelector('.help-overlay').textContent;
      const fold = document.querySelector('.about-details');
      // Every control of the panel (folders included), open or folded.
      const labels = [...document.querySelectorAll('.duet-panel .lil-controller .lil-name')].map((e) => e.textContent.trim());
      const options = [...document.querySelectorAll('.duet-panel select option')].map((o) => o.textContent);
      // Text a visitor can see: visible text nodes outside the details fold, and the menu's options.
      const visible = [];
      const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
      for (let node = walker.nextNode(); node; node = walker.nextNode()) {
        const parent = node.parentElement;
        if (!parent || fold.contains(parent) || parent.closest('script, style, noscript')) continue;
        if (parent.checkVisibility({ visibilityProperty: true }) && node.textContent.trim()) visible.push(node.textContent.trim());
      }
      return { help, labels, options, visible: [...visible, ...options].join(' | '), fold: fold.textContent };
    });
    assert.ok(seen.labels.length >= 8, `panel labels: ${seen.labels}`);
    for (const label of seen.labels) {
      const plain = label.replace('■ stop recording', '● record');
      assert.ok(seen.help.includes(plain.replace(/ \(both dancers\)$/, '')), `the help explains "${label}"`);
    }
    assert.doesNotMatch(seen.visible, /temperature|ghost|CCM|p95|threads?\b|leashed|FID/i, 'research terms outside the details fold');
    // ...and they are one click away, in the fold.
    assert.match(seen.fold, /CCM/);
    assert.match(seen.fold, /temperature/);
    await page.locator('.about-details summary').click();
    assert.match(await page.locator('.engine-figures').textContent(), /step [\d.]+ ms \(p95/);
    await page.locator('.help-close').click();
    await page.locator('.help-overlay').waitFor({ state: 'hidden', timeout: WAIT_MS });
  });

  const boxes = async () =>
    page.evaluate(() => {
      const box = (selector) => {
        const r = document.querySelector(selector).getBoundingClientRect();
        return { x: r.left, y: r.top, w: r.width, h: r.height };
      };
      const canvas = box('canvas.stage');
      // The middle 40 % of the canvas, where the camera keeps the dancers.
      const centre = { x: canvas.x + 0.3 * canvas.w, y: canvas.y + 0.3 * canvas.h, w: 0.4 * canvas.w, h: 0.4 * canvas.h };
      // Each dancer's hip on screen, with a margin. The open panel (a sheet as tall as its
      // controls, a drawer on a phone held sideways) may cover part of the middle: the picture
      // then moves into the space it leaves (web/ui/layout.ts), and the dancers must be clear of it.
      const hip = ([x, y]) => ({ x: x - 20, y: y - 20, w: 40, h: 40 });
      return {
        title: box('.title-row'), hud: box('.hud'), panel: box('.duet-panel'), centre,
        leader: hip(window.duet.leader.screen), follower: hip(window.duet.follower.screen), hudLines: Math.round(box('.hud').h / 16),
      };
    });
  /** The boxes once the title, legend and panel stand still (a resize or the panel's open animation
   *  takes longer than any fixed wait on a busy machine): two reads 0.2 s apart agree. */
  const settled = async () => {
    let previous = '';
    for (const deadline = Date.now() + WAIT_MS; ; ) {
      const b = await boxes();
      const now = JSON.stringify([b.title, b.hud, b.panel, b.centre]);
      if (now === previous || Date.now() > deadline) return b;
      previous = now;
      await sleep(200);
    }
  };
  const overlap = (a, b) => a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h;
  const check = (b, state) => {
    const open = b.panel.h > 60;
    const pairs = [['title', 'hud'], ['title', 'panel'], ['hud', 'panel'], ['title', 'leader'], ['title', 'follower'], ['panel', 'leader'], ['panel', 'follower']];
    if (!open) pairs.push(['title', 'centre'], ['hud', 'centre'], ['panel', 'centre']);
    for (const [n1, n2] of pairs) {
      assert.ok(!overlap(b[n1], b[n2]), `${state}: ${n1} ${JSON.stringify(b[n1])} overlaps ${n2} ${JSON.stringify(b[n2])}`);
    }
    assert.equal(b.hudLines, 1, `${state}: the legend is one line`);
  };

  test('phone layout: title, legend and panel clear of each other and of the dancers (screenshot-phone-panel.png)', async () => {
    check(await settled(), 'panel folded');
    await page.locator('.duet-panel > .lil-title').click();
    await sleep(500); // lil-gui's open animation
    assert.ok(await page.evaluate(() => !document.querySelector('.duet-panel').classList.contains('lil-closed')), 'panel opened');
    check(await settled(), 'panel open');
    saveScreen('screenshot-phone-panel.png', await page.screenshot());
    await page.locator('.duet-panel > .lil-title').click();
    await sleep(500);
  });

  test('phone layout at 360-430 px, portrait and landscape: nothing overlaps, panel folded or open', async () => {
    const sizes = [[360, 740], [430, 932], [740, 360], [844, 390], [932, 430]];
    try {
      for (const [width, height] of sizes) {
        await page.setViewportSize({ width, height });
        await sleep(400); // resize observers, the camera's aspect
        const folded = await page.evaluate(() => document.querySelector('.duet-panel').classList.contains('lil-closed'));
        check(await settled(), `${width}x${height}, panel ${folded ? 'folded' : 'open'}`);
        await page.locator('.duet-panel > .lil-title').click();
        await sleep(500); // lil-gui's open and close animation
        check(await settled(), `${width}x${height}, panel ${folded ? 'open' : 'folded'}`);
        await page.locator('.duet-panel > .lil-title').click();
        await sleep(500);
      }
    } finally {
      await page.setViewportSize({ width: 390, height: 844 });
      await sleep(400);
    }
  });

  test('phone screenshot is not blank', async () => {
    await waitSteps(page, 10);
    const png = await page.screenshot();
    saveScreen('screenshot-phone.png', png);
    const variance = await pixelVariance(page, png);
    assert.ok(variance > MIN_VARIANCE, `screenshot variance ${variance.toFixed(1)}`);
  });

  test('no console errors', () => {
    assert.deepEqual(browser.consoleErrors, []);
  });
});

describe('failures show a message, not a blank page', () => {
  let browser;

  before(async () => {
    browser = await launch(QUICK);
  });

  after(async () => {
    await browser?.close();
  });

  test('missing manifest', async () => {
    const { page } = browser;
    await page.route('**/models/manifest.json', (route) => route.fulfill({ status: 404, body: 'not found' }));
    await page.goto(`${server.url}?seed=1`);
    await page.waitForFunction(() => window.duet?.error, null, { timeout: WAIT_MS });
    const state = await duet(page);
    assert.match(state.error, /missing/i);
    assert.equal(state.ready, false);
    assert.ok(await page.locator('.error-overlay').isVisible());
    await page.unroute('**/models/manifest.json');
  });

  test('corrupt model', async () => {
    const { page } = browser;
    // Same length as the manifest says, wrong content: the session must refuse it.
    await page.route('**/models/*.onnx', async (route) => {
      const response = await route.fetch();
      const body = Buffer.alloc((await response.body()).length, 7);
      await route.fulfill({ response, body });
    });
    await page.goto(`${server.url}?seed=1`);
    await page.waitForFunction(() => window.duet?.error, null, { timeout: WAIT_MS });
    const state = await duet(page);
    assert.match(state.error, /corrupt|does not match/i);
    assert.ok(await page.locator('.error-overlay').isVisible());
    await page.unroute('**/models/*.onnx');
  });
});
