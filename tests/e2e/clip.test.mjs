// End-to-end: "● clip" by the title records the dance for 6 s, counts down on its label, and
// saves a video (duet-YYYYMMDD-HHMMSS.webm or .mp4) through a download; the keys steer right
// after the click. The full screen button is there where document.fullscreenEnabled, hidden where
// not (headless Chromium may say either).
// Run: node --test tests/e2e/clip.test.mjs   (needs /usr/bin/chromium and models in public/models/)

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { QUICK, WAIT_MS, distance, duet, launch, sleep, startServer, waitReady, waitSteps, waitToast } from './harness.mjs';

/** 1.5 s of dance (as in controls.test.mjs). Held that long, ArrowUp carries the spot the leader
 *  dances around (window.duet.anchor) about 0.9 m; his own hips, dancing since 2026-11-25, cover
 *  0.4-2.5 m of it (0.78 m once in a full run), so the spot is measured, as controls.test.mjs does. */
const STEER_STEPS = 45;
const MIN_STEER_M = 0.6;
/** More than a header: an empty recording is a few hundred bytes. How much more depends on how many
 *  frames the machine drew in the clip's 6 s (a busy one drew enough for 19.9 kB), so the first
 *  test decodes its clip and looks at a frame instead. */
const MIN_CLIP_BYTES = 5_000;
const EBML = [0x1a, 0x45, 0xdf, 0xa3];

let server;
let browser;
let page;

