// End-to-end: a visitor's own files as real tools write them (issue 52).
// - Textured avatars keep their textures. Nearly every real VRM (VRoid Studio, Blender's VRM
//   add-on, UniVRM) keeps its textures as PNG or JPEG inside the file; three's glTF loader reads
//   them from blob: addresses, which the page's Content Security Policy must allow (index.html).
//   The tests' own avatars (tests/e2e/vrm.mjs) are textured the same way: a VRM 1.0 and a VRM 0.x
//   avatar are worn with no console error, and the pixels around each avatar's hips on the screen
//   have the texture's colour (its white base colour, had the texture failed).
// - A cut-short avatar or BVH file is refused with a message a visitor understands ("the file is
//   cut short: 20 000 of 36 776 bytes"), and the dance goes on.
// tests/web/avatar.test.ts and tests/web/leaderfile.test.ts check the same messages without a browser.
// Run: node --test tests/e2e/files.test.mjs   (needs /usr/bin/chromium and models in public/models/)

import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { QUICK, ROOT, duet, launch, startServer, waitReady, waitSteps } from './harness.mjs';
import { TEXTURE_RGB, makeVrm } from './vrm.mjs';

/** How long to wait for the page to do something before failing (as the other tests: DUET_WAIT_MS). */
const WAIT_MS = Number(process.env.DUET_WAIT_MS ?? 120_000);

let server;
let browser;

/**
 * Installed before the page's scripts: every toast's kind and text, kept in window.__filesToasts,
 * so that a message is seen even if it has gone again by the time the test looks.
 */
function keepToasts() {
  window.__filesToasts = [];
  new MutationObserver(() => {
    for (const toast of document.querySelectorAll('.toast')) {
      if (toast.__kept) continue;
      toast.__kept = true;
      const kind = [...toast.classList].find((c) => c.startsWith('toast-'))?.slice(6) ?? '';
      window.__filesToasts.push({ kind, text: toast.textContent });
    }
  }).observe(document, { childList: true, subtree: true });
}

