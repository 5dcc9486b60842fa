// The shipped networks alone, in Node's onnxruntime-web (the page's WebAssembly build, one thread):
// the median time of one run of each model, and of a step's two runs (his, then hers), for each
// number of samples drawn at once, with nothing else running in the process. Beside `npm run bench`
// (whose "networks" line is the same runs inside the dancing page) it tells how much of a step the
// networks need and how much the page around them costs them.
//
//   node scripts/bench_networks.mjs                 # samples 1 and 8 (a plain step, the choice on the count)
//   node scripts/bench_networks.mjs --samples 1,4,8,16 --runs 400 --models public/models
//
// Timings on a 2-core machine vary by about ±10 % between runs: compare within one run.

import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import * as ort from 'onnxruntime-web/wasm';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(`--${name}`);
  return i >= 0 ? args[i + 1] : fallback;
};
const dir = option('models', 'public/models');
const samples = option('samples', '1,8').split(',').map(Number);
const runs = Number(option('runs', 300));
if (!samples.every((k) => Number.isInteger(k) && k >= 1) || !(runs >= 10)) {
  console.error('usage: node scripts/bench_networks.mjs [--samples 1,8] [--runs N (>= 10)] [--models DIR]');
  process.exit(2);
}

let manifest;
try {
  manifest = JSON.parse(readFileSync(join(dir, 'manifest.json'), 'utf8'));
} catch (error) {
  console.error(`error: ${join(dir, 'manifest.json')}: ${error.message}`);
  process.exit(2);
}
// The input width of each role, from the manifest's layout (the blocks the page writes).
const width = (blocks) => blocks.reduce((sum, [, n]) => sum + n, 0);
const widths = { leader: width(manifest.layout.leaderInput), follower: width(manifest.layout.followerInput) };

ort.env.wasm.numThreads = 1;
ort.env.logLevel = 'error';
const median = (a) => a.sort((x, y) => x - y)[a.length >> 1];

// Between two steps the page draws, plays sound and builds features: by the next step the networks'
// weights (4 MB of int8) are no longer in the CPU's caches. A walk over CACHE_SWEEP bytes between two
// steps does the same here ("caches swept"); back to back, the weights stay in the caches.
const CACHE_SWEEP = 64 << 20;
const sweep = new Float64Array(CACHE_SWEEP / 8);
const sweepCaches = () => {
  for (let i = 0; i < sweep.length; i += 8) sweep[i] += 1; // one touch per 64-byte line
};

const models = {};
for (const name of ['follower', 'leader']) {
  const entry = manifest.models[name];
  const session = await ort.InferenceSession.create(readFileSync(join(dir, entry.file)), { executionProviders: ['wasm'], graphOptimizationLevel: 'all' });
  models[name] = { entry, session, width: widths[entry.role] ?? widths.follower };
}

/** The feeds and fetches of one run of `name` drawing k samples: a neutral input (the normalized
 *  mean) and uniform noise, as the page's runs get. */
function runOf(name, k) {
  const { entry, session, width } = models[name];
  const noise = entry.channels * entry.classes;
  const feeds = {
    input: new ort.Tensor('float32', new Float32Array(width), [1, width]),
    temperature: new ort.Tensor('float32', new Float32Array([manifest.defaultTemperature]), [1]),
    noise: new ort.Tensor('float32', new Float32Array(k * noise).map(() => Math.random()), [k, noise]),
  };
  const fetches = entry.intention ? ['output', 'intention'] : ['output'];
  return async () => {
    const outputs = await session.run(feeds, fetches);
    for (const tensor of Object.values(outputs)) tensor.dispose();
  };
}

/** Median ms of `body` over `runs` calls (after 30 to let onnxruntime plan its buffers), the caches
 *  swept before each call when `swept`. */
async function time(body, swept) {
  for (let i = 0; i < 30; i++) await body();
  const times = [];
  for (let i = 0; i < runs; i++) {
    if (swept) sweepCaches();
    const started = performance.now();
    await body();
    times.push(performance.now() - started);
  }
  return median(times);
}

console.log(`the networks alone (Node ${process.versions.node}, onnxruntime-web ${ort.env.versions.web}, 1 thread), median of ${runs} runs, ms:`);
console.log(`  ${'samples'.padEnd(8)} ${'follower'.padStart(9)} ${'leader'.padStart(9)} ${'a step (both)'.padStart(14)} ${'... caches swept'.padStart(17)}`);
for (const k of samples) {
  const follower = runOf('follower', k);
  const leader = runOf('leader', k);
  const step = async () => {
    await leader();
    await follower();
  };
  const cells = [await time(follower, false), await time(leader, false), await time(step, false), await time(step, true)];
  console.log(`  ${String(k).padEnd(8)} ${cells[0].toFixed(3).padStart(9)} ${cells[1].toFixed(3).padStart(9)} ${cells[2].toFixed(3).padStart(14)} ${cells[3].toFixed(3).padStart(17)}`);
}
