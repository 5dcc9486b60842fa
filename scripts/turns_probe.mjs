// Leading a turn in the page: for each seed, the duet dances 4 s with nobody steering, then the
// leader is asked to lead a turn (askTurn, +1 counterclockwise seen from above on odd seeds, −1 on
// even ones), and the follower's facing is recorded at every simulation step (1/30 s) for 2.5 s;
// the same seed without any request is the control. A turn counts when her facing has changed by
// 300° or more in the asked direction within those 2.5 s. Prints a table and the totals.
//
// Run: node scripts/turns_probe.mjs [seeds, default 1-10] (dev server, headless Chromium, 1280×800)
// Environment: DUET_TURN_SPEED=1..4 runs the page's speed setting (default 2: the steps, and so the
// dance, are the same at any speed; only the wall time differs). DUET_TURN_JSON=path writes every
// step's facing there. DUET_TURN_FLIP=1 asks the other way (−1 on odd seeds, +1 on even ones).
// The page is reached through tests/e2e/turns.mjs (see there for how askTurn is called).

import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { ROOT, launch, startServer, waitReady } from '../tests/e2e/harness.mjs';
import { FPS, Reloaded, armProbe, followerTurn, leaderDivergence, leaderHand, readProbe, unwrap } from '../tests/e2e/turns.mjs';

const SEEDS = (process.argv[2] ?? '1,2,3,4,5,6,7,8,9,10').split(',').map(Number);
const SPEED = Number(process.env.DUET_TURN_SPEED ?? 2);
const FLIP = process.env.DUET_TURN_FLIP === '1';
const ASK_AT = 4 * FPS; // 4 s of dancing
const WINDOW = Math.round(2.5 * FPS); // 2.5 s after the request
const READY_MS = 180_000;

/** The models' fingerprints (they may be re-exported while this runs: printed before and after). */
const fingerprints = () => Object.entries(JSON.parse(readFileSync(join(ROOT, 'public/models/manifest.json'), 'utf8')).models).map(([name, m]) => `${name} ${m.fingerprint}`).join(', ');
const modelsBefore = fingerprints();
console.log(`models: ${modelsBefore}; speed ${SPEED}`);

const server = await startServer({ mode: 'dev' });
const browser = await launch({ viewport: { width: 1280, height: 800 } });
const { page, consoleErrors } = browser;
page.setDefaultTimeout(READY_MS);

/** One run of a seed: `direction` 0 asks nothing. Run again when the page reloaded under it. */
async function run(seed, direction) {
  for (let attempt = 1; ; attempt++) {
    try {
      return await runOnce(seed, direction);
    } catch (error) {
      if (!(error instanceof Reloaded) || attempt >= 4) throw error;
      console.log(`seed ${seed}: the page reloaded (someone edited it); again`);
    }
  }
}

async function runOnce(seed, direction) {
  // figures=0: he leads only the turn asked for, so the control leads none.
  await page.goto(`${server.url}?seed=${seed}&speed=${SPEED}&figures=0`);
  await waitReady(page, READY_MS);
  await armProbe(page, { askAt: ASK_AT, direction, until: ASK_AT + WINDOW });
  const probe = await readProbe(page, READY_MS);
  const first = probe.steps[0]?.frame;
  if (first === undefined || first > ASK_AT) throw new Error(`seed ${seed}: the recording began at step ${first}, after the request's step ${ASK_AT}`);
  return probe;
}

