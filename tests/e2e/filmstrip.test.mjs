// Film strips of the skinned dancers: for three seeds, 6 s of the running page at 1280×800 (and one
// seed at a phone's 390×844: filmstrip-phone-seed-2.png), one frame every 0.5 s (ArrowUp held for the first 2 s, ArrowLeft for the next 2 s, then nothing),
// composed into one PNG per seed: filmstrip-seed-N.png. Also screenshot-desktop.png and
// screenshot-phone.png. All go to runs/screens/ (harness.SCREENS, git-ignored; docs/testing.md says
// which of them docs/ keeps a copy of). The frames are copied from the stage canvas and composed with a 2D
// canvas inside the page (see captureStrip), so no image library is needed.
//
// Asserts, from window.duet only: the page is ready with skinned bodies and no error, the
// simulation advances between every two captures, both dancers' hips stay above 0.5 m in every
// captured frame, the leader moves when steered, and no frame is blank.
// Run: node --test tests/e2e/filmstrip.test.mjs

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { QUICK, WAIT_MS, distance, duet, launch, pixelVariance, saveScreen, sleep, startServer, waitReady, waitSteps } from './harness.mjs';

// DUET_FILMSTRIP_SEEDS=1 makes one strip only (while working on the bodies).
const SEEDS = (process.env.DUET_FILMSTRIP_SEEDS ?? '1,2,3').split(',').map(Number);
const FRAMES = 12;
const INTERVAL_MS = 500;
const COLUMNS = 4;
/** The two viewports: the part of each frame kept in the strip (the dancers stay near the centre,
 *  on the phone between the title card and the settings bar) and its scale in the strip. */
const DESKTOP = {
  name: 'desktop', launch: { viewport: { width: 1280, height: 800 } },
  crop: { x: 200, y: 110, width: 880, height: 600 }, scale: 0.5, file: (seed) => `filmstrip-seed-${seed}.png`,
};
/** docs/ shows the strip of seed 1 (filmstrip-seed-1.png): the other strips are drawn at half
 *  resolution (QUICK; captureStrip scales the canvas's pixels to the crop), the phone's too (at
 *  its 2, sixteen times the pixels software WebGL fills at 0.5). */
const QUICK_DESKTOP = { ...DESKTOP, launch: { ...DESKTOP.launch, ...QUICK } };
const DOCS_SEED = 1;
const PHONE = {
  name: 'phone', launch: { viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, ...QUICK },
  crop: { x: 0, y: 170, width: 390, height: 560 }, scale: 0.6, file: (seed) => `filmstrip-phone-seed-${seed}.png`,
};
const PHONE_SEED = 2;
const MIN_HIP = 0.5; // metres
const MIN_VARIANCE = 20; // luminance variance; a blank canvas is ~0
const READY_MS = WAIT_MS; // the machine is shared: first loads can be slow
/** Errors of a page that reloaded mid-test (window.duet gone, or the context destroyed). */
const RELOADED = /Execution context was destroyed|navigation|reading 'frame'|window\.duet/;

let server;

before(async () => {
  server = await startServer({ mode: 'dev' });
  // Warm the dev server (first compile, dependency scan) so the measured pages do not reload (the
  // shared one, DUET_DEV_URL, is warm already).
  if (server.shared) return;
  const warm = await launch(QUICK);
  warm.page.setDefaultTimeout(READY_MS);
  await warm.page.goto(`${server.url}?seed=1`).catch(() => undefined);
  await waitReady(warm.page).catch(() => undefined);
  await warm.close();
});

after(async () => {
  await server?.stop();
});

/**
 * In the page: copy the stage canvas every `interval` ms, `frames` times, each right after the
 * page has drawn (an animation-frame callback queued after the page's own, so the WebGL buffer
 * still holds the frame), with a snapshot of window.duet; then compose the copies into a grid with
 * captions and return it as a PNG data URL, with the snapshots and each cell's luminance variance.
 * Copying in the page keeps the 0.5 s rhythm on a slow machine, where a full-page screenshot can
 * take seconds.
 */
