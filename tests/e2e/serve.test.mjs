// scripts/serve.mjs without a browser: it sends a precompressed copy only while that copy is as
// new as the file beside it, and the MIME types module scripts and wasm need.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync, utimesSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { brotliCompressSync } from 'node:zlib';
import { serve } from '../../scripts/serve.mjs';

test('a .br copy older than its file is not sent; a fresh one is', async () => {
  const dir = mkdtempSync(join(tmpdir(), 'duet-serve-'));
  const server = await serve({ dir });
  try {
    const file = join(dir, 'app.mjs');
    writeFileSync(`${file}.br`, brotliCompressSync('export const version = 1;'));
    writeFileSync(file, 'export const version = 2;');
    const past = new Date(Date.now() - 60_000);
    utimesSync(`${file}.br`, past, past); // compressed a minute before the file was rebuilt
    const get = () => fetch(`${server.url}app.mjs`, { headers: { 'accept-encoding': 'br' } });
    // Node's fetch decodes brotli itself: the body is the text either way.
    let response = await get();
    assert.equal(response.headers.get('content-encoding'), null, 'the stale copy is not used');
    assert.equal(await response.text(), 'export const version = 2;');
    assert.match(response.headers.get('content-type'), /^text\/javascript/);

    writeFileSync(`${file}.br`, brotliCompressSync('export const version = 2;'));
    const future = new Date(Date.now() + 60_000);
    utimesSync(`${file}.br`, future, future);
    response = await get();
    assert.equal(response.headers.get('content-encoding'), 'br', 'a fresh copy is sent compressed');
    assert.equal(await response.text(), 'export const version = 2;');
  } finally {
    await server.stop();
    rmSync(dir, { recursive: true, force: true });
  }
});
