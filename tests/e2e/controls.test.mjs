// End-to-end: the keys always steer. After a click on any control of the settings panel (a
// button, a checkbox, a slider, the partner menu, a folder's title) the arrow keys steer the
// leader and Space pauses; no control catches Space or Enter by accident. The address keeps every
// setting as it changes, and a link brings them all back. On a phone: the pause button, "reset
// view", and camera limits that keep the pair in view whatever two fingers do.
// Run: node --test tests/e2e/controls.test.mjs   (needs /usr/bin/chromium and models in public/models/)
//
// Steering is measured in steps of the dance, not in wall time: 45 steps are 1.5 s of dance
// however busy the machine is (a slow machine dances in slow motion: web/ui/main.ts).

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { QUICK, WAIT_MS, distance, duet, launch, sleep, startServer, waitReady, waitSteps } from './harness.mjs';

/** 1.5 s of dance. */
const STEER_STEPS = 45;
/** Held for STEER_STEPS, ArrowUp carries the spot the leader dances around (window.duet.anchor,
 *  which moves only while he is steered) about 0.9 m; a key the page never saw leaves it where it
 *  was. (The leader's own root walked 1.7-2.6 m when the leader only walked; the leader that dances
 *  covers 0.4-2.5 m of it, in whatever figure he dances.) */
const MIN_STEER_M = 0.6;
/** DEFAULT_ORBIT in web/draw/scene.ts. */
const DEFAULT_CAMERA = { azimuth: 35, polar: 70, distance: 5.2 };

let server;

before(async () => {
  server = await startServer({ mode: 'dev' });
});

after(async () => {
  await server?.stop();
});

/** How far ArrowUp, held for STEER_STEPS steps, carries the leader's spot (m), from wherever it is. */
async function steerUp(page) {
  const start = await duet(page);
  await page.keyboard.down('ArrowUp');
  try {
    await waitSteps(page, STEER_STEPS);
  } finally {
    await page.keyboard.up('ArrowUp');
  }
  return distance(start.anchor, (await duet(page)).anchor);
}

/** What has focus, for messages. */
const focused = (page) => page.evaluate(() => {
  const e = document.activeElement;
  if (!e || e === document.body) return 'the page';
  return `${e.tagName.toLowerCase()} "${(e.textContent || '').trim().slice(0, 30)}"`;
});

const exactly = (text) => new RegExp(`^\\s*${text.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')}\\s*$`);
/** A real click, without waiting for the element to stand still for two frames first (slow with
 *  software rendering): the panel does not move. */
const FAST = { force: true };
const controller = (page, name) => page.locator('.duet-panel .lil-controller').filter({ has: page.locator('.lil-name', { hasText: exactly(name) }) });
const button = (page, name) => page.locator('.duet-panel button', { hasText: name }).first();
const recording = (page) => page.locator('.record-status.recording').isVisible();
/** The pause / resume button (the turn, clip and full screen buttons by the title share its look: class pause-button). */
const pauseButton = (page) => page.locator('.title-row .pause-button', { hasText: /^\s*(pause|resume)\s*$/ });

/** Click a slider where its value already is: a click on the slider, the value unchanged. */
async function clickSlider(page, row) {
  const box = await row.locator('.lil-slider').boundingBox();
  // lil-gui draws the value as the fill's share of the slider's width.
  const share = await row.locator('.lil-fill').evaluate((fill) => fill.getBoundingClientRect().width / fill.parentElement.getBoundingClientRect().width);
  await page.mouse.click(box.x + Math.max(1, Math.min(box.width - 1, share * box.width)), box.y + box.height / 2);
}