before(async () => {
  server = await startServer({ mode: 'dev' });
  browser = await launch({ viewport: { width: 1280, height: 800 }, acceptDownloads: true, ...QUICK });
  page = browser.page;
  await page.goto(`${server.url}?seed=1&speed=2`);
  await waitReady(page);
  await waitSteps(page, 5);
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

describe('desktop: save a clip, and full screen', { timeout: 5 * WAIT_MS }, () => {
  test('"● clip" counts down, saves a video of the dance, and the keys still steer', async () => {
    const clip = page.locator('.title-row .clip-button');
    assert.ok(await clip.isVisible(), 'a clip button by the title');
    const idle = (await clip.textContent()).trim();
    const download = page.waitForEvent('download', { timeout: WAIT_MS });
    await clip.click({ force: true });
    const labels = new Set();
    const badges = new Set();
    for (let i = 0; i < 30 && labels.size < 3; i++) {
      labels.add((await clip.textContent()).trim());
      const badge = page.locator('.clip-badge');
      if (await badge.isVisible()) badges.add((await badge.textContent()).trim());
      await sleep(250);
    }
    const counts = [...labels].filter((l) => /\d+ s/.test(l));
    assert.ok(counts.length >= 2, `the label counts down: ${JSON.stringify([idle, ...labels])}`);
    assert.ok(badges.size >= 1, 'a badge while recording');
    assert.notEqual(await page.evaluate(() => document.activeElement?.className), 'pause-button clip-button recording', 'the clip button let the focus go');

    // The keys steer while it records (the click gave the focus back to the page).
    const start = await duet(page);
    await page.keyboard.down('ArrowUp');
    try {
      await waitSteps(page, STEER_STEPS);
    } finally {
      await page.keyboard.up('ArrowUp');
    }
    const moved = distance(start.anchor, (await duet(page)).anchor);
    assert.ok(moved >= MIN_STEER_M, `ArrowUp carried the leader's spot ${moved.toFixed(2)} m after the clip button`);

    const types = await page.evaluate(() => ['video/mp4;codecs=avc1', 'video/mp4', 'video/webm;codecs=vp9', 'video/webm;codecs=vp8'].filter((t) => MediaRecorder.isTypeSupported(t)));
    console.log(`MediaRecorder records: ${types.join(', ')}`);
    const file = await download;
    const name = file.suggestedFilename();
    assert.match(name, /^duet-\d{8}-\d{6}\.(webm|mp4)$/);
    const bytes = readFileSync(await file.path());
    assert.ok(bytes.length > MIN_CLIP_BYTES, `the clip is ${bytes.length} bytes`);
    if (name.endsWith('.webm')) assert.deepEqual([...bytes.subarray(0, 4)], EBML, 'WebM starts with the EBML magic');
    // Its length, as a <video> reads it (a MediaRecorder WebM has no duration until seeked to the end).
    // In a blank page of its own: the site's Content-Security-Policy allows no blob: media.
    const blank = await browser.context.newPage();
    const seconds = await blank.evaluate(async ({ b64, type }) => {
      const data = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      const video = document.createElement('video');
      video.muted = true;
      video.src = URL.createObjectURL(new Blob([data], { type }));
      await new Promise((resolve, reject) => {
        video.onloadedmetadata = resolve;
        video.onerror = () => reject(new Error('the video does not load'));
      });
      if (!Number.isFinite(video.duration)) {
        video.currentTime = 1e9;
        await new Promise((resolve) => (video.ontimeupdate = resolve));
      }
      // A frame from the middle: the dance, not a black picture (mean luminance and its spread).
      video.currentTime = Math.min(3, video.duration / 2);
      await new Promise((resolve) => (video.onseeked = resolve));
      const canvas = document.createElement('canvas');
      canvas.width = 160;
      canvas.height = 100;
      const context = canvas.getContext('2d');
      context.drawImage(video, 0, 0, canvas.width, canvas.height);
      const pixels = context.getImageData(0, 0, canvas.width, canvas.height).data;
      let sum = 0, squares = 0;
      for (let i = 0; i < pixels.length; i += 4) {
        const y = 0.299 * pixels[i] + 0.587 * pixels[i + 1] + 0.114 * pixels[i + 2];
        sum += y;
        squares += y * y;
      }
      const n = pixels.length / 4, mean = sum / n;
      return { duration: video.duration, width: video.videoWidth, height: video.videoHeight, mean, variance: squares / n - mean * mean };
    }, { b64: bytes.toString('base64'), type: name.endsWith('.webm') ? 'video/webm' : 'video/mp4' });
    await blank.close();
    console.log(`clip ${name}: ${bytes.length} bytes, ${seconds.duration.toFixed(2)} s, ${seconds.width}x${seconds.height}, mid-clip frame luminance ${seconds.mean.toFixed(0)} ± ${Math.sqrt(seconds.variance).toFixed(0)}; ArrowUp walked ${moved.toFixed(2)} m`);
    assert.ok(seconds.duration > 4 && seconds.duration < 8, `the clip is ${seconds.duration} s long`);
    assert.ok(seconds.width > 0 && seconds.height > 0);
    assert.ok(seconds.mean > 40 && seconds.variance > 20, `a frame of the clip is not the dance: mean luminance ${seconds.mean.toFixed(0)}, variance ${seconds.variance.toFixed(0)}`);
    await page.waitForFunction((label) => document.querySelector('.clip-button').textContent.trim() === label, idle, { timeout: WAIT_MS });
    assert.ok(!(await page.locator('.clip-badge').isVisible()), 'the badge goes when the clip is saved');
  });

  test('the full screen button is shown exactly where document.fullscreenEnabled', async () => {
    const enabled = await page.evaluate(() => document.fullscreenEnabled);
    const visible = await page.locator('.title-row .fullscreen-button').isVisible();
    assert.equal(await page.locator('.title-row .fullscreen-button').count(), 1);
    assert.equal(visible, enabled, `fullscreenEnabled ${enabled}, button visible ${visible}`);
    if (enabled) {
      await page.locator('.fullscreen-button').click({ force: true });
      await page.waitForFunction(() => document.fullscreenElement !== null, null, { timeout: WAIT_MS });
      await page.locator('.fullscreen-button').click({ force: true });
      await page.waitForFunction(() => document.fullscreenElement === null, null, { timeout: WAIT_MS });
      const start = await duet(page);
      await page.keyboard.down('ArrowUp');
      try {
        await waitSteps(page, STEER_STEPS);
      } finally {
        await page.keyboard.up('ArrowUp');
      }
      const moved = distance(start.anchor, (await duet(page)).anchor);
      assert.ok(moved >= MIN_STEER_M, `ArrowUp carried the leader's spot ${moved.toFixed(2)} m after the full screen button`);
    }
  });

  test('where MediaRecorder makes no MP4 the clip is WebM (EBML magic); without MediaRecorder a toast says so', async () => {
    const webm = await browser.context.newPage();
    const errors = [];
    webm.on('pageerror', (error) => errors.push(String(error)));
    // As Firefox: no MP4 from MediaRecorder.
    await webm.addInitScript(() => {
      const supported = MediaRecorder.isTypeSupported.bind(MediaRecorder);
      MediaRecorder.isTypeSupported = (type) => !type.startsWith('video/mp4') && supported(type);
    });
    try {
      await webm.goto(`${server.url}?seed=2&speed=2`);
      await waitReady(webm);
      const download = webm.waitForEvent('download', { timeout: WAIT_MS });
      await webm.locator('.title-row .clip-button').click({ force: true });
      const file = await download;
      const bytes = readFileSync(await file.path());
      console.log(`clip ${file.suggestedFilename()}: ${bytes.length} bytes, starts ${[...bytes.subarray(0, 4)].map((b) => b.toString(16)).join(' ')}`);
      assert.match(file.suggestedFilename(), /^duet-\d{8}-\d{6}\.webm$/);
      assert.ok(bytes.length > MIN_CLIP_BYTES, `the clip is ${bytes.length} bytes`);
      assert.deepEqual([...bytes.subarray(0, 4)], EBML, 'WebM starts with the EBML magic');
      // A browser without MediaRecorder: a toast, no error.
      await webm.evaluate(() => delete window.MediaRecorder);
      await webm.locator('.title-row .clip-button').click({ force: true });
      await waitToast(webm, 'cannot record', null);
      assert.deepEqual(errors, []);
    } finally {
      await webm.close();
    }
  });

  test('no console errors', () => {
    assert.deepEqual(browser.consoleErrors, []);
  });
});