function captureStrip({ frames, interval, crop, scale, columns, title, keys, patience }) {
  return (async () => {
    const stage = document.querySelector('canvas.stage');
    const w = Math.round(crop.width * scale);
    const h = Math.round(crop.height * scale);
    const header = 36;
    const strip = document.createElement('canvas');
    strip.width = columns * w;
    strip.height = header + Math.ceil(frames / columns) * h;
    const c = strip.getContext('2d', { willReadFrequently: true });
    c.fillStyle = '#ffffff';
    c.fillRect(0, 0, strip.width, strip.height);
    c.fillStyle = '#222';
    c.font = '18px sans-serif';
    c.fillText(title, 10, 24);
    const states = [];
    const began = performance.now();
    for (let k = 0; k < frames; k++) {
      const wait = began + k * interval - performance.now();
      if (wait > 0) await new Promise((resolve) => setTimeout(resolve, wait));
      // A late copy (a slow software-GPU frame) can leave the next one only a frame later, before
      // any step: wait for a step since the last copy (the test fails without one, after `patience`).
      const previous = states.length ? states[states.length - 1].frame : -1;
      const deadline = performance.now() + patience;
      while (window.duet.frame === previous && performance.now() < deadline) await new Promise((resolve) => setTimeout(resolve, 10));
      await new Promise((resolve) => requestAnimationFrame(resolve));
      const x = (k % columns) * w;
      const y = header + Math.floor(k / columns) * h;
      // Scale the stage's pixels (the canvas may be larger than its CSS size) to the crop.
      const sx = stage.width / stage.clientWidth;
      c.drawImage(stage, crop.x * sx, crop.y * sx, crop.width * sx, crop.height * sx, x, y, w, h);
      const t = (performance.now() - began) / 1000;
      states.push({ ...JSON.parse(JSON.stringify(window.duet)), t });
      c.strokeStyle = '#bbb';
      c.strokeRect(x + 0.5, y + 0.5, w - 1, h - 1);
      c.fillStyle = 'rgba(255,255,255,0.8)';
      c.fillRect(x + 4, y + 4, 150, 22);
      c.fillStyle = '#222';
      c.font = '14px sans-serif';
      c.fillText(`t = ${t.toFixed(1)} s${keys[k] ? `  ${keys[k]}` : ''}`, x + 10, y + 20);
    }
    const variances = [];
    for (let k = 0; k < frames; k++) {
      const { data } = c.getImageData((k % columns) * w, header + Math.floor(k / columns) * h + 30, w, h - 30);
      let sum = 0;
      let squares = 0;
      for (let i = 0; i < data.length; i += 4) {
        const l = 0.299 * data[i] + 0.587 * data[i + 1] + 0.114 * data[i + 2];
        sum += l;
        squares += l * l;
      }
      const n = data.length / 4;
      variances.push(squares / n - (sum / n) ** 2);
    }
    return { png: strip.toDataURL('image/png'), states, variances };
  })();
}

