// The music in the page (web/ui/music.ts, web/music/groove.ts), desktop and phone.
//
// Asserts, from window.duet:
// - before any key or tap nothing of the band is fetched and no audio context exists; the dance
//   counts on in silence at the manifest's tempo, both dancers choosing their steps on the count;
// - the first key press (desktop) or tap (phone) starts the band: the audio context runs, the
//   band's loop is rendered and plays on, and the dance's count advances at the chosen tempo (within 1 % over 7 s of
//   the music's own clock, the audio clock the listener hears: one loop of the band at the slowest tempo);
// - the count each step dances on is the one heard: sampled beside what is heard now, the median
//   gap is under 50 ms;
// - tempo and mute from the panel reach the music and the address; ?tempo= and ?music=0 from the
//   address reach the page; arrow keys steer after each panel control; no page error.
//
// Run: node --test tests/e2e/music.test.mjs

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { QUICK, WAIT_MS, displacement, duet, launch, sleep, startServer, waitReady, waitSteps } from './harness.mjs';

/**
 * Seconds of the music's clock a tempo is read over: a loop of the band (16 beats) at the slowest
 * tempo (139 a minute: 6.9 s), so the count is read across the loop's restart. The count and the
 * clock are read together (window.duet.music: the count is the band's, of the clock's time), so
 * a longer read is no more precise.
 */
const SECONDS = Number(process.env.DUET_MUSIC_SECONDS ?? 7);

let server;
before(async () => {
  server = await startServer();
});
after(async () => {
  await server?.stop();
});

const music = (page) => page.evaluate(() => window.duet.music);
const query = (page) => page.evaluate(() => Object.fromEntries(new URLSearchParams(location.search)));

/** Wait until the band plays (the context running and notes scheduled). */
async function waitPlaying(page) {
  await page.waitForFunction(() => {
    const m = window.duet.music;
    return m.state === 'playing' && m.context === 'running' && m.scheduled > 0 && m.heard !== null;
  }, null, { timeout: WAIT_MS, polling: 50 });
}

/**
 * The rate the count the dance reads moves at, beats a minute, over `seconds` of the music: the
 * heard count against the audio clock the listener hears (the music's own clock: on a machine too
 * busy to render sound in time the music itself plays slow, and the dance with it). That each step
 * dances on this count is stepGap's to check.
 */
async function danceTempo(page, seconds) {
  const read = () => page.evaluate(() => ({ beat: window.duet.music.heard, time: window.duet.music.time }));
  const a = await read();
  await sleep(seconds * 1000);
  const b = await read();
  return ((b.beat - a.beat) / (b.time - a.time)) * 60;
}

/**
 * Median and worst gap, seconds, between the count the step on screen danced on and the one heard
 * when that step read it (what is heard now, less the time since). A page that cannot keep up
 * with real time owes steps, and each owed step reads the count of its own moment: the gap is then
 * that debt, and stays under 50 ms while the page keeps up.
 */
async function stepGap(page, samples = 40) {
  const gaps = [];
  for (let i = 0; i < samples; i++) {
    const { beat, heard, tempo, since } = await page.evaluate(() => ({
      beat: window.duet.beat, heard: window.duet.music.heard, tempo: window.duet.tempo,
      since: (performance.now() - window.duet.countAt) / 1000,
    }));
    gaps.push(Math.abs(((heard - beat) * 60) / tempo - since));
    await sleep(97);
  }
  gaps.sort((x, y) => x - y);
  return { median: gaps[gaps.length >> 1], worst: gaps[gaps.length - 1] };
}

/** The panel row whose label is `name`. */
const controller = (page, name) => page.locator('.duet-panel .lil-controller', { has: page.locator('.lil-name', { hasText: new RegExp(`^${name}$`) }) });