const rows = [];
const dump = {};
try {
  // Warm the dev server (first compile) so the measured pages do not reload.
  await page.goto(`${server.url}?seed=1`).catch(() => undefined);
  await waitReady(page, READY_MS).catch(() => undefined);
  for (const seed of SEEDS) {
    const direction = (seed % 2 === 1 ? 1 : -1) * (FLIP ? -1 : 1);
    const asked = await run(seed, direction);
    const control = await run(seed, 0);
    const a = followerTurn(asked.steps, ASK_AT, direction);
    const c = followerTurn(control.steps, ASK_AT, direction);
    const cAny = Math.max(followerTurn(control.steps, ASK_AT, 1).best, followerTurn(control.steps, ASK_AT, -1).best);
    const divergence = leaderDivergence(asked, control);
    const before = Math.max(0, ...divergence.filter((d) => d.frame <= ASK_AT).map((d) => d.distance));
    const firstApart = divergence.find((d) => d.frame > ASK_AT && d.distance > 0.05);
    const within1s = Math.max(0, ...divergence.filter((d) => d.frame > ASK_AT && d.frame <= ASK_AT + FPS).map((d) => d.distance));
    const askedSteps = asked.steps.filter((s) => s.frame > ASK_AT);
    const leadingFor = askedSteps.filter((s) => s.turnAsked !== 0).length / FPS;
    // His higher hand, highest within the 2.5 s, asked and not (a raised hand leads her turn).
    const hand = Math.max(...leaderHand(asked.steps, ASK_AT));
    const handUnasked = Math.max(...leaderHand(control.steps, ASK_AT));
    const aAny = Math.max(a.best, followerTurn(asked.steps, ASK_AT, -direction).best);
    rows.push({ seed, direction, a, c, aAny, cAny, before, within1s, hand, handUnasked, firstApart: firstApart ? (firstApart.frame - ASK_AT) / FPS : null, took: asked.took, leadingFor });
    const headingDeltas = (probe) => {
      const h = unwrap(probe.steps.filter((s) => s.frame >= ASK_AT).map((s) => s.followerHeading));
      return h.map((v) => ((v - h[0]) * 180) / Math.PI);
    };
    dump[seed] = { direction, asked: a.deltas, control: c.deltas, askedHeading: headingDeltas(asked), controlHeading: headingDeltas(control), divergence, figure: asked.steps.map((s) => [s.frame, s.turnAsked, ...s.figure.map((v) => +v.toFixed(3))]) };
    const r = rows[rows.length - 1];
    console.log(
      `seed ${seed} dir ${direction > 0 ? '+1 ccw' : '-1 cw '}: asked ${a.turned ? `yes ${a.at.toFixed(2)} s` : 'no'} (best ${a.best.toFixed(0)}°, net ${a.net.toFixed(0)}°), ` +
        `unasked ${c.turned ? `yes ${c.at.toFixed(2)} s` : 'no'} (best ${c.best.toFixed(0)}° that way, ${cAny.toFixed(0)}° any way, net ${c.net.toFixed(0)}°); ` +
        `leader apart before ${r.before.toFixed(4)} m, within 1 s ${within1s.toFixed(2)} m, > 5 cm after ${r.firstApart ?? '-'} s; ` +
        `his hand up to ${hand.toFixed(2)} m (unasked ${handUnasked.toFixed(2)} m); took ${asked.took} via ${asked.via}, request held ${leadingFor.toFixed(2)} s`,
    );
  }
} finally {
  await browser.close();
  await server.stop();
}

const yn = (t) => (t.turned ? `yes, ${t.at.toFixed(2)} s` : 'no');
console.log('\n| seed | direction | turned asked | asked: most / net that way | asked, most either way | turned unasked | unasked: most / net that way | unasked, most either way | his hand highest, asked / unasked |');
console.log('|---|---|---|---|---|---|---|---|---|');
for (const r of rows) {
  const d = r.direction;
  console.log(
    `| ${r.seed} | ${d > 0 ? '+1 (ccw)' : '−1 (cw)'} | ${yn(r.a)} | ${r.a.best.toFixed(0)}° / ${(d * r.a.net).toFixed(0)}° | ${r.aAny.toFixed(0)}° | ${yn(r.c)} | ${r.c.best.toFixed(0)}° / ${(d * r.c.net).toFixed(0)}° | ${r.cAny.toFixed(0)}° | ${r.hand.toFixed(2)} / ${r.handUnasked.toFixed(2)} m |`,
  );
}
const askedTurned = rows.filter((r) => r.a.turned).length;
const unaskedTurned = rows.filter((r) => r.c.turned).length;
console.log(`\nasked: turned ${askedTurned} of ${rows.length}; unasked: turned ${unaskedTurned} of ${rows.length} (≥ 300° in the asked direction within 2.5 s)`);
console.log(`either direction: asked ${rows.filter((r) => r.aAny >= 300).length} of ${rows.length}, unasked ${rows.filter((r) => r.cAny >= 300).length} of ${rows.length}`);
console.log(`his hand above 1.6 m: asked ${rows.filter((r) => r.hand > 1.6).length} of ${rows.length}, unasked ${rows.filter((r) => r.handUnasked > 1.6).length} of ${rows.length}`);
const modelsAfter = fingerprints();
if (modelsAfter !== modelsBefore) console.log(`the models changed during the run: now ${modelsAfter}`);
if (consoleErrors.length) console.log('console errors:', consoleErrors);
if (process.env.DUET_TURN_JSON) writeFileSync(process.env.DUET_TURN_JSON, JSON.stringify(dump));
