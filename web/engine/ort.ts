// onnxruntime-web, loaded on its own.
//
// Why a dynamic import in a separate module: the WASM build starts its worker threads from the
// script it lives in (import.meta.url). If ORT were bundled into the app's entry chunk, every
// worker would re-run the whole app after `vite build`, and session creation hangs with
// numThreads > 1. A dynamic import gives ORT a chunk of its own. `onnxruntime-web/wasm` is the
// CPU-only build (about 14 MB of wasm, 3.7 MB gzipped) instead of the 28 MB JSEP one.
// Its .wasm is found with `new URL(..., import.meta.url)`, which Vite rewrites into a relative
// asset URL, so it also loads when dist/ is served from a sub-path.

export const ort = await import('onnxruntime-web/wasm');

/**
 * Set the number of WASM threads. Must run before the first InferenceSession is created.
 * Threads need SharedArrayBuffer, which browsers only give to cross-origin-isolated pages
 * (COOP + COEP headers); without isolation we run on one thread rather than fail.
 */
export function configureThreads(requested: number | null, wasmBinary?: Uint8Array): number {
  // The page fetched the wasm itself (wasm.ts), with a progress bar: onnxruntime fetches nothing.
  if (wasmBinary) ort.env.wasm.wasmBinary = wasmBinary;
  const most = globalThis.crossOriginIsolated ? 2 : 1;
  const threads = requested === null ? most : Math.max(1, Math.min(most, Math.round(requested)));
  ort.env.wasm.numThreads = threads;
  // Keep ORT's own warnings (e.g. about unused initializers) out of the console.
  ort.env.logLevel = 'error';
  return threads;
}
