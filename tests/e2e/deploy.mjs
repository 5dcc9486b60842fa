// Two builds deployed in turn at one address, visited by one browser profile: what a returning
// visitor meets after a new version of the site goes up. Shared by tests/e2e/deploy.test.mjs (a
// few trials in `npm test`) and scripts/deploy_trials.mjs (hundreds, with a tally).
//
// The two builds differ as two real deployments do: build B's manifest names other models (one
// fingerprint changed), so its service worker is another version and its page code another hash.
// The server serves whichever build the `current` link points at; a trial flips the link and
// visits again, and the visit must dance: the page of the build that is up, with that build's
// manifest (never a mix), within `readyMs`.

import { cpSync, mkdirSync, readFileSync, rmSync, symlinkSync, renameSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { build as viteBuild } from 'vite';
import { serve } from '../../scripts/serve.mjs';
import { BUILT, ROOT, WAIT_MS, sleep } from './harness.mjs';

/** Build the site into `outDir`, with public/ replaced by `publicDir` when given. */
async function buildInto(outDir, publicDir) {
  await viteBuild({
    root: ROOT,
    configFile: join(ROOT, 'vite.config.ts'),
    logLevel: 'warn',
    ...(publicDir ? { publicDir } : {}),
    build: { outDir, emptyOutDir: true },
  });
}

/**
 * Build A (the site as it is) and B (the same with another follower fingerprint in its manifest)
 * under `dir`; returns { url, deploy(name), up(), stop() } with a server on `current`.
 */
export async function twoBuilds(dir) {
  rmSync(dir, { recursive: true, force: true });
  mkdirSync(dir, { recursive: true });
  const a = join(dir, 'a'), b = join(dir, 'b'), publicB = join(dir, 'public-b');
  // Build A is the site as it is: a copy of the one scripts/test.sh made for all the files, if any.
  if (BUILT) cpSync(BUILT, a, { recursive: true });
  else await buildInto(a);
  cpSync(join(ROOT, 'public'), publicB, { recursive: true });
  const manifestPath = join(publicB, 'models', 'manifest.json');
  const manifest = JSON.parse(readFileSync(manifestPath, 'utf8'));
  const entry = manifest.models.follower;
  entry.fingerprint = entry.fingerprint.split('').reverse().join('');
  writeFileSync(manifestPath, `${JSON.stringify(manifest, null, 1)}\n`);
  await buildInto(b, publicB);
  const current = join(dir, 'current');
  // Flipping a symbolic link is what a deploy by `ln -sfn` does: atomic, and the server reads
  // every file through it (scripts/serve.mjs resolves paths per request).
  let up = 'a';
  const deploy = (name) => {
    up = name;
    const next = join(dir, 'current.next');
    rmSync(next, { force: true });
    symlinkSync(name === 'a' ? a : b, next);
    renameSync(next, current);
  };
  deploy('a');
  const server = await serve({ dir: current, base: '/duet/' });
  return { url: server.url, deploy, up: () => up, stop: () => server.stop() };
}

/** Wait until this origin's service worker has stored the wasm and the first two models of `version`:
 * up to DUET_WAIT_MS, as every wait (on a busy 2-core machine 30 s were once not enough). */
export async function waitCached(page, version, timeoutMs = WAIT_MS) {
  const deadline = Date.now() + timeoutMs;
  for (;;) {
    const held = await page.evaluate(async (name) => {
      if (!(await caches.has(name))) return [];
      return (await (await caches.open(name)).keys()).map((r) => r.url);
    }, `duet-${version}`).catch(() => []);
    if (held.some((u) => u.endsWith('.wasm')) && held.filter((u) => u.endsWith('.onnx')).length >= 2) return true;
    if (Date.now() > deadline) return false;
    await sleep(200);
  }
}

/**
 * One visit after a deploy: go to `url`, wait for the first dancing step. Returns
 * { outcome: 'danced' | 'error' | 'hang', ms, error, version, models, build, recovered, stage }:
 * 'hang' is no step and no message within readyMs (what the watchdog must never let happen).
 */
export async function visit(page, url, readyMs = 45_000) {
  const started = Date.now();
  let outcome = 'danced';
  try {
    // A service worker that hangs can keep the navigation itself from ever committing.
    await page.goto(url, { waitUntil: 'commit', timeout: readyMs });
    // A watchdog's reload replaces the page: wait across navigations.
    for (;;) {
      const state = await page.evaluate(() => (window.duet ? { ready: window.duet.ready, error: window.duet.error } : null)).catch(() => null);
      if (state?.error) { outcome = 'error'; break; }
      if (state?.ready) break;
      if (Date.now() - started > readyMs) { outcome = 'hang'; break; }
      await sleep(50);
    }
  } catch {
    outcome = 'hang';
  }
  // A page whose service worker hangs can leave any call into it hanging too: 5 s at most.
  const within = (promise, ms) => Promise.race([promise, sleep(ms).then(() => ({}))]);
  const info = await within(page.evaluate(async () => ({
    error: window.duet?.error ?? null,
    // A page that does not publish its version: the newest service worker's (?v= of its script).
    version: window.duet?.version ?? (await navigator.serviceWorker.getRegistration().then((r) => {
      const worker = r?.installing ?? r?.waiting ?? r?.active;
      return worker ? new URL(worker.scriptURL).searchParams.get('v') : null;
    })),
    models: window.duet?.modelsVersion ?? null,
    build: window.duet?.buildVersion ?? null,
    recovered: window.duet?.recovered ?? 0,
    stages: Object.keys(window.duet?.bootTimings ?? {}),
    modelBytes: window.duet?.modelBytes ?? 0,
  })).catch(() => ({})), 5000);
  return { outcome, ms: Date.now() - started, ...info, stage: info.stages?.at(-1) ?? null };
}