describe('desktop: a click in the panel leaves the keys steering', () => {
  let browser;
  let page;
  const dialogs = [];

  before(async () => {
    browser = await launch({ viewport: { width: 1280, height: 800 }, permissions: ['clipboard-read', 'clipboard-write'], ...QUICK });
    page = browser.page;
    page.on('dialog', (dialog) => {
      dialogs.push(dialog.message());
      dialog.dismiss().catch(() => undefined);
    });
    // With a listener the file choosers ("leader from BVH file…", the avatar) never open.
    page.on('filechooser', () => undefined);
    // At 4x speed the 1.5 s of dance per check take less of the test's time.
    await page.goto(`${server.url}?seed=1&speed=4`);
    await waitReady(page);
    await waitSteps(page, 5);
  });

  after(async () => {
    await browser?.close();
  });

  test('after a click on any panel control (or the buttons by the title), ArrowUp carries the leader spot ≥ 0.6 m in 1.5 s of dance', async () => {
    const results = [];
    const check = async (what) => {
      const moved = await steerUp(page);
      results.push({ what, moved, focus: await focused(page) });
    };
    const rows = await page.locator('.duet-panel .lil-controller').evaluateAll((rows) =>
      rows.map((row) => ({
        name: row.querySelector('.lil-name').textContent.trim(),
        kind: ['function', 'boolean', 'option', 'number'].find((k) => row.classList.contains(`lil-${k}`)),
        disabled: row.classList.contains('lil-disabled'),
      })),
    );
    const skipped = [];
    for (const { name, kind, disabled } of rows) {
      const row = controller(page, name);
      // Recording and its download have a test of their own (below); disabled buttons take no click.
      if (disabled || /record|download/.test(name)) {
        skipped.push(name);
        continue;
      }
      if (kind === 'function') {
        await row.locator('button').click(FAST);
        await sleep(100);
        await check(`button "${name}"`);
      } else if (kind === 'boolean') {
        await row.locator('input').click(FAST);
        await check(`checkbox "${name}"`);
        await row.locator('input').click(FAST); // back as it was
      } else if (kind === 'option') {
        // As a person does: click the menu, choose another partner, then the first one again.
        const select = row.locator('select');
        const first = await select.inputValue();
        const other = await select.evaluate((s) => [...s.options].find((o) => !o.selected).value);
        const model = (await duet(page)).model;
        await select.click(FAST);
        await select.selectOption(other);
        await page.waitForFunction((m) => window.duet.model !== m, model, { timeout: WAIT_MS });
        await select.click(FAST);
        await select.selectOption(first);
        await page.waitForFunction(() => window.duet.model === 'ours', null, { timeout: WAIT_MS });
        await waitSteps(page, 3);
        await check(`menu "${name}"`);
        assert.equal((await duet(page)).model, 'ours', 'the arrow keys did not change the partner');
      } else if (kind === 'number') {
        await clickSlider(page, row);
        await check(`slider "${name}"`);
        if (name === 'variety') {
          // Its text field keeps the keys while it has them; Enter gives them back.
          await row.locator('input').click(FAST);
          await page.keyboard.press('Enter');
          await check(`text field "${name}", then Enter`);
        }
      }
    }
    const report = () => {
      const failed = results.filter((r) => r.moved < MIN_STEER_M);
      assert.deepEqual(
        failed.map((r) => `after ${r.what}: ${r.moved.toFixed(2)} m (focus on ${r.focus})`),
        [],
        `ArrowUp walked ${results.map((r) => r.moved.toFixed(2)).join(', ')} m; skipped here: ${skipped.join(', ')}`,
      );
    };
    report();
    const names = rows.map((r) => r.name);
    for (const expected of ['partner', 'variety', 'tempo', 'music', 'his own turns', 'possible reactions', 'floor paths', 'show what the partner expects', 'start again (R)', 'reset view', 'copy link to this view', 'skeleton']) {
      assert.ok(names.includes(expected), `the panel has "${expected}" (it has ${names.join(', ')})`);
    }

    // Folding a folder and the whole panel, and unfolding them again.
    for (const title of ['record · play a file', 'settings']) {
      const bar = page.locator('.duet-panel .lil-title', { hasText: title }).first();
      await bar.click(FAST);
      await sleep(400);
      await bar.click(FAST);
      await sleep(400);
      await check(`title "${title}", twice`);
    }
    // The buttons by the title: pause (twice: paused, then dancing) and the help's "?" and "×".
    await pauseButton(page).click(FAST);
    await pauseButton(page).click(FAST);
    await check('pause button, twice');
    await page.locator('.help-button').click(FAST);
    await page.locator('.help-close').click(FAST);
    await check('help "?", then "×"');
    // Leading a turn (a request to the leader's network) by its button and by T leaves the keys steering.
    await page.locator('.turn-button').first().click(FAST);
    await check('turn button "↻ turn"');
    await page.keyboard.press('KeyT');
    await check('T (lead a turn)');
    report();
    assert.deepEqual(dialogs, [], 'no dialog');
  });

  test('every control clicked in a shuffled order, three times: none stops another, the keys steer and Space pauses', async (t) => {
    // The walk above goes in the panel's order; a visitor does not. Each walk clicks every
    // control once in an order drawn from its seed (printed, to replay one), then checks the keys.
    const names = await page.locator('.duet-panel .lil-controller').evaluateAll((rows) =>
      rows.filter((row) => !row.classList.contains('lil-disabled')).map((row) => row.querySelector('.lil-name').textContent.trim()));
    // Recording starts a take and its downloads save files: they have tests of their own.
    const clicks = names.filter((name) => !/record|download|leader from|avatar/.test(name)).map((name) => ({
      name,
      click: async () => {
        const row = controller(page, name);
        const kind = await row.evaluate((r) => ['function', 'boolean', 'option', 'number'].find((k) => r.classList.contains(`lil-${k}`)));
        if (kind === 'function') await row.locator('button').click(FAST);
        else if (kind === 'boolean') await row.locator('input').click(FAST);
        else if (kind === 'option') await row.locator('select').click(FAST);
        else await clickSlider(page, row);
      },
    }));
    for (const [name, selector] of [['pause', null], ['?', '.help-button'], ['turn', '.turn-button'], ['title', '.duet-panel .lil-title']]) {
      clicks.push({
        name,
        click: async () => {
          if (selector === null) await pauseButton(page).click(FAST);
          else await page.locator(selector).first().click(FAST);
          // The help and the panel's title toggle: a second click puts them back as they were.
          if (name === '?') await page.locator('.help-close').click(FAST);
          if (name === 'title') await page.locator(selector).first().click(FAST);
        },
      });
    }
    for (const seed of [1, 2, 3].map((k) => (Date.now() + k * 7919) % 100_000)) {
      // A small seeded shuffle (Lehmer generator), so a failing order can be replayed.
      let state = seed + 1;
      const random = () => (state = (state * 48271) % 2147483647) / 2147483647;
      const order = clicks.map((c) => ({ c, key: random() })).sort((a, b) => a.key - b.key).map(({ c }) => c);
      for (const { click } of order) await click();
      await page.keyboard.press('Escape'); // a menu left open by its click closes, as a visitor's would
      if ((await duet(page)).paused) await page.keyboard.press('Space'); // the pause button's click
      const walk = order.map((c) => c.name).join(' → ');
      t.diagnostic(`seed ${seed}: ${walk}`);
      const moved = await steerUp(page);
      assert.ok(moved >= MIN_STEER_M, `seed ${seed}: after ${walk}, ArrowUp carried the spot ${moved.toFixed(2)} m (focus on ${await focused(page)})`);
      await page.keyboard.press('Space');
      assert.equal((await duet(page)).paused, true, `seed ${seed}: Space pauses after the walk`);
      await page.keyboard.press('Space');
      assert.equal((await duet(page)).paused, false, `seed ${seed}: and Space resumes`);
      assert.equal((await duet(page)).error, null);
    }
    assert.deepEqual(dialogs, [], 'no dialog');
  });

  test('after "● record", Space pauses and resumes the dance and the recording goes on; Enter presses nothing', async () => {
    await button(page, '● record').click(FAST);
    await page.locator('.record-status.recording').waitFor({ state: 'visible', timeout: WAIT_MS });
    await page.keyboard.press('Space');
    await page.waitForFunction(() => window.duet.paused === true).catch(() => undefined);
    assert.equal((await duet(page)).paused, true, `Space did not pause (focus on ${await focused(page)})`);
    const paused = await pausedFrame(page);
    assert.ok(await recording(page), 'Space stopped the recording');
    await sleep(1000);
    assert.equal((await duet(page)).frame, paused, 'no step while paused');
    await page.keyboard.press('Space');
    await waitSteps(page, 5);
    assert.equal((await duet(page)).paused, false, 'a second Space resumes');
    assert.ok(await recording(page), 'still recording after the second Space');
    await page.keyboard.press('Enter');
    await sleep(300);
    assert.ok(await recording(page), 'Enter stopped the recording');
    const moved = await steerUp(page);
    assert.ok(moved >= MIN_STEER_M, `after "● record": ArrowUp walked ${moved.toFixed(2)} m`);
    assert.ok(await recording(page), 'steering stopped the recording');

    await button(page, '■ stop recording').click(FAST);
    await page.locator('.record-status', { hasText: 'not downloaded' }).waitFor({ state: 'visible', timeout: WAIT_MS });
    const afterStop = await steerUp(page);
    assert.ok(afterStop >= MIN_STEER_M, `after "■ stop recording": ArrowUp walked ${afterStop.toFixed(2)} m`);
    const downloads = [];
    page.on('download', (d) => downloads.push(d));
    await button(page, 'download BVH').click(FAST);
    const afterDownload = await steerUp(page);
    assert.ok(afterDownload >= MIN_STEER_M, `after "download BVH": ArrowUp walked ${afterDownload.toFixed(2)} m`);
    for (const deadline = Date.now() + WAIT_MS; downloads.length < 2 && Date.now() < deadline; ) await sleep(50);
    assert.equal(downloads.length, 2, 'one BVH file per dancer');
    assert.deepEqual(dialogs, [], 'no "Start a new take?" or any other dialog');
  });

  test('R puts the camera back to its first view, too', async () => {
    await page.mouse.move(640, 420);
    await page.mouse.down();
    await page.mouse.move(900, 300, { steps: 10 });
    await page.mouse.up();
    await page.mouse.wheel(0, 400);
    const turnedAway = () => window.duet.camera && Math.abs(window.duet.camera.azimuth - 35) > 10; // 35: DEFAULT_CAMERA.azimuth
    await page.waitForFunction(turnedAway).catch(() => undefined); // the drag's glide
    const turned = (await duet(page)).camera;
    assert.ok(turned && Math.abs(turned.azimuth - DEFAULT_CAMERA.azimuth) > 10, `the drag turned the camera: ${JSON.stringify(turned)}`);
    await page.keyboard.press('r');
    await waitCamera(page, DEFAULT_CAMERA, 'after R');
  });

  test('no console errors', () => {
    assert.deepEqual(browser.consoleErrors, []);
  });
});

