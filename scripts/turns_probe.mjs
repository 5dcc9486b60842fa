// Leading a turn in the page, counted as `python -m training.evaluation.lead` counts it: for each
// seed the duet dances with nobody steering and without his own figures (?figures=0), and is asked
// for her turn 3 s and 10 s into the dance (her right, then her left, on even seeds: T then Shift+T;
// the other order on odd ones); every step is recorded to 4 s after the second request, and the
// same seed never asked is the control. A request works when she completes a turn (figures.turns
// on her facing: 300° within 2.5 s, tests/e2e/turns.mjs `followerTurns`) within REQUEST_SECONDS of
// dance after it; the control's same windows say how often she turns unasked. Also counted: his
// higher hand above 1.6 m within those seconds. Prints a row per request and the totals.
//
// Run: node scripts/turns_probe.mjs [seeds, default 0-19] (dev server, headless Chromium, 1280×800)
// Environment: DUET_TURN_SPEED=1..4 runs the page's speed setting (default 1, so that the probe is
// armed before the first request at 3 s; the steps, and so the dance, are the same at any speed;
// only the wall time differs). DUET_TURN_JSON=path writes the rows.

import { writeFileSync } from 'node:fs';
import { QUICK, launch, startServer, waitReady } from '../tests/e2e/harness.mjs';
import { FPS, Reloaded, armProbe, followerTurns, leaderHand, readProbe } from '../tests/e2e/turns.mjs';

const SEEDS = (process.argv[2] ?? Array.from({ length: 20 }, (_, i) => i).join(',')).split(',').map(Number);
const SPEED = Number(process.env.DUET_TURN_SPEED ?? 1);
const ASK_AT = [3 * FPS, 10 * FPS]; // lead.WARM_UP and REQUEST_EVERY
const REQUEST_SECONDS = 4; // lead.REQUEST_SECONDS
const WINDOW = REQUEST_SECONDS * FPS;
const UNTIL = ASK_AT[ASK_AT.length - 1] + WINDOW;
const HAND_RAISED = 1.6; // m (figures.HAND_RAISED)
const READY_MS = 300_000;

const server = await startServer({ mode: 'dev' });
const browser = await launch({ viewport: { width: 1280, height: 800 }, ...QUICK });
const { page, consoleErrors } = browser;
page.setDefaultTimeout(READY_MS);

/** One run of a seed, asked (`asks`) or not ([]); run again when the page reloaded under it. */
async function run(seed, asks) {
  for (let attempt = 1; ; attempt++) {
    try {
      await page.goto(`${server.url}?seed=${seed}&speed=${SPEED}&figures=0`);
      await waitReady(page, READY_MS);
      await armProbe(page, { asks, until: UNTIL });
      const probe = await readProbe(page, READY_MS);
      if (probe.steps[0]?.frame > ASK_AT[0]) throw new Error(`seed ${seed}: the recording began at step ${probe.steps[0].frame}`);
      return probe;
    } catch (error) {
      if (!(error instanceof Reloaded) || attempt >= 4) throw error;
      console.log(`seed ${seed}: the page reloaded (someone edited it); again`);
    }
  }
}

const rows = [];
try {
  // Warm the dev server (first compile) so the measured pages do not reload.
  await page.goto(`${server.url}?seed=1`).catch(() => undefined);
  await waitReady(page, READY_MS).catch(() => undefined);
  for (const seed of SEEDS) {
    const ways = seed % 2 === 0 ? [-1, 1] : [1, -1];
    const asks = ASK_AT.map((at, i) => ({ at, direction: ways[i] }));
    const asked = await run(seed, asks);
    const control = await run(seed, []);
    for (const { at, direction } of asks) {
      const a = followerTurns(asked.steps, at, WINDOW);
      const c = followerTurns(control.steps, at, WINDOW);
      const hand = Math.max(...leaderHand(asked.steps, at).slice(0, WINDOW + 1));
      const handUnasked = Math.max(...leaderHand(control.steps, at).slice(0, WINDOW + 1));
      const row = {
        seed, at: at / FPS, direction, turned: a.length > 0, thatWay: a.some(([, d]) => d === direction), first: a[0]?.[0] ?? null,
        turnedUnasked: c.length > 0, hand, handUnasked, took: asks.every((x) => asked.asks.find((y) => y.at === x.at)?.took),
      };
      rows.push(row);
      console.log(
        `seed ${seed} at ${row.at} s, her ${direction > 0 ? 'left ' : 'right'}: asked ${row.thatWay ? `the asked way, ${row.first.toFixed(2)} s` : row.turned ? 'the other way' : 'no turn'}, ` +
          `unasked ${row.turnedUnasked ? 'turned' : 'no turn'}; his hand up to ${hand.toFixed(2)} m (unasked ${handUnasked.toFixed(2)} m)`,
      );
    }
  }
} finally {
  await browser.close();
  await server.stop();
}

const share = (f) => `${Math.round((100 * rows.filter(f).length) / rows.length)} %`;
const way = (d) => {
  const r = rows.filter((x) => x.direction === d);
  return `${r.filter((x) => x.thatWay).length} of ${r.length}`;
};
console.log(`\n${rows.length} requests over ${SEEDS.length} seeds, within ${REQUEST_SECONDS} s of dance (figures.turns on her facing):`);
console.log(`- she turned: ${share((r) => r.turned)} asked, ${share((r) => r.turnedUnasked)} of the same windows never asked`);
console.log(`- the asked way: ${share((r) => r.thatWay)} (to her right ${way(-1)}, to her left ${way(1)}); of her turns after a request, ${Math.round((100 * rows.filter((r) => r.thatWay).length) / Math.max(1, rows.filter((r) => r.turned).length))} % the asked way`);
console.log(`- his hand above ${HAND_RAISED} m: ${share((r) => r.hand > HAND_RAISED)} asked, ${share((r) => r.handUnasked > HAND_RAISED)} unasked`);
console.log(`- every request taken: ${rows.every((r) => r.took)}`);
if (consoleErrors.length) console.log('console errors:', consoleErrors);
if (process.env.DUET_TURN_JSON) writeFileSync(process.env.DUET_TURN_JSON, JSON.stringify(rows));
