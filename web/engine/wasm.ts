// onnxruntime's WebAssembly, fetched and compiled by the fetcher worker (fetcher.worker.ts)
// rather than by onnxruntime: the worker starts it before onnxruntime's JavaScript has even
// arrived, compiles it while it downloads (WebAssembly.compileStreaming: the compiler runs on
// background threads as the bytes come in, so on a slow network the module is ready moments
// after its last byte), and counts its bytes for the progress bar. ort.ts hands the compiled
// module to onnxruntime.
//
// `onnxruntime-web/wasm` ships only the SIMD + threads build (11.2 MB; the JSEP one is 21.9 MB).
// onnxruntime-web is held at 1.22: its wasm is 1.80 MB brotli against 2.30 MB for 1.30's (14.2 MB),
// which on the phone profile's 9 Mbit/s link brought the first dancing frame 0.6-1.4 s sooner in
// six alternating pairs, at the same step time (docs/measurements.md, "onnxruntime-web 1.22"). Its JavaScript loads the
// Emscripten loader (GLUE_URL) as a file of its own; 1.30's carries it inside. Both files are
// imported by path (vite.config.ts: onnxruntime-web-dist): the package's export map lists neither.

import wasmUrl from 'onnxruntime-web-dist/ort-wasm-simd-threaded.wasm?url';
import glueUrl from 'onnxruntime-web-dist/ort-wasm-simd-threaded.mjs?url';
import { type DownloadProgress, VERSION_HEADER, countBody, readBody, wireSize } from './download';
import { DuetError } from '../ui/errors';
import type { DownloadSlots } from './slots';

/** Uncompressed size of the wasm, from vite.config.ts (0 under test runners without it). */
declare const __ORT_WASM_BYTES__: number | undefined;
export const WASM_BYTES = typeof __ORT_WASM_BYTES__ === 'number' ? __ORT_WASM_BYTES__ : 0;
/** Where the build put the wasm (its name carries a content hash). */
export const WASM_URL: string = wasmUrl;
/** Where the build put onnxruntime's Emscripten loader (ort.ts hands it to onnxruntime; its worker
 *  threads start from it too). */
export const GLUE_URL: string = glueUrl;

/** The wasm on its way: `received` once its last byte is in, `module` once it is compiled. */
export interface WasmDownload {
  received: Promise<void>;
  module: Promise<WebAssembly.Module>;
}

/**
 * Download and compile the wasm, reporting bytes as `progress` part "wasm", in a slot of `slots`.
 *
 * The response itself goes to compileStreaming (a response straight from fetch, so Chromium can
 * also keep the compiled code with it); a clone is read only to count bytes. A host that serves
 * .wasm with another MIME type than application/wasm would make compileStreaming refuse: then the
 * bytes are read and compiled in one piece.
 */
export function loadWasm(progress: DownloadProgress, slots: DownloadSlots, version = ''): WasmDownload {
  progress.expect('wasm', WASM_BYTES);
  const fail = (error: unknown) => {
    throw new DuetError('Could not load onnxruntime', `${WASM_URL}: ${(error as Error).message}`);
  };
  // An object, not the promise itself: the download is over when the bytes are in, while the
  // compilation may still be going.
  const download = slots.run(WASM_BYTES, async (): Promise<{ compiled: Promise<WebAssembly.Module> }> => {
    const response = await fetch(WASM_URL, version ? { headers: { [VERSION_HEADER]: version } } : undefined);
    if (!response.ok) throw new Error(`answered ${response.status}`);
    progress.wire('wasm', wireSize(response, WASM_BYTES));
    if (typeof WebAssembly.compileStreaming === 'function' && /^application\/wasm\b/.test(response.headers.get('content-type') ?? '')) {
      const copy = response.clone();
      const compiled = WebAssembly.compileStreaming(response);
      compiled.catch(() => undefined); // reported through `module`
      await countBody(copy, (n) => progress.add('wasm', n));
      progress.finish('wasm');
      return { compiled };
    }
    const bytes = await readBody(response, (n) => progress.add('wasm', n), WASM_BYTES);
    progress.finish('wasm');
    return { compiled: WebAssembly.compile(bytes) };
  });
  return {
    received: download.then(() => undefined, () => undefined), // a failure is reported through `module`
    module: download.then(({ compiled }) => compiled).catch(fail),
  };
}