/** One seed in one viewport: load, steer, copy 12 frames, write the strip, check what window.duet said. */
async function filmstrip(t, seed, view = DESKTOP) {
  const browser = await launch(view.launch);
  try {
    const { page, consoleErrors } = browser;
    page.setDefaultTimeout(READY_MS);
    await page.goto(`${server.url}?seed=${seed}`);
    await waitReady(page);
    await waitSteps(page, 20);

    // Keys from here while the page copies its frames (ArrowUp 0-2 s, ArrowLeft 2-4 s).
    const keys = Array.from({ length: FRAMES }, (_, k) => (k < 4 ? '↑ held' : k < 8 ? '← held' : ''));
    const capture = page.evaluate(captureStrip, {
      frames: FRAMES, interval: INTERVAL_MS, crop: view.crop, scale: view.scale, columns: COLUMNS, keys, patience: WAIT_MS,
      title: `duet · ${view.name} · seed ${seed} · every 0.5 s · ↑ 0–2 s, ← 2–4 s`,
    });
    await page.keyboard.down('ArrowUp');
    await sleep(4 * INTERVAL_MS);
    await page.keyboard.up('ArrowUp');
    await page.keyboard.down('ArrowLeft');
    await sleep(4 * INTERVAL_MS);
    await page.keyboard.up('ArrowLeft');
    const { png, states, variances } = await capture;
    saveScreen(view.file(seed), png);

    assert.equal(states.length, FRAMES);
    for (let k = 0; k < FRAMES; k++) {
      const state = states[k];
      assert.equal(state.error, null, `frame ${k}: error ${state.error}`);
      assert.equal(state.bodies, 'skinned');
      if (k > 0) assert.ok(state.frame > states[k - 1].frame, `frame ${k}: the simulation did not advance (step ${state.frame}, from t = ${states[k - 1].t.toFixed(2)} to ${state.t.toFixed(2)} s, step median ${state.stepMs?.median} ms, p95 ${state.stepMs?.p95} ms)`);
      for (const role of ['leader', 'follower']) {
        assert.ok(state[role].hip > MIN_HIP, `frame ${k}: the ${role}'s hip is at ${state[role].hip} m`);
      }
      assert.ok(variances[k] > MIN_VARIANCE, `frame ${k} looks blank (variance ${variances[k].toFixed(1)})`);
    }
    // Each copy waits only for the next drawn frame, so the strip spans about 5.5 s on a quiet
    // machine; a busy one draws a frame a second or slower. How long it took is printed, not checked.
    t.diagnostic(`captures took ${states[FRAMES - 1].t.toFixed(1)} s`);
    const moved = distance(states[0].leader.root, states[FRAMES - 1].leader.root);
    assert.ok(moved > 0.2, `the steered leader moved only ${moved.toFixed(2)} m`);
    assert.deepEqual(consoleErrors, []);
  } finally {
    await browser.close();
  }
}

/** The dev server reloads the page when a source file changes under it (someone editing while
 *  the test runs): that run says nothing about the page, so it is run once more. */
async function filmstripOnce(t, seed, view) {
  try {
    await filmstrip(t, seed, view);
  } catch (error) {
    if (!RELOADED.test(String(error))) throw error;
    await filmstrip(t, seed, view);
  }
}

describe('film strips of the skinned dancers', () => {
  for (const seed of SEEDS) {
    test(`seed ${seed}: 12 frames over 6 s (${DESKTOP.file(seed)})`, (t) => filmstripOnce(t, seed, seed === DOCS_SEED ? DESKTOP : QUICK_DESKTOP));
  }
  test(`phone, seed ${PHONE_SEED}: 12 frames over 6 s (${PHONE.file(PHONE_SEED)})`, (t) => filmstripOnce(t, PHONE_SEED, PHONE));

  test('desktop and phone screenshots (screenshot-desktop.png, screenshot-phone.png)', async () => {
    for (const [name, options] of [
      ['desktop', { viewport: { width: 1280, height: 800 } }],
      // The phone's at half resolution: docs/ shows framing.test.mjs's phone pictures, not this one.
      ['phone', { viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, ...QUICK }],
    ]) {
      const browser = await launch(options);
      try {
        const { page } = browser;
        page.setDefaultTimeout(READY_MS);
        await page.goto(`${server.url}?seed=1`);
        await waitReady(page);
        await waitSteps(page, 60);
        const state = await duet(page);
        assert.equal(state.bodies, 'skinned');
        assert.ok(state.follower.hip > MIN_HIP);
        const png = await page.screenshot();
        saveScreen(`screenshot-${name}.png`, png);
        const variance = await pixelVariance(page, png);
        assert.ok(variance > MIN_VARIANCE, `${name} screenshot variance ${variance.toFixed(1)}`);
      } finally {
        await browser.close();
      }
    }
  });
});