/** Two camera places the same within what a link and a glide's last frames can tell apart. */
function sameCamera(camera, expected) {
  if (!camera || !expected) return false;
  const turn = Math.abs(((camera.azimuth - expected.azimuth + 540) % 360) - 180);
  return turn < 0.5 && Math.abs(camera.polar - expected.polar) < 0.5 && Math.abs(camera.distance - expected.distance) < 0.05;
}

function assertCamera(camera, expected, when) {
  assert.ok(camera, `${when}: window.duet.camera`);
  assert.ok(sameCamera(camera, expected), `${when}: camera ${JSON.stringify(camera)}, expected ${JSON.stringify(expected)}`);
}

/** The camera once it is at `expected` (the glide is counted in frames: slow on a busy machine). */
async function waitCamera(page, expected, when) {
  const deadline = Date.now() + WAIT_MS;
  let camera = (await duet(page)).camera;
  while (!sameCamera(camera, expected) && Date.now() < deadline) {
    await sleep(100);
    camera = (await duet(page)).camera;
  }
  assertCamera(camera, expected, when);
}

/** Wait for Space (or the pause button) to take effect and the step under way to end; the frame then. */
async function pausedFrame(page) {
  await page.waitForFunction(() => window.duet.paused === true);
  for (let frame = (await duet(page)).frame; ; ) {
    await sleep(500);
    const now = (await duet(page)).frame;
    if (now === frame) return now;
    frame = now;
  }
}

