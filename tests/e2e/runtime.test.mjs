// The page's onnxruntime-web (WebAssembly, one version) computes what Python's onnxruntime (native,
// another version) computed for the evaluation tables, on the shipped models: the same codes and
// the same poses and intentions. tests/fixtures/runtime.json holds the inputs and Python's outputs
// (tests/python/fixtures_writer.py); the page makes its sessions as it does for dancing
// (web/engine/policy.ts, SESSION_OPTIONS), on one thread and on two.

import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { QUICK, ROOT, launch, startServer, waitReady } from './harness.mjs';

const fixture = JSON.parse(readFileSync(join(ROOT, 'tests', 'fixtures', 'runtime.json'), 'utf8'));
const manifest = JSON.parse(readFileSync(join(ROOT, 'public', 'models', 'manifest.json'), 'utf8'));

let server;
let browser;

before(async () => {
  server = await startServer({ mode: 'dev' });
  browser = await launch(QUICK);
});

after(async () => {
  await browser?.close();
  await server?.stop();
});

test('the fixture was written from the shipped models', () => {
  assert.deepEqual(Object.keys(fixture.models).sort(), Object.keys(manifest.models).sort());
  for (const [name, model] of Object.entries(fixture.models)) {
    assert.equal(model.fingerprint, manifest.models[name].fingerprint,
      `${name}: tests/fixtures/runtime.json is from other models; rerun .venv/bin/python tests/python/fixtures_writer.py`);
  }
});

for (const threads of [1, 2]) {
  test(`the browser's outputs are Python's, on ${threads} thread${threads > 1 ? 's' : ''}`, async () => {
    const { page } = browser;
    await page.goto(`${server.url}?seed=1&threads=${threads}`);
    await waitReady(page);
    const results = await page.evaluate(async (fixture) => {
      const { ort } = await import('/web/engine/ort.ts');
      const { SESSION_OPTIONS } = await import('/web/engine/policy.ts');
      const out = { threads: ort.env.wasm.numThreads, models: {} };
      for (const [name, model] of Object.entries(fixture.models)) {
        const bytes = new Uint8Array(await (await fetch(`models/${name}.onnx`)).arrayBuffer());
        const session = await ort.InferenceSession.create(bytes, SESSION_OPTIONS);
        const b = model.batch;
        const outputs = await session.run({
          input: new ort.Tensor('float32', Float32Array.from(model.input), [b, model.input.length / b]),
          temperature: new ort.Tensor('float32', Float32Array.from([fixture.temperature]), [1]),
          noise: new ort.Tensor('float32', Float32Array.from(model.noise), [b, model.noise.length / b]),
        });
        out.models[name] = Object.fromEntries(Object.entries(outputs).map(([k, t]) => [k, Array.from(t.data, Number)]));
        await session.release();
      }
      return out;
    }, fixture);
    assert.equal(results.threads, threads, 'the page set the thread count asked for');
    for (const [name, model] of Object.entries(fixture.models)) {
      for (const [output, expected] of Object.entries(model.outputs)) {
        const got = results.models[name][output];
        assert.ok(got, `${name}: no output "${output}"`);
        assert.equal(got.length, expected.length, `${name}.${output}: length`);
        if (output === 'code') {
          assert.deepEqual(got, expected, `${name}: the sampled codes differ`);
          continue;
        }
        // Measured: the followers' outputs and every intention agree to the fixture's 7 digits; the
        // leader's pose differs by up to 1.8e-3 in one of the two samples (299 of 646 numbers, codes
        // equal), the same with onnxruntime-web 1.30: the WebAssembly build against the native
        // one, not the version. A different code would move a pose by tenths.
        let worst = 0;
        for (let i = 0; i < got.length; i++) worst = Math.max(worst, Math.abs(got[i] - expected[i]) / Math.max(1, Math.abs(expected[i])));
        assert.ok(worst < 5e-3, `${name}.${output}: differs from Python by up to ${worst.toExponential(2)}`);
      }
    }
  });
}
