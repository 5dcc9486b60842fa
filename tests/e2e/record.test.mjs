// End-to-end: record the duet and download it as BVH; make the leader dance a BVH file (file
// button and drag-and-drop); files the page cannot dance give a visible message and the page runs on.
// Run: node --test tests/e2e/record.test.mjs   (needs /usr/bin/chromium and models in public/models/)

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { QUICK, WAIT_MS, distance, duet, launch, sleep, startServer, waitReady, waitSteps, waitToast } from './harness.mjs';

const JOINTS = [
  // name, parent, offset in metres (a plain dancer facing +Z, arms out, left = +X)
  ['hip', -1, [0, 0, 0]],
  ['abdomen', 0, [0, 0.1, 0]],
  ['chest', 1, [0, 0.2, 0]],
  ['neck', 2, [0, 0.22, 0]],
  ['head', 3, [0, 0.12, 0]],
  ['lShldr', 2, [0.18, 0.18, 0]],
  ['lForeArm', 5, [0.28, 0, 0]],
  ['lHand', 6, [0.25, 0, 0]],
  ['rShldr', 2, [-0.18, 0.18, 0]],
  ['rForeArm', 8, [-0.28, 0, 0]],
  ['rHand', 9, [-0.25, 0, 0]],
  ['lThigh', 0, [0.1, -0.05, 0]],
  ['lShin', 11, [0, -0.42, 0]],
  ['lFoot', 12, [0, -0.42, 0]],
  ['rThigh', 0, [-0.1, -0.05, 0]],
  ['rShin', 14, [0, -0.42, 0]],
  ['rFoot', 15, [0, -0.42, 0]],
];
const UNITS_PER_METRE = 1 / 1.5; // the page's BVH units (web/mirror/skeleton.ts SCALE)

/**
 * A hand-made BVH of the 17-joint dancer walking forward (+Z) at `speed` m/s, legs and arms
 * swinging, at `fps`. `names` renames joints (for a BVH of another skeleton).
 */
function walkingBvh({ frames = 90, fps = 30, speed = 0.6, names = {} } = {}) {
  const lines = ['HIERARCHY'];
  const write = (j, depth) => {
    const [name, , offset] = JOINTS[j];
    const pad = '  '.repeat(depth);
    lines.push(`${pad}${j === 0 ? 'ROOT' : 'JOINT'} ${names[name] ?? name}`, `${pad}{`);
    lines.push(`${pad}  OFFSET ${offset.map((v) => (v * UNITS_PER_METRE).toFixed(6)).join(' ')}`);
    lines.push(`${pad}  CHANNELS ${j === 0 ? '6 Xposition Yposition Zposition' : '3'} Zrotation Xrotation Yrotation`);
    const children = JOINTS.flatMap(([, parent], c) => (parent === j ? [c] : []));
    for (const c of children) write(c, depth + 1);
    if (children.length === 0) lines.push(`${pad}  End Site`, `${pad}  {`, `${pad}    OFFSET 0 0.05 0`, `${pad}  }`);
    lines.push(`${pad}}`);
  };
  write(0, 0);
  lines.push('MOTION', `Frames: ${frames}`, `Frame Time: ${(1 / fps).toFixed(7)}`);
  for (let f = 0; f < frames; f++) {
    const phase = (2 * Math.PI * f) / fps; // one stride per second
    const swing = 25 * Math.sin(phase);
    const row = [0, (0.95 + 0.02 * Math.cos(2 * phase)) * UNITS_PER_METRE, ((speed * f) / fps) * UNITS_PER_METRE, 0, 0, 0];
    for (let j = 1; j < JOINTS.length; j++) {
      const name = JOINTS[j][0];
      let z = 0;
      let x = 0;
      if (name === 'lThigh') x = -swing;
      if (name === 'rThigh') x = swing;
      if (name === 'lShin' || name === 'rShin') x = 10 + 10 * Math.sin(phase + (name === 'lShin' ? 0 : Math.PI));
      if (name === 'lShldr') [z, x] = [-70, swing];
      if (name === 'rShldr') [z, x] = [70, -swing];
      row.push(z, x, 0);
    }
    lines.push(row.map((v) => v.toFixed(5)).join(' '));
  }
  return lines.join('\n') + '\n';
}

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

/** Check a BVH text the way a reader would: hierarchy, frame count, one row of 54 numbers per frame. */
function checkBvh(text) {
  assert.ok(text.startsWith('HIERARCHY\n'), 'starts with HIERARCHY');
  for (const [name] of JOINTS) assert.match(text, new RegExp(`(ROOT|JOINT) ${name}\\n`), `has joint ${name}`);
  const frames = Number(/\nFrames: (\d+)\n/.exec(text)?.[1]);
  assert.ok(frames > 0, `Frames: ${frames}`);
  assert.match(text, /\nFrame Time: 0\.0333333\n/);
  const rows = text.slice(text.indexOf('Frame Time:')).trim().split('\n').slice(1);
  assert.equal(rows.length, frames, 'one row per frame');
  for (const row of rows) {
    const values = row.split(' ').map(Number);
    assert.equal(values.length, 54);
    assert.ok(values.every(Number.isFinite), 'finite numbers');
  }
  return frames;
}

let server;
let browser;
let page;
let recordedLeader = null;