before(async () => {
  server = await startServer();
  browser = await launch(QUICK);
  await browser.context.addInitScript(keepToasts);
  await browser.page.goto(`${server.url}?seed=2&camera=90,75,4`); // from the side: both dancers in view
  await waitReady(browser.page, WAIT_MS);
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

/** Drop a file at a point of the page (client pixels), as a browser does when one is dragged there. */
async function dropAt(page, name, bytes, [x, y] = [640, 400]) {
  await page.evaluate(
    ({ name, base64, x, y }) => {
      const data = new DataTransfer();
      data.items.add(new File([Uint8Array.from(atob(base64), (c) => c.charCodeAt(0))], name, { type: 'application/octet-stream' }));
      const target = document.querySelector('canvas');
      for (const type of ['dragenter', 'dragover', 'drop']) {
        target.dispatchEvent(new DragEvent(type, { dataTransfer: data, bubbles: true, cancelable: true, clientX: x, clientY: y }));
      }
    },
    { name, base64: Buffer.from(bytes).toString('base64'), x, y },
  );
}

/** The text of the first error toast whose text holds `title`, once one has been shown. */
async function errorToast(page, title) {
  const handle = await page.waitForFunction(
    (title) => window.__filesToasts.find((t) => t.kind === 'error' && t.text.includes(title))?.text,
    title, { timeout: WAIT_MS, polling: 50 },
  );
  return handle.jsonValue();
}

const avatars = async (page) => (await duet(page)).avatars ?? {};

/** Hue in degrees (0-360) and saturation (0-1) of an sRGB colour. */
function hueSaturation([r, g, b]) {
  const max = Math.max(r, g, b), min = Math.min(r, g, b), d = max - min;
  if (d === 0) return [0, 0];
  const h = max === r ? ((g - b) / d) % 6 : max === g ? (b - r) / d + 2 : (r - g) / d + 4;
  return [(60 * h + 360) % 360, d / max];
}

/**
 * The share of the pixels within `radius` px of a dancer's hips on the screen that have the avatar
 * texture's colour: its hue within 20°, clearly saturated, lit or in shade. An avatar whose texture
 * did not load is drawn in its white base colour, which counts for nothing; nothing else on the
 * page is green.
 */
async function textureShare(page, dancer, radius = 30) {
  const [x, y] = (await duet(page))[dancer].screen;
  const clip = { x: Math.round(x) - radius, y: Math.round(y) - radius, width: 2 * radius, height: 2 * radius };
  const png = await page.screenshot({ clip });
  // The browser decodes the screenshot (Node has no PNG decoder).
  const pixels = await page.evaluate(async (base64) => {
    const bitmap = await createImageBitmap(new Blob([Uint8Array.from(atob(base64), (c) => c.charCodeAt(0))], { type: 'image/png' }));
    const context = new OffscreenCanvas(bitmap.width, bitmap.height).getContext('2d');
    context.drawImage(bitmap, 0, 0);
    return Array.from(context.getImageData(0, 0, bitmap.width, bitmap.height).data);
  }, png.toString('base64'));
  const [hue] = hueSaturation(TEXTURE_RGB);
  let hits = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    const rgb = pixels.slice(i, i + 3);
    const [h, s] = hueSaturation(rgb);
    const off = Math.min(Math.abs(h - hue), 360 - Math.abs(h - hue));
    if (off < 20 && s > 0.35 && Math.max(...rgb) > 40) hits++;
  }
  return hits / (pixels.length / 4);
}

/** Pause (true) or resume the dance with Space, and wait until the page says it has. */
async function pause(page, paused) {
  await page.keyboard.press('Space');
  await page.waitForFunction((paused) => window.duet.paused === paused, paused, { timeout: WAIT_MS });
  // Two frames drawn since: what is on the screen is the paused pose.
  await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
}

/** Wait until `done(window.duet)` holds; on a timeout, the toasts shown say why not. */
async function waitFor(page, what, done) {
  try {
    await page.waitForFunction(done, null, { timeout: WAIT_MS, polling: 50 });
  } catch (error) {
    const toasts = await page.evaluate(() => window.__filesToasts.map((t) => `${t.kind}: ${t.text}`));
    throw new Error(`${what}: ${error.message}; toasts: ${JSON.stringify(toasts)}`);
  }
}

test('textured avatars, VRM 1.0 on the partner and VRM 0.x on the leader, are drawn in their texture with no console error', async () => {
  const { page } = browser;
  // Dropped while paused, at each dancer's hips: the dancer nearest the drop point wears the file,
  // and paused, the two cannot swap places between reading where they are and the drop.
  await pause(page, true);
  const state = await duet(page);
  await dropAt(page, 'textured-1.vrm', makeVrm('Textured', '1.0'), state.follower.screen);
  await waitFor(page, 'the partner wears textured-1.vrm', () => window.duet.avatars?.follower);
  await dropAt(page, 'textured-0.vrm', makeVrm('Textured older', '0.0'), state.leader.screen);
  await waitFor(page, 'the leader wears textured-0.vrm', () => window.duet.avatars?.leader);
  assert.deepEqual(Object.fromEntries(Object.entries(await avatars(page)).map(([k, v]) => [k, v.name])), { follower: 'textured-1.vrm', leader: 'textured-0.vrm' });
  await pause(page, false);
  await waitSteps(page, 10, WAIT_MS);
  // Paused again, so that the picture and the hips' places on the screen are of the same frame.
  await pause(page, true);
  const shares = {};
  for (const dancer of ['follower', 'leader']) shares[dancer] = await textureShare(page, dancer);
  await pause(page, false);
  const said = Object.entries(shares).map(([d, s]) => `${d} ${(100 * s).toFixed(1)} %`).join(', ');
  console.log(`pixels around the hips in the texture's colour: ${said}`);
  assert.deepEqual(browser.consoleErrors, [], `console errors (pixels in the texture's colour: ${said})`);
  for (const [dancer, share] of Object.entries(shares)) {
    assert.ok(share > 0.2, `pixels around the hips in the texture's colour: ${said}; the ${dancer}'s texture is not drawn`);
  }
});

/** The dance goes on after a refused file: no error, more steps taken, the avatars as they were. */
async function dancesOn(page, avatarsBefore) {
  const before = (await duet(page)).frame;
  await waitSteps(page, 10, WAIT_MS);
  const state = await duet(page);
  assert.equal(state.error, null);
  assert.ok(state.frame >= before + 10, 'the dance goes on');
  assert.deepEqual(Object.keys(state.avatars ?? {}).sort(), avatarsBefore);
  assert.equal(await page.locator('.error-overlay').count(), 0, 'no error overlay');
}

test('a cut-short avatar is refused with "the file is cut short: N of M bytes", and the dance goes on', async () => {
  const { page } = browser;
  const whole = makeVrm('Textured', '1.0');
  const worn = Object.keys(await avatars(page)).sort();
  await dropAt(page, 'cut.vrm', whole.subarray(0, 20_000), (await duet(page)).follower.screen);
  const text = (await errorToast(page, 'Cannot wear cut.vrm')).replace(/\u202f/g, ' ');
  const total = whole.length.toLocaleString('en-US').replace(/,/g, ' ');
  assert.match(text, new RegExp(`The file is cut short: 20 000 of ${total} bytes\\. Download or export it again\\.`));
  assert.doesNotMatch(text, /typed array|RangeError|GLTFLoader/);
  await dancesOn(page, worn);
  assert.equal((await avatars(page)).follower?.name, 'textured-1.vrm', 'the partner keeps the avatar it wore');
});

test('a cut-short BVH is refused with where it ends, and the dance goes on', async () => {
  const { page } = browser;
  // The CMU-skeleton fixture (9 frames at 120 fps), cut inside its 7th frame.
  const text = JSON.parse(readFileSync(join(ROOT, 'tests', 'fixtures', 'bvh.json'), 'utf8')).full.text;
  const lines = text.split('\n');
  const first = lines.findIndex((l) => l.startsWith('Frame Time:')) + 1;
  const cut = [...lines.slice(0, first + 6), lines[first + 6].trim().split(/\s+/).slice(0, 10).join(' ')].join('\n');
  const worn = Object.keys(await avatars(page)).sort();
  await dropAt(page, 'cut.bvh', Buffer.from(cut));
  const message = (await errorToast(page, 'Cannot dance cut.bvh')).replace(/\u202f/g, ' ');
  assert.match(message, /The file is cut short: it ends in frame 7 of the 9 it announces \(it holds \d+ of the \d+ numbers they need\)/);
  await dancesOn(page, worn);
  assert.equal(await page.locator('.record-status', { hasText: 'leader dances cut.bvh' }).count(), 0, 'the leader does not dance the file');
  assert.deepEqual(browser.consoleErrors, []);
});