describe('the address keeps every setting', () => {
  let browser;

  before(async () => {
    browser = await launch({ viewport: { width: 1280, height: 800 }, ...QUICK });
  });

  after(async () => {
    await browser?.close();
  });

  /** Every panel control's value as shown: menus by their label, checkboxes, numbers. */
  const shown = (page) => page.locator('.duet-panel .lil-controller').evaluateAll((rows) =>
    Object.fromEntries(rows.flatMap((row) => {
      const name = row.querySelector('.lil-name').textContent.trim();
      const select = row.querySelector('select');
      const input = row.querySelector('input');
      if (select) return [[name, select.selectedOptions[0]?.textContent]];
      if (input?.type === 'checkbox') return [[name, input.checked]];
      if (input) return [[name, Number(input.value)]];
      return [];
    })));
  const query = (page) => page.evaluate(() => Object.fromEntries(new URLSearchParams(location.search)));

  /** The address once `key` in it has the value `value` (waits up to WAIT_MS; then the assert says what it is). */
  async function expectInAddress(page, key, value, after) {
    const deadline = Date.now() + WAIT_MS;
    let now = await query(page);
    while (now[key] !== value && Date.now() < deadline) {
      await sleep(100);
      now = await query(page);
    }
    assert.equal(now[key], value, `after ${after}, the address is ?${new URLSearchParams(now)}`);
  }

  test('each change is written to the address (one history entry), and the address brings every setting back', async () => {
    const { page } = browser;
    // ?ref is not a setting of the page: it must stay as it is.
    await page.goto(`${server.url}?seed=5&ref=notes`);
    await waitReady(page);
    const entries = await page.evaluate(() => history.length);

    await controller(page, 'partner').locator('select').selectOption({ label: 'baseline, no intention' });
    await expectInAddress(page, 'model', 'ccm', 'choosing the baseline partner');
    const ghosts = controller(page, 'possible reactions').locator('input');
    await ghosts.fill('3');
    await ghosts.press('Enter');
    await expectInAddress(page, 'ghosts', '3', 'typing 3 possible reactions');
    const tempo = controller(page, 'tempo').locator('input');
    await tempo.fill('181');
    await tempo.press('Enter');
    await expectInAddress(page, 'tempo', '181', 'typing tempo 181');
    await controller(page, 'music').locator('input').click(FAST);
    await expectInAddress(page, 'music', '0', 'turning the music off');
    const variety = controller(page, 'variety').locator('input');
    await variety.fill('0.35');
    await variety.press('Enter');
    await expectInAddress(page, 'temperature', '0.35', 'typing variety 0.35');
    await controller(page, 'floor paths').locator('input').click(FAST);
    await expectInAddress(page, 'trajectories', '0', 'turning floor paths off');
    await controller(page, 'show what the partner expects').locator('input').click(FAST);
    await expectInAddress(page, 'intentions', '1', 'turning the expectations on');
    await controller(page, 'skeleton').locator('input').click(FAST);
    await expectInAddress(page, 'skeleton', '1', 'turning the skeleton on');
    // The camera: a drag turns it; the address follows it while it glides. OrbitControls' glide
    // is counted in frames (with software rendering on a busy machine it can take many seconds),
    // and its last frames move it by less than the address's 0.1 (the page stops writing once the
    // place it writes stands still): so the address and the camera agree within a tolerance.
    await page.mouse.move(640, 420);
    await page.mouse.down();
    await page.mouse.move(800, 380, { steps: 8 });
    await page.mouse.up();
    const read = (value) => {
      const [azimuth, polar, distance] = String(value ?? '').split(',').map(Number);
      return [azimuth, polar, distance].every(Number.isFinite) ? { azimuth, polar, distance } : null;
    };
    let camera = null;
    let address = await query(page);
    let link = page.url();
    for (const deadline = Date.now() + WAIT_MS; Date.now() < deadline; address = await query(page)) {
      link = page.url();
      camera = (await duet(page)).camera;
      if (read(address.camera) && sameCamera(camera, read(address.camera))) break;
      await sleep(200);
    }
    assertCamera(camera, read(address.camera), `after a drag, the address ?${new URLSearchParams(address)} and the camera`);
    assert.equal(address.ref, 'notes', 'a parameter the page does not set stays');
    assert.equal(address.seed, '5', 'the seed stays');
    assert.equal(await page.evaluate(() => history.length), entries, 'no new history entries: the address is replaced, not pushed');

    const settings = await shown(page);
    await page.close();
    // The link, opened afresh in another tab.
    const second = await browser.context.newPage();
    const errors = [];
    second.on('pageerror', (error) => errors.push(String(error)));
    second.on('console', (message) => message.type() === 'error' && errors.push(message.text()));
    await second.goto(link);
    await waitReady(second);
    await waitSteps(second, 3);
    assert.deepEqual(await shown(second), settings, `the link ${link} shows the same panel`);
    const state = await duet(second);
    assert.equal(state.model, 'ccm');
    assertCamera(state.camera, read(new URL(link).searchParams.get('camera')), 'the link');
    assert.deepEqual([...browser.consoleErrors, ...errors], []);
  });
});

