// Leading a turn in the page (tests/e2e/turns.mjs says how the request is made and recorded).
// Seed 8 at 1280×800: the duet dances 4 s (120 steps) with nobody steering, then the leader is
// asked to lead a clockwise turn (−1, her right: what T does), and every step is
// recorded for 3 s; the same seed without a request is the control (half resolution, 4x speed: it
// takes no picture, and is compared step by step). The same led turn on a phone
// (390×844, touch). Film strips from the request on, a frame every 0.5 s of dance time:
// filmstrip-led-turn-desktop.png and filmstrip-led-turn-phone.png in runs/screens/ (harness.SCREENS).
//
// Asserts, from the page's own simulation:
// - the page takes the request and holds it while it is planned and danced (turnAsked: from the
//   next beat, FIGURE_BEATS.her_turn long), then lets it go; his own figures are off (?figures=0);
// - the two runs are the same dance up to the request (so what differs after it is the request's
//   doing), and the leader's pose differs by more than 1 cm within 1 s after it;
// - the request reaches both dancers through the figure they read: his input holds her turn, the
//   asked way, while it is danced, and no figure before the request;
// - the request raises his hand: his higher hand goes above LEAD_HAND m within 2.5 s (in the
//   recording it passes 1.6 m in 84 % of her turns; in Python within 4 s after 59 % of requests,
//   in the page after 48 % of 40, so seed 8 is one where it does: docs/results.md, "Leading a turn");
// - the page keeps dancing through the turn: a step every 1/30 s of dance, both hips above 0.5 m,
//   no error; the phone dances the same steps as the desktop;
// - the strips' frames are not blank.
// Whether the follower completes a turn is printed, not asserted: she is not told. Seed 8 is the
// strip's because she completes the led turn there, the asked way (491° to her right within 2.5 s,
// the first full turn 1.43 s after the request; 19° unasked) and his hand rises over his head
// (1.78 m): what a led turn looks like when it works.
//
// Run: node --test tests/e2e/turns.test.mjs (DUET_TURN_SEED, DUET_TURN_DIRECTION: another seed, +1 her left)

import { after, before, describe, test } from 'node:test';
import assert from 'node:assert/strict';
import { QUICK, WAIT_MS, launch, saveScreen, startServer, waitReady } from './harness.mjs';
import { FPS, J, Reloaded, armProbe, captureLedTurn, followerTurn, followerTurns, leaderDivergence, leaderHand, poseDistance, readProbe } from './turns.mjs';

const SEED = Number(process.env.DUET_TURN_SEED ?? 8);
const DIRECTION = Number(process.env.DUET_TURN_DIRECTION ?? -1); // −1 clockwise seen from above: her right (T); +1 her left (Shift+T)
const ASK_AT = 4 * FPS; // the request, in steps after the page started dancing
const UNTIL = ASK_AT + 3 * FPS; // recorded up to 3 s after the request
const FRAMES = 6; // strip frames, every 0.5 s of dance from the request on
const MIN_HIP = 0.5; // m
const LEAD_HAND = 1.6; // m above the floor: a raised hand
const MIN_VARIANCE = 20; // luminance variance of a strip cell; a blank canvas is ~0
const READY_MS = WAIT_MS; // the machine is shared: first loads can be slow
const DESKTOP = {
  name: 'desktop', launch: { viewport: { width: 1280, height: 800 } },
  crop: { x: 200, y: 110, width: 880, height: 600 }, scale: 0.5, file: 'filmstrip-led-turn-desktop.png',
};
/**
 * The desktop at half resolution (QUICK) and 4x speed, for the runs that take no picture: the
 * dance is the same step by step at any speed and resolution (the control run is compared step by
 * step with the asked one at 1x, full resolution), and a frame drawn every few steps rather than
 * every step leaves the machine to the steps.
 */
const QUICK_DESKTOP = { ...DESKTOP, launch: { ...DESKTOP.launch, ...QUICK }, query: '&speed=4', file: null };
const PHONE = {
  name: 'phone', launch: { viewport: { width: 390, height: 844 }, deviceScaleFactor: 2, isMobile: true, hasTouch: true },
  crop: { x: 0, y: 170, width: 390, height: 560 }, scale: 0.6, file: 'filmstrip-led-turn-phone.png',
};

let server;

before(async () => {
  server = await startServer({ mode: 'dev' });
  // Warm the dev server (first compile, dependency scan) so the measured pages do not reload (the
  // shared one, DUET_DEV_URL, is warm already).
  if (server.shared) return;
  const warm = await launch(QUICK);
  warm.page.setDefaultTimeout(READY_MS);
  await warm.page.goto(`${server.url}?seed=${SEED}`).catch(() => undefined);
  await waitReady(warm.page).catch(() => undefined);
  await warm.close();
});

