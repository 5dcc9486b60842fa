// End-to-end: a VRM avatar dropped on a dancer dresses that dancer (web/draw/avatar.ts): its bones
// follow the dancer's while they dance and its feet stay on the floor, "plain bodies again" takes
// it off, the panel's button dresses the partner, and a file that is not an avatar gives a message
// while the page dances on. The avatar is the tests' own (tests/e2e/vrm.mjs); tests/web/avatar.test.ts
// checks the retargeting itself.
// Run: node --test tests/e2e/avatar.test.mjs

import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { WAIT_MS, duet, launch, pausedStill, saveScreen, startServer, waitReady, waitSteps, waitToast } from './harness.mjs';
import { makeVrm } from './vrm.mjs';

let server;
let browser;

before(async () => {
  server = await startServer();
  browser = await launch();
  await browser.page.goto(`${server.url}?seed=2&camera=90,75,4`); // from the side: both dancers in view
  await waitReady(browser.page);
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

/** Drop a file at a point of the page (client pixels), as a browser does when one is dragged there. */
async function dropAt(page, name, bytes, [x, y]) {
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

/**
 * Drop a file on a dancer: the page dresses the dancer drawn nearest the drop. The dance is paused
 * for it (on a busy machine the pair moves on between reading where a dancer is drawn and the
 * drop), and the point is a little beyond the dancer, away from the other one, so that the two
 * standing close cannot swap it.
 */
async function dropOn(page, dancer, name, bytes) {
  await page.keyboard.press('Space');
  await pausedStill(page);
  const state = await duet(page);
  const [x, y] = state[dancer].screen;
  const [ox, oy] = state[dancer === 'leader' ? 'follower' : 'leader'].screen;
  const { width, height } = page.viewportSize();
  const clamp = (v, top) => Math.min(top - 2, Math.max(2, v));
  await dropAt(page, name, bytes, [clamp(x + 0.25 * (x - ox), width), clamp(y + 0.25 * (y - oy), height)]);
  await page.keyboard.press('Space');
  await page.waitForFunction(() => window.duet.paused === false);
}

const avatars = async (page) => (await duet(page)).avatars ?? {};
const button = (page, name) => page.locator('.lil-gui button', { hasText: name });

test('a .vrm dropped on the partner dresses the partner; its bones follow the dance', async () => {
  const { page } = browser;
  await dropOn(page, 'follower', 'test-dancer.vrm', makeVrm('Test Dancer'));
  await page.waitForFunction(() => window.duet.avatars?.follower, null, { timeout: WAIT_MS });
  assert.deepEqual(Object.keys(await avatars(page)), ['follower']);
  assert.equal((await avatars(page)).follower.name, 'test-dancer.vrm');
  await waitToast(page, 'Your partner wears test-dancer.vrm', 'info');
  // While dancing: every bone of the avatar within a few degrees of the dancer's, ankles on the
  // dancer's (scaled) ankle heights.
  const samples = [];
  for (let i = 0; i < 10; i++) {
    await waitSteps(page, 6);
    samples.push((await avatars(page)).follower);
  }
  const worst = (key) => Math.max(...samples.map((s) => s[key]));
  assert.ok(worst('fitDeg') < 5, `worst bone angle per sample (degrees): ${samples.map((s) => s.fitDeg.toFixed(2)).join(' ')}`);
  assert.ok(worst('feetCm') < 5, `ankles off (cm): ${samples.map((s) => s.feetCm.toFixed(2)).join(' ')}`);
  saveScreen('screenshot-avatar.png', await page.screenshot());
});

test('a .vrm dropped on the leader dresses the leader; "plain bodies again" takes both off', async () => {
  const { page } = browser;
  await dropOn(page, 'leader', 'older.vrm', makeVrm('Older', '0.0'));
  await page.waitForFunction(() => window.duet.avatars?.leader, null, { timeout: WAIT_MS });
  assert.deepEqual(Object.keys(await avatars(page)).sort(), ['follower', 'leader']);
  await waitSteps(page, 10);
  const { leader } = await avatars(page);
  assert.ok(leader.fitDeg < 5 && leader.feetCm < 5, JSON.stringify(leader));
  await button(page, 'plain bodies again').click();
  await page.waitForFunction(() => Object.keys(window.duet.avatars ?? {}).length === 0, null, { timeout: WAIT_MS });
  assert.equal(await button(page, 'plain bodies again').isDisabled(), true);
});

test("the panel's avatar button dresses the partner (phones have no drag and drop)", async () => {
  const { page } = browser;
  await page.locator('input[aria-label="avatar file for the partner"]').setInputFiles({ name: 'chosen.vrm', mimeType: 'application/octet-stream', buffer: makeVrm('Chosen') });
  await page.waitForFunction(() => window.duet.avatars?.follower, null, { timeout: WAIT_MS });
  assert.deepEqual(Object.keys(await avatars(page)), ['follower']);
  assert.equal((await avatars(page)).follower.name, 'chosen.vrm');
  await button(page, 'plain bodies again').click();
  await page.waitForFunction(() => Object.keys(window.duet.avatars ?? {}).length === 0, null, { timeout: WAIT_MS });
});

test('a file that is not an avatar gives a message, and the dance goes on', async () => {
  const { page } = browser;
  const before = (await duet(page)).frame;
  await dropOn(page, 'follower', 'not-an-avatar.vrm', Buffer.from('HIERARCHY\nROOT hip'));
  assert.match(await waitToast(page, 'Cannot wear not-an-avatar.vrm', 'error'), /not a VRM avatar/);
  await waitSteps(page, 10);
  assert.ok((await duet(page)).frame > before, 'still dancing');
  assert.deepEqual(await avatars(page), {});
  assert.deepEqual(browser.consoleErrors, []);
});
