// The page's own duets, nobody steering and nobody asking: for each seed the page dances
// DUET_FIG_SECONDS (default 30) of dance (recorded from the step the probe is armed at, within the
// first LATE_S seconds of dance: the page starts dancing as soon as it is ready), and every step's
// joints of both dancers, as the page draws them (after the contact layer), are written to a JSON
// file that `python -m training.evaluation.page_figures FILE` measures against the recording with
// figures.py (turns a minute, spin frames, body motion, travel, the leader's largest distance from
// his spot, the floor's origin where the page starts him): the same measures as
// training.evaluation.lead's "Dancing unasked", for the page.
//
// Run: node scripts/figures_probe.mjs [seeds, default 1-10] (dev server, headless Chromium,
// 1280×800). Environment: DUET_FIG_JSON=path (default runs/figures_probe.json),
// DUET_FIG_SECONDS, DUET_FIG_SPEED=1..4 (default 4: the steps, and so the dance, are the same at
// any speed; only the wall time differs). The page is reached through tests/e2e/turns.mjs.

import { mkdirSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { ROOT, launch, startServer, waitReady } from '../tests/e2e/harness.mjs';
import { FPS, Reloaded, armProbe, readProbe } from '../tests/e2e/turns.mjs';

const SEEDS = (process.argv[2] ?? '1,2,3,4,5,6,7,8,9,10').split(',').map(Number);
const SECONDS = Number(process.env.DUET_FIG_SECONDS ?? 30);
const SPEED = Number(process.env.DUET_FIG_SPEED ?? 4);
const OUT = process.env.DUET_FIG_JSON ?? join(ROOT, 'runs', 'figures_probe.json');
const STEPS = Math.round(SECONDS * FPS);
const LATE_S = 10;
const READY_MS = 300_000;

if (SEEDS.some((s) => !Number.isInteger(s) || s < 0)) throw new Error(`seeds must be whole numbers ≥ 0, got ${process.argv[2]}`);
if (!(SECONDS >= 5)) throw new Error(`DUET_FIG_SECONDS must be at least 5 (a turn is counted over 2.5 s), got ${process.env.DUET_FIG_SECONDS}`);

const server = await startServer({ mode: 'dev' });
const browser = await launch({ viewport: { width: 1280, height: 800 } });
const { page, consoleErrors } = browser;
page.setDefaultTimeout(READY_MS);

/** One seed's dance: the steps from the page's first to STEPS (run again if the page reloaded). */
async function dance(seed) {
  for (let attempt = 1; ; attempt++) {
    try {
      await page.goto(`${server.url}?seed=${seed}&speed=${SPEED}`);
      await waitReady(page, READY_MS);
      await armProbe(page, { askAt: -1, direction: 0, until: STEPS + LATE_S * FPS });
      const probe = await readProbe(page, READY_MS);
      const first = probe.steps[0]?.frame;
      if (!(first <= LATE_S * FPS)) throw new Error(`seed ${seed}: the recording began at step ${first}, after ${LATE_S} s of dance`);
      const steps = probe.steps.filter((s) => s.frame < first + STEPS);
      if (steps.some((s) => s.steerActive || s.turnAsked !== 0)) throw new Error(`seed ${seed}: someone steered or asked`);
      return steps;
    } catch (error) {
      if (!(error instanceof Reloaded) || attempt >= 3) throw error;
      console.log(`seed ${seed}: the page reloaded (someone edited it); again`);
    }
  }
}

const seeds = [];
try {
  // Warm the dev server (first compile) so the measured pages do not reload.
  await page.goto(`${server.url}?seed=${SEEDS[0]}`).catch(() => undefined);
  await waitReady(page, READY_MS).catch(() => undefined);
  for (const [i, seed] of SEEDS.entries()) {
    const started = Date.now();
    const steps = await dance(seed);
    // start: where the page put the leader at its first step, his spot (simulation.ts starts him at the
    // floor's origin, and nobody steering he stays free within ANCHOR_FREE of it).
    // beat: the count each step danced on, for the rhythm (page_figures reads it as rhythm.py does
    // duet.soak_one's record); leaderOwn / followerOwn: the networks' bodies beside the drawn ones.
    seeds.push({
      seed, first: steps[0].frame, start: [0, 0], tempo: steps[0].tempo, beat: steps.map((s) => s.beat),
      leader: steps.map((s) => s.leader), follower: steps.map((s) => s.follower),
      leaderOwn: steps.map((s) => s.leaderOwn), followerOwn: steps.map((s) => s.followerOwn),
    });
    console.log(`seed ${seed}: ${steps.length} steps (${((Date.now() - started) / 1000).toFixed(1)} s) [${i + 1}/${SEEDS.length}]`);
  }
} finally {
  await browser.close();
  await server.stop();
}
if (consoleErrors.length) console.log(`console errors: ${consoleErrors.join(' | ')}`);
mkdirSync(dirname(OUT), { recursive: true });
writeFileSync(OUT, JSON.stringify({ fps: FPS, seconds: SECONDS, speed: SPEED, shown: 'after the contact layer', seeds }));
console.log(`wrote ${OUT}: ${seeds.length} seeds × ${SECONDS} s; measure it with python -m training.evaluation.page_figures ${OUT}`);