before(async () => {
  server = await startServer({ mode: 'dev' });
  browser = await launch({ acceptDownloads: true, ...QUICK });
  page = browser.page;
  // The first visit compiles the modules in the dev server; allow for it.
  await page.goto(`${server.url}?seed=1`);
  await waitReady(page);
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

describe('record and export', () => {
  test('records ~2 s and downloads one BVH per dancer', async () => {
    await waitSteps(page, 5);
    await button(page, '● record').click();
    await page.locator('.record-status', { hasText: 'REC' }).waitFor({ state: 'visible', timeout: WAIT_MS });
    await waitSteps(page, 60);
    // Download while recording: what was recorded so far is saved, and the recording goes on.
    const downloads = [];
    page.on('download', (d) => downloads.push(d));
    await button(page, 'download BVH').click();
    const deadline = Date.now() + WAIT_MS;
    while (downloads.length < 2 && Date.now() < deadline) await sleep(50);
    assert.equal(downloads.length, 2, 'two downloads');
    await waitSteps(page, 5);
    assert.ok(await page.locator('.record-status', { hasText: 'REC' }).isVisible(), 'still recording');
    await button(page, '■ stop recording').click();
    await page.locator('.record-status', { hasText: 'not downloaded' }).waitFor({ state: 'visible', timeout: WAIT_MS });

    const files = {};
    for (const download of downloads) {
      const name = download.suggestedFilename();
      const match = /^duet-(leader|follower)-\d{8}-\d{6}\.bvh$/.exec(name);
      assert.ok(match, `file name ${name}`);
      files[match[1]] = readFileSync(await download.path(), 'utf8');
    }
    assert.deepEqual(Object.keys(files).sort(), ['follower', 'leader']);
    const frames = checkBvh(files.leader);
    assert.equal(checkBvh(files.follower), frames, 'both dancers have every frame');
    assert.ok(frames >= 60, `${frames} frames recorded`);
    await waitToast(page, 'BVH saved', 'info');
    recordedLeader = files.leader;
  });
});

describe('files the leader cannot dance', () => {
  const cases = [
    ['notes.txt', 'hello, these are not motions', /not a BVH file/],
    ['empty.bvh', '', /empty/],
    ['robot.bvh', walkingBvh({ names: { lShin: 'leftKnee', rShin: 'rightKnee' } }), /lacks joint.*lShin/],
    ['film.bvh', walkingBvh({ fps: 24 }), /24 fps.*30, 60 or 120/],
  ];
  for (const [name, content, pattern] of cases) {
    test(`${name}: a visible message, no error, the duet dances on`, async () => {
      const before = await duet(page);
      await dropFile(page, name, content);
      const text = await waitToast(page, pattern);
      assert.match(text, new RegExp(name.replace('.', '\\.')));
      await waitSteps(page, 10);
      const state = await duet(page);
      assert.equal(state.error, null);
      assert.equal(state.ready, true);
      assert.ok(state.frame >= before.frame + 10, 'frames advance');
      assert.equal(await page.locator('.error-overlay').count(), 0, 'no error overlay');
    });
  }

  test('the message goes away when clicked', async () => {
    await dropFile(page, 'again.txt', 'nope');
    const toast = page.locator('.toast-error', { hasText: 'again.txt' });
    await toast.waitFor({ state: 'visible' });
    await toast.click();
    await toast.waitFor({ state: 'detached', timeout: WAIT_MS });
  });
});

describe('leader from a BVH file', () => {
  test('a file chosen with the file button: the leader dances it, the follower keeps reacting', async () => {
    await page.locator('input.leader-file').setInputFiles({ name: 'walk.bvh', mimeType: 'text/plain', buffer: Buffer.from(walkingBvh()) });
    await page.locator('.record-status', { hasText: 'leader dances walk.bvh' }).waitFor({ state: 'visible', timeout: WAIT_MS });
    await waitToast(page, 'The leader dances a file', 'info');
    const start = await duet(page);
    await waitSteps(page, 90); // 3 s of dance
    const end = await duet(page);
    assert.equal(end.error, null);
    assert.equal(end.ready, true);
    const leaderMoved = distance(start.leader.root, end.leader.root);
    // The file walks 0.6 m/s: ~1.8 m in 3 s (it loops, re-anchored where the leader stands).
    assert.ok(leaderMoved > 1.0, `leader walked ${leaderMoved.toFixed(2)} m`);
    const followerMoved = distance(start.follower.root, end.follower.root);
    assert.ok(followerMoved > 0.3, `follower moved ${followerMoved.toFixed(2)} m while the leader walked away`);
  });

  test('"leader back to model" ends the file', async () => {
    await button(page, 'leader back to model').click();
    await page.locator('.record-status', { hasText: 'leader dances' }).waitFor({ state: 'hidden', timeout: WAIT_MS });
    await waitSteps(page, 10);
    const state = await duet(page);
    assert.equal(state.error, null);
    assert.equal(state.ready, true);
  });

  test("the page's own recording, dropped on the page, is danced by the leader", async () => {
    assert.ok(recordedLeader, 'the recording test ran');
    await dropFile(page, 'duet-leader.bvh', recordedLeader);
    await page.locator('.record-status', { hasText: 'leader dances duet-leader.bvh' }).waitFor({ state: 'visible', timeout: WAIT_MS });
    await waitSteps(page, 30);
    const state = await duet(page);
    assert.equal(state.error, null);
    assert.equal(state.ready, true);
    await button(page, 'leader back to model').click();
  });

  test('no console errors', () => {
    assert.deepEqual(browser.consoleErrors, []);
  });
});
