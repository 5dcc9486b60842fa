// onnxruntime-web, loaded on its own.
//
// Why a dynamic import in a separate module: the loading scene does not need onnxruntime's
// JavaScript, so it comes in a chunk of its own while the floor is drawn. Its WASM threads start
// from the script the Emscripten loader lives in (import.meta.url): in 1.22 that is the loader's
// own file (wasm.ts, GLUE_URL). When the loader sat inside the app's entry chunk (1.30 bundled
// into it), every worker re-ran the whole app after `vite build` and session creation hung with
// numThreads > 1. `onnxruntime-web/wasm` is the CPU-only build (11.2 MB of wasm, 1.80 MB brotli)
// instead of the 21.9 MB JSEP one.

import * as ort from 'onnxruntime-web/wasm';
import { bootMark } from './boot';
import { GLUE_URL, WASM_URL } from './wasm';

// A static import, so that the page's import() of this module fetches onnxruntime's chunk with it
// (Vite preloads a dynamic import's dependencies side by side), at main.ts's start, before the
// wasm and the models fill the link. Imported inside this module (as it was), it was asked for
// only once this module ran, 1.9-4.3 s into a first visit on the phone profile (four visits), behind them.
bootMark('ort:imported');
export { ort };

/**
 * The smallest valid wasm binary (magic number and version, no sections). onnxruntime is given
 * this as its `wasmBinary`, so that it fetches nothing itself; useCompiledModule() recognises it
 * when onnxruntime instantiates it and instantiates the page's compiled module instead.
 */
const PLACEHOLDER = new Uint8Array([0x00, 0x61, 0x73, 0x6d, 0x01, 0x00, 0x00, 0x00]);

function isPlaceholder(source: unknown): boolean {
  const bytes = source instanceof ArrayBuffer ? new Uint8Array(source) : ArrayBuffer.isView(source) ? new Uint8Array(source.buffer, source.byteOffset, source.byteLength) : null;
  return bytes !== null && bytes.length === PLACEHOLDER.length && PLACEHOLDER.every((b, i) => bytes[i] === b);
}

/**
 * Make onnxruntime use `module`, compiled by the page while it downloaded (wasm.ts), instead of
 * compiling the 11 MB binary a second time. onnxruntime-web has no option for a compiled module:
 * its loader (Emscripten) calls WebAssembly.instantiate(wasmBinary, imports) once, on this thread,
 * when the first session is created. That one call, recognised by the placeholder binary, is
 * answered with an instance of `module` (which is also the module Emscripten sends to its worker
 * threads); every other call goes straight to the browser's WebAssembly.instantiate, and the
 * original function is put back after the call.
 */
function useCompiledModule(module: WebAssembly.Module): void {
  const instantiate = WebAssembly.instantiate;
  const handOver = function (this: unknown, ...args: Parameters<typeof instantiate>) {
    if (!isPlaceholder(args[0])) return (instantiate as (...a: unknown[]) => unknown).apply(this, args);
    WebAssembly.instantiate = instantiate;
    return instantiate(module, args[1]).then((instance) => ({ module, instance }));
  };
  WebAssembly.instantiate = handOver as typeof WebAssembly.instantiate;
  ort.env.wasm.wasmBinary = PLACEHOLDER;
}

/**
 * Set the number of WASM threads and hand onnxruntime its compiled module. Must run before the
 * first InferenceSession is created. Threads need SharedArrayBuffer, which browsers only give to
 * cross-origin-isolated pages (COOP + COEP headers); without isolation we run on one thread
 * rather than fail.
 */
export function configureThreads(requested: number | null, module?: WebAssembly.Module): number {
  // The page fetched and compiled the wasm itself (wasm.ts), with a progress bar.
  if (module) useCompiledModule(module);
  // onnxruntime 1.22 imports its Emscripten loader from a file of its own, by default from beside
  // its own chunk under the package's file name; the build hashed that name (wasm.ts). The wasm's
  // address too, for a page that did not hand over a compiled module.
  ort.env.wasm.wasmPaths = { mjs: new URL(GLUE_URL, location.href).href, wasm: new URL(WASM_URL, location.href).href };
  const most = globalThis.crossOriginIsolated ? 2 : 1;
  const threads = requested === null ? most : Math.max(1, Math.min(most, Math.round(requested)));
  ort.env.wasm.numThreads = threads;
  // Keep ORT's own warnings (e.g. about unused initializers) out of the console.
  ort.env.logLevel = 'error';
  return threads;
}

/**
 * Why onnxruntime could not start, where its host tells: the Emscripten loader (a module script)
 * served with a type that is not JavaScript, which browsers refuse to run. Without this the
 * failure reads as a corrupt model (policy.ts). Null when the type is right or cannot be read.
 */
export async function loaderTypeProblem(): Promise<string | null> {
  try {
    const url = new URL(GLUE_URL, location.href);
    const response = await fetch(url, { method: 'HEAD' });
    const type = response.headers.get('content-type') ?? '';
    if (!response.ok || /javascript|ecmascript/i.test(type)) return null;
    return `${url.pathname} comes as "${type || 'no type'}", and browsers run a module script only when it comes as JavaScript: the host must serve .mjs files as text/javascript.`;
  } catch {
    return null;
  }
}