describe('music on a desktop', () => {
  let browser;
  const fetched = [];

  before(async () => {
    browser = await launch({ viewport: { width: 1280, height: 800 }, ...QUICK });
    browser.page.on('request', (request) => fetched.push(request.url()));
    await browser.page.goto(`${server.url}?seed=3`);
    await waitReady(browser.page);
  });
  after(async () => {
    await browser?.close();
  });

  test('silent until the first key: nothing of the band fetched, the dance counts at the manifest tempo', async () => {
    const { page } = browser;
    const manifest = await page.evaluate(() => fetch('/public/models/manifest.json').then((r) => r.json()).catch(() => null));
    const state = await duet(page);
    assert.equal(state.music.state, 'waiting');
    assert.equal(state.music.context, 'none', 'no audio context before a gesture');
    if (manifest?.music?.tempo) assert.equal(state.tempo, manifest.music.tempo);
    assert.ok(!fetched.some((url) => /\/music\/groove/.test(url)), 'the band is not fetched before the music starts');
    const a = state.beat;
    await waitSteps(page, 60);
    const later = await duet(page);
    const b = later.beat;
    // Each step each dancer's sample is chosen on the count (web/mirror/on_count.ts), unless a guard
    // had to take over: two dancers, 60 steps.
    if (manifest?.onCount) assert.ok(later.counted - state.counted >= 60, `chosen on the count in ${later.counted - state.counted} dancer-steps of >= 60 steps`);
    // 60 steps of dance = 2 s at the tempo (the silent count moves a step of the tempo per step)
    assert.ok(b - a >= (60 * state.tempo) / 60 / 30 - 1e-6, `silent count moved ${b - a} beats over >= 60 steps`);
  });

  test('the first key starts the band; the heard count keeps the tempo within 1 %; steps dance on what is heard', async () => {
    const { page } = browser;
    await page.keyboard.down('ArrowUp');
    await page.keyboard.up('ArrowUp');
    await waitPlaying(page);
    assert.ok(fetched.some((url) => /\/music\/groove/.test(url)), 'the band is fetched when the music starts');
    const tempo = (await duet(page)).tempo;
    const heard = await danceTempo(page, SECONDS);
    assert.ok(Math.abs(heard / tempo - 1) <= 0.01, `the dance counted ${heard.toFixed(2)} beats a minute of music at tempo ${tempo}`);
    const gap = await stepGap(page);
    assert.ok(gap.median <= 0.05, `count on screen vs heard: median ${(1000 * gap.median).toFixed(0)} ms (worst ${(1000 * gap.worst).toFixed(0)} ms)`);
    const before = await music(page);
    await sleep(2000);
    const later = await music(page);
    assert.ok(later.context === 'running' && later.heard > before.heard + 1, 'the band plays on');
    assert.equal(later.dropped, 0, 'no note dropped');
  });

  test('tempo and mute from the panel reach the music and the address; the arrows still steer after each', async () => {
    const { page, consoleErrors } = browser;
    const tempoBox = controller(page, 'tempo').locator('input');
    await tempoBox.fill('190');
    await tempoBox.press('Enter');
    await page.waitForFunction(() => new URLSearchParams(location.search).get('tempo') === '190', null, { timeout: WAIT_MS });
    assert.equal((await duet(page)).tempo, 190);
    // the band renders the new tempo in the background and takes it over on a beat
    await page.waitForFunction(() => window.duet.music.tempo === 190, null, { timeout: WAIT_MS, polling: 50 });
    const heard = await danceTempo(page, 8);
    assert.ok(Math.abs(heard / 190 - 1) <= 0.01, `the dance counted ${heard.toFixed(1)} beats a minute after choosing 190`);
    // The number box keeps the arrows while it has focus (it is a number); a click on the page gives them back.
    await page.mouse.click(640, 700);
    const steered = await displacement(page, 45, () => page.keyboard.down('ArrowUp'), () => page.keyboard.up('ArrowUp'));
    assert.ok(steered.moved > 0.2, `ArrowUp after the tempo box moved the leader's spot ${steered.moved.toFixed(2)} m`);

    await controller(page, 'music').locator('input').click();
    await page.waitForFunction(() => window.duet.music.state === 'muted', null, { timeout: WAIT_MS });
    assert.equal((await query(page)).music, '0');
    assert.equal((await music(page)).heard, null, 'muted: nothing heard');
    const a = (await duet(page)).beat;
    await waitSteps(page, 30);
    assert.ok((await duet(page)).beat > a, 'muted, the dance keeps its silent count');
    const steeredMuted = await displacement(page, 45, () => page.keyboard.down('ArrowLeft'), () => page.keyboard.up('ArrowLeft'));
    assert.ok(steeredMuted.moved > 0.2, `ArrowLeft after the music box moved the spot ${steeredMuted.moved.toFixed(2)} m`);

    await controller(page, 'music').locator('input').click();
    await waitPlaying(page);
    assert.equal((await query(page)).music, undefined, 'playing is the default: not in the address');
    assert.deepEqual(consoleErrors, []);
  });

  test('the address brings tempo and mute back', async () => {
    const { page } = browser;
    await page.goto(`${server.url}?seed=3&tempo=160&music=0`);
    await waitReady(page);
    const state = await duet(page);
    assert.equal(state.tempo, 160);
    assert.equal(state.music.state, 'muted');
    await page.keyboard.press('ArrowRight');
    await sleep(500);
    assert.equal((await music(page)).context, 'none', 'muted by the address: no audio context even after a key');
    const shown = await controller(page, 'tempo').locator('input').inputValue();
    assert.equal(Number(shown), 160);
    // an address tempo out of range is clamped to what the control offers
    await page.goto(`${server.url}?seed=3&tempo=900`);
    await waitReady(page);
    assert.equal((await duet(page)).tempo, 200);
  });
});

describe('music on a phone', () => {
  let browser;

  before(async () => {
    browser = await launch({ viewport: { width: 390, height: 844 }, isMobile: true, hasTouch: true, ...QUICK });
    await browser.page.goto(`${server.url}?seed=4`);
    await waitReady(browser.page);
  });
  after(async () => {
    await browser?.close();
  });

  test('the first tap starts the band and the count keeps the tempo', async () => {
    const { page, consoleErrors } = browser;
    assert.equal((await music(page)).state, 'waiting');
    await page.touchscreen.tap(195, 500);
    await waitPlaying(page);
    const tempo = (await duet(page)).tempo;
    const heard = await danceTempo(page, SECONDS);
    assert.ok(Math.abs(heard / tempo - 1) <= 0.01, `the dance counted ${heard.toFixed(2)} beats a minute of music at tempo ${tempo}`);
    const gap = await stepGap(page, 20);
    assert.ok(gap.median <= 0.05, `count on screen vs heard: median ${(1000 * gap.median).toFixed(0)} ms`);
    assert.deepEqual(consoleErrors, []);
  });
});