/** Two fingers on the screen, from `from` to `to` ([[x, y], [x, y]] each), through the DevTools
 *  protocol (Playwright has no multi-touch API). */
async function twoFingers(page, from, to, steps = 6) {
  const cdp = await page.context().newCDPSession(page);
  const points = (t) => [0, 1].map((i) => ({
    x: from[i][0] + (to[i][0] - from[i][0]) * t,
    y: from[i][1] + (to[i][1] - from[i][1]) * t,
    id: i + 1,
    radiusX: 8,
    radiusY: 8,
    force: 1,
  }));
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: points(0) });
  for (let s = 1; s <= steps; s++) {
    await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: points(s / steps) });
  }
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
  await cdp.detach();
  await sleep(1000); // the glide after the gesture (OrbitControls' damping)
}

describe('phone: pause, reset view, and a camera that keeps the pair in view', () => {
  let browser;
  let page;
  const size = { width: 390, height: 844 };

  before(async () => {
    browser = await launch({ viewport: size, isMobile: true, hasTouch: true, ...QUICK });
    page = browser.page;
    await page.goto(`${server.url}?seed=1`);
    await waitReady(page);
    await waitSteps(page, 5);
  });

  after(async () => {
    await browser?.close();
  });

  test('the pause button stops the dance and starts it again', async () => {
    const pause = pauseButton(page);
    assert.ok(await pause.isVisible(), 'a pause button is on screen');
    await pause.tap();
    const paused = await pausedFrame(page); // a step already under way ends
    await sleep(1000);
    assert.equal((await duet(page)).frame, paused, 'no step while paused');
    assert.match(await pause.textContent(), /resume/);
    await pause.tap();
    await waitSteps(page, 5);
    assert.equal((await duet(page)).paused, false);
    assert.match(await pause.textContent(), /pause/);
  });

  /** Both dancers' hips are drawn inside the screen. */
  async function bothInView(when) {
    const state = await duet(page);
    for (const dancer of ['leader', 'follower']) {
      const [x, y] = state[dancer].screen;
      assert.ok(x >= 0 && x <= size.width && y >= 0 && y <= size.height,
        `${when}: the ${dancer} is drawn at (${x.toFixed(0)}, ${y.toFixed(0)}), outside the ${size.width}x${size.height} screen (camera ${JSON.stringify(state.camera)})`);
    }
    return state.camera;
  }

  test('pinching and turning with two fingers never loses the pair; "reset view" brings the first view back', async () => {
    await pauseButton(page).tap(); // the pair stands still while the camera moves
    try {
      // Fingers apart, 8 times as far: closer, as close as it goes (from 5.2 m).
      await twoFingers(page, [[175, 420], [215, 420]], [[35, 420], [355, 420]]);
      await bothInView('pinched closer');
      // Fingers together, twice: as far as it goes.
      for (let i = 0; i < 2; i++) await twoFingers(page, [[35, 420], [355, 420]], [[175, 420], [215, 420]]);
      const far = await bothInView('pinched away');
      assert.ok(far.distance <= 12.01, `the camera went ${far.distance.toFixed(1)} m away, into the fog`);
      // Two fingers up and down the screen: over the top, and down to the floor.
      await twoFingers(page, [[150, 300], [240, 300]], [[150, 800], [240, 800]]);
      const top = await bothInView('turned over the top');
      await twoFingers(page, [[150, 700], [240, 700]], [[150, 100], [240, 100]]);
      const low = await bothInView('turned down to the floor');
      assert.ok(top.polar >= 4.9 && low.polar <= 88.1, `polar angle ${top.polar.toFixed(1)}..${low.polar.toFixed(1)}°`);

      await page.locator('.duet-panel > .lil-title').tap();
      await sleep(500); // lil-gui's open animation
      await page.locator('.duet-panel button', { hasText: 'reset view' }).tap();
      await waitCamera(page, DEFAULT_CAMERA, 'after "reset view"');
      await bothInView('after "reset view"');
      await page.locator('.duet-panel > .lil-title').tap();
      await sleep(500);
    } finally {
      await pauseButton(page).tap();
    }
  });

  test('no console errors', () => {
    assert.deepEqual(browser.consoleErrors, []);
  });
});