after(async () => {
  await server?.stop();
});

/**
 * One run of a seed (SEED unless given) in a viewport, recorded up to step `until`: `direction` 0
 * asks nothing; `view.file` also writes a strip. Returns the recording, the strip's snapshots and
 * variances, and the console errors.
 */
async function runOnce(view, direction, strip, seed = SEED, until = UNTIL, shared = null) {
  const browser = shared ?? (await launch(view.launch));
  const errorsBefore = browser.consoleErrors.length;
  try {
    const { page, consoleErrors } = browser;
    page.setDefaultTimeout(READY_MS);
    // figures=0: he leads only the turn asked for, so the control run leads none.
    await page.goto(`${server.url}?seed=${seed}&figures=0${view.query ?? ''}`);
    // Armed as soon as the page's scripts are in, before its first step: at 4x speed the dance
    // was past the request's step by the time a probe armed after `ready` was in.
    await armProbe(page, { askAt: ASK_AT, direction, until });
    await waitReady(page);
    let capture = null;
    if (strip) {
      capture = page.evaluate(captureLedTurn, {
        askAt: ASK_AT, frames: FRAMES, every: FPS / 2, crop: view.crop, scale: view.scale, columns: 3, timeoutMs: READY_MS,
        title: `duet · ${view.name} · seed ${SEED} · a turn led ${direction > 0 ? 'to her left (↺)' : 'to her right (↻, T)'} at +0 s · every 0.5 s of dance`,
      });
      capture.catch(() => undefined); // awaited below; a reload rejects it first
    }
    const probe = await readProbe(page, READY_MS);
    let shot = null;
    if (capture) {
      shot = await capture;
      saveScreen(view.file, shot.png);
    }
    return { probe, shot, consoleErrors: consoleErrors.slice(errorsBefore) };
  } catch (error) {
    if (/Execution context was destroyed|navigation/.test(String(error))) throw new Reloaded(String(error));
    throw error;
  } finally {
    if (!shared) await browser.close();
  }
}

/** The dev server reloads the page when someone edits its source under the test: run again. */
async function run(view, direction, strip = false, seed = SEED, until = UNTIL, shared = null) {
  for (let attempt = 1; ; attempt++) {
    try {
      return await runOnce(view, direction, strip, seed, until, shared);
    } catch (error) {
      if (!(error instanceof Reloaded) || attempt >= 3) throw error;
    }
  }
}

/** The checks every run shares: it recorded the request's step and every step after, and danced. */
function checkDancing(name, probe, consoleErrors) {
  const frames = probe.steps.map((s) => s.frame);
  assert.ok(frames[0] <= ASK_AT, `${name}: the recording began at step ${frames[0]}, after the request's step ${ASK_AT}`);
  const after = probe.steps.filter((s) => s.frame >= ASK_AT);
  assert.deepEqual(after.map((s) => s.frame), Array.from({ length: UNTIL - ASK_AT + 1 }, (_, i) => ASK_AT + i), `${name}: a step is missing`);
  for (const s of after) {
    for (const role of ['leader', 'follower']) {
      assert.ok(s[role].every(Number.isFinite), `${name}, step ${s.frame}: the ${role}'s joints are not finite`);
      assert.ok(s[role][3 * J.hip + 1] > MIN_HIP, `${name}, step ${s.frame}: the ${role}'s hip is at ${s[role][3 * J.hip + 1].toFixed(2)} m`);
    }
    assert.equal(s.steerActive, false, `${name}, step ${s.frame}: someone steered`);
  }
  assert.deepEqual(consoleErrors, [], `${name}: console errors`);
}

/** The leader's higher hand above his head (m, negative: below), largest over the steps after the request. */
const handAboveHead = (probe) =>
  Math.max(...probe.steps.filter((s) => s.frame > ASK_AT).map((s) => Math.max(s.leader[3 * J.lHand + 1], s.leader[3 * J.rHand + 1]) - s.leader[3 * J.head + 1]));

