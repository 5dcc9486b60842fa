// The messages between the page (fetcher.ts) and the fetcher worker (fetcher.worker.ts).

/** The worker's name: this prefix, then the page's address (models/ is relative to it, and its
 *  query has the settings), so that the worker can start without waiting for a message. */
export const WORKER_NAME = 'duet-fetcher ';

export type ToWorker =
  /** Download a model (answered with 'model' or 'failed'). The worker downloads the first
   *  dance's models by itself. */
  { type: 'load'; name: string };

/** A file the worker fetched, from its own resource timing (the page's does not list it); times
 *  in ms since the epoch (timeOrigin + startTime...). */
export interface FetchedFile {
  url: string;
  transferSize: number;
  encodedBodySize: number;
  start: number;
  firstByte: number;
  end: number;
}

export type FromWorker =
  /** Bytes of all downloads so far and expected (the loading bar): as they travel (compressed)
   *  once `sized`, decoded before (download.ts DownloadProgress). */
  | { type: 'progress'; loaded: number; total: number; sized: boolean }
  /** A boot stage (boot.ts) reached in the worker; `at`: ms since the epoch (timeOrigin + now). */
  | { type: 'mark'; stage: string; at: number }
  /** onnxruntime's wasm, compiled, and what the worker fetched so far. */
  | { type: 'wasm'; module: WebAssembly.Module; files: FetchedFile[] }
  /** A model file's bytes (checked against the manifest), and what the worker fetched so far. */
  | { type: 'model'; name: string; bytes: Uint8Array; files: FetchedFile[] }
  /** The wasm (`name` 'wasm') or a model could not be loaded: a DuetError's title and detail. */
  | { type: 'failed'; name: string; title: string; detail: string };
