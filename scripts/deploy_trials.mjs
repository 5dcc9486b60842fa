// Two builds deployed in turn at one address, one browser profile visiting after each deploy
// (tests/e2e/deploy.mjs): counts the visits that danced, failed with a message, or hung, on one
// WASM thread and on two by turns.
//
//   node scripts/deploy_trials.mjs [--trials 100] [--dir /tmp/duet-deploy] [--ready-ms 45000]
//
// Each trial flips the deployed build and visits; before the next one the service worker must
// hold the new version's wasm and models, as a visitor's browser would after a visit. Prints one
// line per trial and a tally; exits 1 when any visit did not dance.

import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { launch } from '../tests/e2e/harness.mjs';
import { twoBuilds, visit, waitCached } from '../tests/e2e/deploy.mjs';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(`--${name}`);
  return i >= 0 ? args[i + 1] : fallback;
};
const trials = Number(option('trials', 100));
const readyMs = Number(option('ready-ms', 45_000));
if (!Number.isInteger(trials) || trials < 1) throw new Error(`--trials must be a positive whole number, got ${option('trials')}`);

const site = await twoBuilds(option('dir', join(tmpdir(), 'duet-deploy')));
const browser = await launch();
const tally = { danced: 0, error: 0, hang: 0, recovered: 0, mixed: 0, uncached: 0 };
const times = [];
try {
  // The visitor's first visit, until the worker has cached everything.
  let page = browser.page;
  const first = await visit(page, `${site.url}?seed=1`, readyMs);
  if (first.outcome !== 'danced' || !(await waitCached(page, first.version))) throw new Error(`the first visit did not dance and cache: ${JSON.stringify(first)}`);
  let up = 'a';
  for (let i = 1; i <= trials; i++) {
    up = up === 'a' ? 'b' : 'a';
    site.deploy(up);
    const threads = i % 2 ? '&threads=1' : '';
    const result = await visit(page, `${site.url}?seed=${i}${threads}`, readyMs);
    tally[result.outcome]++;
    if (result.recovered) tally.recovered++;
    // The page's build and the manifest it danced with are one version.
    const mixed = result.outcome === 'danced' && result.build !== null && result.build !== result.models;
    if (mixed) tally.mixed++;
    if (result.outcome === 'hang') {
      // What the visitor would do: close the tab and open the page again (same profile).
      await Promise.race([page.close().catch(() => undefined), new Promise((done) => setTimeout(done, 5000))]);
      page = await browser.context.newPage();
    }
    let cached = true;
    if (result.outcome === 'danced') {
      times.push(result.ms);
      cached = await waitCached(page, result.version);
      if (!cached) tally.uncached++;
    }
    console.log(`${new Date().toISOString().slice(11, 19)} trial ${i}/${trials}: build ${up}, ${threads ? '1 thread' : '2 threads'}: ${result.outcome} in ${(result.ms / 1000).toFixed(2)} s` +
      `${result.recovered ? `, watchdog restarted ${result.recovered}x` : ''}${mixed ? `, MIXED page ${result.build} models ${result.models}` : ''}` +
      `${cached ? '' : ', the worker did not cache it'}${result.outcome !== 'danced' ? ` (last stage ${result.stage}, error ${result.error})` : ''}`);
  }
} finally {
  await browser.close();
  await site.stop();
}
times.sort((x, y) => x - y);
const at = (q) => (times.length ? (times[Math.min(times.length - 1, Math.floor(q * times.length))] / 1000).toFixed(2) : '-');
console.log(`\n${trials} visits after a deploy: ${tally.danced} danced, ${tally.error} with a message, ${tally.hang} hung; ` +
  `${tally.recovered} needed the watchdog; ${tally.mixed} mixed versions; ${tally.uncached} not cached after; ` +
  `time to the first step median ${at(0.5)} s, p95 ${at(0.95)} s, max ${at(1)} s`);
process.exit(tally.danced === trials && tally.mixed === 0 ? 0 : 1);
