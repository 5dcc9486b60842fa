// onnxruntime's WebAssembly binary, fetched by the page itself rather than by onnxruntime: the
// page starts it before onnxruntime's JavaScript has even arrived, and counts its bytes for the
// progress bar. ort.ts hands the bytes to onnxruntime (env.wasm.wasmBinary).
//
// `onnxruntime-web/wasm` ships only the SIMD + threads build, and it is the smallest of the four
// (14.2 MB; the JSPI one is 16.8 MB, asyncify 26.8 MB, JSEP 28.3 MB): the one to keep.

import wasmUrl from 'onnxruntime-web/ort-wasm-simd-threaded.wasm?url';
import { type DownloadProgress, VERSION_HEADER, readBody } from './download';
import { DuetError } from '../ui/errors';

/** Uncompressed size of the wasm, from vite.config.ts (0 under test runners without it). */
declare const __ORT_WASM_BYTES__: number | undefined;
export const WASM_BYTES = typeof __ORT_WASM_BYTES__ === 'number' ? __ORT_WASM_BYTES__ : 0;
/** Where the build put the wasm (its name carries a content hash). */
export const WASM_URL: string = wasmUrl;

/** Download the wasm, reporting bytes as `progress` part "wasm". */
export async function fetchWasm(progress: DownloadProgress, version = ''): Promise<Uint8Array> {
  progress.expect('wasm', WASM_BYTES);
  try {
    const response = await fetch(WASM_URL, version ? { headers: { [VERSION_HEADER]: version } } : undefined);
    if (!response.ok) throw new Error(`answered ${response.status}`);
    const bytes = await readBody(response, (n) => progress.add('wasm', n), WASM_BYTES);
    progress.finish('wasm');
    return bytes;
  } catch (error) {
    throw new DuetError('Could not load onnxruntime', `${WASM_URL}: ${(error as Error).message}`);
  }
}
