// End-to-end: a leader file that holds what no dancer can do (the page's own recording with the
// hip of 10 frames moved to 1e30 m, 1e15 m or 1e9 m, or a rotation of 1e30 degrees) is refused
// with a message that names the quantity, the frame, the value and the bound; the dance goes on,
// and R brings both dancers back to the middle of the floor and of the screen, also while a file
// plays. Before the check (web/ui/leaderfile.ts) the 1e30 file was danced: both dancers left for
// 1e30 m and the camera, moved along, lost its offset to rounding, so R never brought them back.
// Run: node --test tests/e2e/badfile.test.mjs   (needs /usr/bin/chromium and models in public/models/)

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { QUICK, WAIT_MS, duet, launch, reset, sleep, startServer, waitReady, waitSteps, waitToast } from './harness.mjs';

const VIEWPORT = { width: 1280, height: 800 };

/** Dispatch a file drop on the page, as a browser does when a file is dragged onto it. */
async function dropFile(page, name, content) {
  await page.evaluate(
    ({ name, content }) => {
      const data = new DataTransfer();
      data.items.add(new File([content], name, { type: 'application/octet-stream' }));
      const target = document.querySelector('canvas') ?? document.body;
      for (const type of ['dragenter', 'dragover', 'drop']) {
        target.dispatchEvent(new DragEvent(type, { dataTransfer: data, bubbles: true, cancelable: true }));
      }
    },
    { name, content },
  );
}

const button = (page, name) => page.locator('.lil-gui button', { hasText: name });
const playing = (page, name) => page.locator('.record-status', { hasText: `leader dances ${name}` });


/** The page's recording with `value` in channels `channels` of frames 21..30 (counted from 1). */
function corrupt(text, channels, value) {
  const lines = text.split('\n');
  const first = lines.findIndex((l) => l.startsWith('Frame Time:')) + 1;
  for (let f = 20; f < 30; f++) {
    const row = lines[first + f].split(' ');
    for (const c of channels) row[c] = value;
    lines[first + f] = row.join(' ');
  }
  return lines.join('\n');
}

/** Both dancers near the middle of the floor, and drawn inside the window. */
function assertBack(state, label) {
  for (const dancer of ['leader', 'follower']) {
    const { root, screen } = state[dancer];
    const away = Math.hypot(root[0], root[1]);
    assert.ok(away < 1.5, `${label}: the ${dancer} is ${away.toExponential(2)} m from the middle of the floor`);
    assert.ok(screen, `${label}: the ${dancer} has a place on the screen`);
    const [x, y] = screen;
    assert.ok(x > 0 && x < VIEWPORT.width && y > 0 && y < VIEWPORT.height, `${label}: the ${dancer} is drawn at ${x}, ${y}, off the window`);
  }
}

let server;
let browser;
let page;
let recording = null;

before(async () => {
  server = await startServer({ mode: 'dev' });
  browser = await launch({ acceptDownloads: true, viewport: VIEWPORT, ...QUICK });
  page = browser.page;
  await page.goto(`${server.url}?seed=1`);
  await waitReady(page);
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

describe('leader files no dancer could have recorded', () => {
  test("the page's own recording (3 s)", async () => {
    await waitSteps(page, 5);
    await button(page, '● record').click();
    await page.locator('.record-status', { hasText: 'REC' }).waitFor({ state: 'visible', timeout: WAIT_MS });
    await waitSteps(page, 90);
    await button(page, '■ stop recording').click();
    const download = page.waitForEvent('download', { predicate: (d) => /leader/.test(d.suggestedFilename()), timeout: WAIT_MS });
    await button(page, 'download BVH').click();
    recording = readFileSync(await (await download).path(), 'utf8');
    assert.match(recording, /^HIERARCHY\n/);
    assert.ok(Number(/\nFrames: (\d+)\n/.exec(recording)[1]) >= 90);
  });

  test('hip at 1e30 m in 10 frames: a message naming it, the dance goes on, R brings both dancers back', async () => {
    assert.ok(recording, 'the recording test ran');
    const start = await duet(page);
    await dropFile(page, 'far.bvh', corrupt(recording, [0, 1, 2], '1e30'));
    const text = await waitToast(page, 'far.bvh', 'error');
    assert.match(text, /Cannot dance far\.bvh/);
    assert.match(text, /hip Xposition in frame 21 of \d+ is 1\.00e\+30 units \(1\.50e\+30 m\).*within 1000 m/);
    await waitSteps(page, 30);
    const state = await duet(page);
    assert.equal(state.error, null);
    assert.equal(state.ready, true);
    assert.ok(state.frame >= start.frame + 30, 'the dance goes on');
    assert.equal(await playing(page, 'far.bvh').count(), 0, 'the leader does not dance the file');
    assert.equal(await page.locator('.error-overlay').count(), 0, 'no error overlay');
    assertBack(await reset(page), 'after R');
  });

  const others = [
    ['far15.bvh', [0, 1, 2], '1e15', /hip Xposition in frame 21 of \d+ is 1\.00e\+15 units.*within 1000 m/],
    ['far9.bvh', [0, 1, 2], '1e9', /hip Xposition in frame 21 of \d+ is 1\.00e\+9 units.*within 1000 m/],
    // hip Yrotation, the 6th number of a row
    ['spin.bvh', [5], '1e30', /hip Yrotation in frame 21 of \d+ is 1\.00e\+30°.*1,000,000°/],
  ];
  for (const [name, channels, value, pattern] of others) {
    test(`${value} in ${channels.length === 3 ? 'the hip position' : 'a rotation'}: refused with a message`, async () => {
      await dropFile(page, name, corrupt(recording, channels, value));
      assert.match(await waitToast(page, name, 'error'), pattern);
      assert.equal(await playing(page, name).count(), 0);
      assert.equal((await duet(page)).error, null);
    });
  }

  test('the recording itself is danced, and R brings both dancers back while it plays', async () => {
    await dropFile(page, 'duet-leader.bvh', recording);
    await playing(page, 'duet-leader.bvh').waitFor({ state: 'visible', timeout: WAIT_MS });
    await waitSteps(page, 60);
    assertBack(await reset(page), 'R while the file plays');
    assert.equal(await playing(page, 'duet-leader.bvh').count(), 1, 'the file plays on after R');
    await waitSteps(page, 10);
    assert.equal((await duet(page)).error, null);
    await button(page, 'leader back to model').click();
    await sleep(100);
  });

  test('no console errors', () => {
    assert.deepEqual(browser.consoleErrors, []);
  });
});
