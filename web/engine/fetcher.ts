// The page's side of the fetcher worker (fetcher.worker.ts, which downloads onnxruntime's wasm,
// compiling it as it streams in, and the model files): start it, and take what it delivers.

import { DuetError } from '../ui/errors';
import { bootMark } from './boot';
import { type FetchedFile, type FromWorker, type ToWorker, WORKER_NAME } from './protocol';
import workerUrl from './fetcher.worker.ts?worker&url';

interface Deferred<T> {
  promise: Promise<T>;
  resolve: (value: T) => void;
  reject: (error: unknown) => void;
}

function deferred<T>(): Deferred<T> {
  let resolve: (value: T) => void = () => undefined;
  let reject: (error: unknown) => void = () => undefined;
  const promise = new Promise<T>((res, rej) => ((resolve = res), (reject = rej)));
  promise.catch(() => undefined); // reported where it is awaited
  return { promise, resolve, reject };
}

export class Fetcher {
  /** The worker's script (bundled by Vite), for the service worker's list of files to keep. */
  readonly scriptUrl = new URL(workerUrl, location.href);
  /** onnxruntime's wasm, compiled. */
  readonly wasm: Promise<WebAssembly.Module>;
  /** Resolves with the worker's first message: it runs, and its downloads have begun. */
  readonly started: Promise<void>;
  /** Files the worker fetched (its own resource timing), as of its last message with a list (the wasm, a model). */
  files: FetchedFile[] = [];
  /** Every download asked for so far is in (its last byte; the wasm may still be compiling). */
  done = false;

  private readonly worker: Worker;
  private readonly compiled = deferred<WebAssembly.Module>();
  private readonly running = deferred<void>();
  private readonly models = new Map<string, Deferred<Uint8Array>>();
  private readonly asked = new Set<string>();
  private progress: ((loaded: number, total: number, sized: boolean) => void) | null = null;
  private lastProgress: [number, number, boolean] | null = null;

  constructor() {
    this.wasm = this.compiled.promise;
    this.started = this.running.promise;
    // The page's address goes in the worker's name (the one thing a worker has from its first
    // moment; a fragment in its URL would be lost when the service worker answers): with it the
    // worker starts the downloads by itself.
    this.worker = new Worker(this.scriptUrl, { type: 'module', name: `${WORKER_NAME}${location.href}` });
    this.worker.onmessage = (event: MessageEvent<FromWorker>) => this.receive(event.data);
    // The worker's script did not load or threw at its top level.
    this.worker.onerror = (event) => {
      event.preventDefault();
      const error = new DuetError('Could not load onnxruntime', event.message || `${this.scriptUrl.pathname} did not load`);
      this.compiled.reject(error);
      for (const model of this.models.values()) model.reject(error);
      this.running.resolve();
    };
  }

  /** Bytes of the downloads so far and expected, on every whole percent (the latest at once):
   *  compressed, as they travel, once `sized` (download.ts DownloadProgress). */
  set onProgress(listener: (loaded: number, total: number, sized: boolean) => void) {
    this.progress = listener;
    if (this.lastProgress) listener(...this.lastProgress);
  }

  /** A model file's bytes (the worker fetches the first dance's models by itself). */
  model(name: string): Promise<Uint8Array> {
    if (!this.asked.has(name)) {
      this.asked.add(name);
      this.worker.postMessage({ type: 'load', name } satisfies ToWorker);
    }
    return this.entry(name).promise;
  }

  private entry(name: string): Deferred<Uint8Array> {
    let model = this.models.get(name);
    if (!model) {
      model = deferred<Uint8Array>();
      this.models.set(name, model);
    }
    return model;
  }

  private receive(message: FromWorker): void {
    this.running.resolve();
    switch (message.type) {
      case 'progress':
        this.lastProgress = [message.loaded, message.total, message.sized];
        this.done = message.total > 0 && message.loaded >= message.total;
        this.progress?.(message.loaded, message.total, message.sized);
        break;
      case 'mark':
        bootMark(message.stage, message.at - performance.timeOrigin);
        break;
      case 'wasm':
        this.files = message.files;
        this.compiled.resolve(message.module);
        break;
      case 'model':
        this.files = message.files;
        this.entry(message.name).resolve(message.bytes);
        break;
      case 'failed': {
        const error = new DuetError(message.title, message.detail);
        if (message.name === 'wasm') this.compiled.reject(error);
        else this.entry(message.name).reject(error);
        break;
      }
    }
  }
}