describe(`leading a turn (seed ${SEED})`, () => {
  let desktopAsked = null;

  test('a request reaches the leader, and the page dances on (desktop, with filmstrip-led-turn-desktop.png)', async () => {
    const asked = await run(DESKTOP, DIRECTION, true);
    // The control takes no picture: drawn at half resolution (the dance does not depend on the
    // screen: the phone's test below checks that).
    const control = await run(QUICK_DESKTOP, 0);
    desktopAsked = asked;
    checkDancing('asked', asked.probe, asked.consoleErrors);
    checkDancing('control', control.probe, control.consoleErrors);

    // The page took the request at its step, held it, and let it go.
    assert.equal(asked.probe.took, true, `the request was refused (${asked.probe.via})`);
    const held = asked.probe.steps.filter((s) => s.frame > ASK_AT && s.turnAsked === DIRECTION).map((s) => s.frame);
    assert.ok(asked.probe.steps.filter((s) => s.frame <= ASK_AT).every((s) => s.turnAsked === 0), 'a turn was asked before the request');
    assert.equal(held[0], ASK_AT + 1, 'the step after the request does not hold it');
    assert.ok(held.length >= FPS, `the request was held for ${held.length} steps only`);
    assert.equal(asked.probe.steps.at(-1).turnAsked, 0, 'the request was still held 3 s later');
    assert.ok(control.probe.steps.every((s) => s.turnAsked === 0), 'the control run holds a request');

    // Same dance up to the request; the leader's motion differs within 1 s after it.
    const apart = leaderDivergence(asked.probe, control.probe);
    const before = apart.filter((d) => d.frame <= ASK_AT);
    assert.ok(before.length >= 10, `only ${before.length} steps to compare before the request`);
    const beforeMax = Math.max(...before.map((d) => d.distance));
    assert.ok(beforeMax < 0.001, `the runs differ by ${beforeMax.toFixed(4)} m before the request: the dance is not reproducible, the comparison says nothing`);
    const within = apart.filter((d) => d.frame > ASK_AT && d.frame <= ASK_AT + FPS);
    const withinMax = Math.max(...within.map((d) => d.distance));
    const first = within.find((d) => d.distance > 0.01);
    assert.ok(withinMax > 0.01, `the leader's pose within 1 s of the request differs by ${withinMax.toFixed(4)} m at most: the request did not reach his motion`);
    // The lead goes through the figure both dancers read (web/mirror/features.ts figureBlock): while
    // her turn is danced his input holds it, the asked way, inside now (key t+0; 4 kinds x (inside,
    // progress) a key, her turn to her left first); before the request, nothing.
    const NOW_KEY = 6;
    const kind = DIRECTION > 0 ? 0 : 1;
    const insideNow = (step) => step.figure[2 * (NOW_KEY * 4 + kind)];
    const danced = asked.probe.steps.filter((s) => s.frame >= ASK_AT + 12 && s.frame <= ASK_AT + 38);
    assert.ok(danced.length > 20 && danced.every((s) => insideNow(s) === 1), 'his input does not hold the asked turn while it is danced');
    assert.ok(asked.probe.steps.filter((s) => s.frame <= ASK_AT).every((s) => s.figure.every((v) => v === 0)), 'a figure before the request');
    const hand = Math.max(...leaderHand(asked.probe.steps, ASK_AT).slice(0, Math.round(2.5 * FPS) + 1));
    assert.ok(hand > LEAD_HAND, `his hand rose to ${hand.toFixed(2)} m at most within 2.5 s of the request: he did not lead`);

    // The strip: six frames from the request on, none blank.
    const { states, variances } = asked.shot;
    assert.equal(states.length, FRAMES);
    // window.duet.figure names the asked turn while it is danced: from the next beat (within 11
    // steps at 170 beats a minute) for FIGURE_BEATS.her_turn (38 steps); none once it is over (?figures=0).
    const herTurn = { name: 'her_turn', way: DIRECTION > 0 ? 'left' : 'right', asked: true };
    states.forEach((state, k) => {
      assert.equal(state.error, null);
      assert.ok(state.frame >= ASK_AT + k * (FPS / 2), `strip frame ${k} is of step ${state.frame}`);
      assert.ok(variances[k] > MIN_VARIANCE, `strip frame ${k} looks blank (variance ${variances[k].toFixed(1)})`);
      if (state.frame >= ASK_AT + 12 && state.frame <= ASK_AT + 38) assert.deepEqual(state.figure, herTurn, `strip frame ${k}: window.duet.figure`);
      if (state.frame > ASK_AT + 2 * FPS) assert.equal(state.figure, null, `strip frame ${k}: a figure 2 s after the request`);
    });

    const a = followerTurn(asked.probe.steps, ASK_AT, DIRECTION);
    const c = followerTurn(control.probe.steps, ASK_AT, DIRECTION);
    console.log(
      `seed ${SEED}: leader apart ${withinMax.toFixed(3)} m within 1 s (over 1 cm from +${((first.frame - ASK_AT) / FPS).toFixed(2)} s); ` +
        `follower turned ${a.best.toFixed(0)}° ${DIRECTION > 0 ? 'her left' : 'her right'} asked (full turn: ${a.turned ? `${a.at.toFixed(2)} s` : 'no'}), ${c.best.toFixed(0)}° unasked; ` +
        `his higher hand up to ${hand.toFixed(2)} m within 2.5 s, above his head at most ${handAboveHead(asked.probe).toFixed(2)} m asked, ${handAboveHead(control.probe).toFixed(2)} m unasked; ` +
        `strip steps ${states.map((s) => s.frame - ASK_AT).join(', ')} after the request`,
    );
  });

  test('the same led turn on a phone (filmstrip-led-turn-phone.png)', async () => {
    const phone = await run(PHONE, DIRECTION, true);
    checkDancing('phone', phone.probe, phone.consoleErrors);
    assert.equal(phone.probe.took, true);
    const { states, variances } = phone.shot;
    assert.equal(states.length, FRAMES);
    variances.forEach((v, k) => assert.ok(v > MIN_VARIANCE, `phone strip frame ${k} looks blank (variance ${v.toFixed(1)})`));
    // The dance does not depend on the screen: the phone's steps are the desktop's.
    if (desktopAsked) {
      const byFrame = new Map(desktopAsked.probe.steps.map((s) => [s.frame, s]));
      const shared = phone.probe.steps.filter((s) => byFrame.has(s.frame));
      assert.ok(shared.length > UNTIL - ASK_AT, 'too few steps to compare with the desktop');
      const worst = Math.max(...shared.map((s) => Math.max(poseDistance(s.leader, byFrame.get(s.frame).leader), poseDistance(s.follower, byFrame.get(s.frame).follower))));
      assert.ok(worst < 0.001, `the phone danced another dance: ${worst.toFixed(4)} m from the desktop's`);
    }
  });
});

// Leading a turn in several seeds: her turn asked after 4 s in each of SEEDS (askTurn, what T and
// Shift+T call), her left on odd seeds and her right on even ones, his own figures off, and her
// facing recorded for REQUEST_SECONDS. Counted as `lead` counts in Python (turns.mjs
// `followerTurns`: figures.turns, 300 degrees within 2.5 s). She gets no command: both dancers
// read the figure being led, and her guard prefers her network's samples that turn its way.
// With the shipped models she turned the asked way within 4 s in 13 of these 16 (Python's `lead`:
// after 75 % of 40 requests; docs/results.md, "Leading a turn"). Asserted: at least MIN_TURNED of
// the 16, which a follower who turns the asked way after 60 % of requests misses by chance about
// twice in a hundred models, and every request taken without an error.
const MIN_TURNED = 6;
const SEEDS = Array.from({ length: 16 }, (_, i) => i + 1);
const REQUEST_SECONDS = 4;
const WINDOW = REQUEST_SECONDS * FPS;
/** The seeds' runs take no picture: drawn at half resolution and 4x speed (QUICK_DESKTOP), one
 *  page after another in one browser (a launch each cost seconds of a busy machine). */
const SEEDS_VIEW = QUICK_DESKTOP;

describe(`leading a turn in ${SEEDS.length} seeds`, () => {
  test(`she turns the asked way within ${REQUEST_SECONDS} s of T or Shift+T in most of them`, async () => {
    const rows = [];
    const browser = await launch(SEEDS_VIEW.launch);
    try {
      for (const seed of SEEDS) {
        const direction = seed % 2 === 1 ? 1 : -1;
        const { probe, consoleErrors } = await run(SEEDS_VIEW, direction, false, seed, ASK_AT + WINDOW, browser);
        assert.deepEqual(consoleErrors, [], `seed ${seed}: console errors`);
        assert.equal(probe.took, true, `seed ${seed}: the request was refused (${probe.via})`);
        assert.ok(probe.steps[0].frame <= ASK_AT, `seed ${seed}: the recording began after the request`);
        const found = followerTurns(probe.steps, ASK_AT, WINDOW);
        rows.push({ seed, found, thatWay: found.some(([, d]) => d === direction) });
      }
    } finally {
      await browser.close();
    }
    const turned = rows.filter((r) => r.thatWay);
    console.log(`led turns: ${rows.map((r) => `seed ${r.seed} ${r.found.length ? r.found.map(([t, d]) => `${d > 0 ? 'left' : 'right'} at ${t.toFixed(2)} s`).join(' ') : 'none'}${r.thatWay ? ' (the asked way)' : ''}`).join(', ')}; ` +
      `she turned the asked way in ${turned.length} of ${rows.length}`);
    assert.ok(turned.length >= MIN_TURNED, `she turned the asked way within ${REQUEST_SECONDS} s of the request in only ${turned.length} of ${rows.length} seeds`);
  });
});
