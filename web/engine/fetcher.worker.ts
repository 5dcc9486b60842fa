// The fetcher worker: onnxruntime's wasm (compiled as it streams in) and the model files,
// downloaded away from the page's main thread. Why: the page's thread is busy building and
// drawing the scene while the models load, and while a long task runs there (building the scene,
// compiling shaders, onnxruntime creating a session: 0.5-2 s each at the phone bench's 4x CPU)
// nothing on that thread reads the downloads' bytes, so they stall. Here they are read as they
// come in, and the wasm's compiler is fed without waiting for the page. The compiled module and
// the files' bytes go to the page (fetcher.ts), where onnxruntime runs.
//
// The worker starts on its own, without waiting for a message: the page's address comes in the
// worker's name (fetcher.ts), and the worker fetches the wasm, the manifest and the first dance's
// models (firstdance.ts) from its first moment. (Messages the page posts while a worker is still
// starting only arrive once the page's thread is free again.)

import { DuetError } from '../ui/errors';
import { bootMark, bootSpan, onBootMark } from './boot';
import { DownloadProgress } from './download';
import { firstDanceModels } from './firstdance';
import { fetchModelBytes, loadManifest } from './manifest';
import { assetVersion, otherDeployment } from './offline';
import { type FetchedFile, type FromWorker, type ToWorker, WORKER_NAME } from './protocol';
import { DownloadSlots } from './slots';
import { loadWasm } from './wasm';

const post = (message: FromWorker, transfer: Transferable[] = []) => self.postMessage(message, { transfer });

// Stages are recorded against this worker's clock; the page converts them to its own.
onBootMark((stage, at) => post({ type: 'mark', stage, at: performance.timeOrigin + at }));
bootMark('worker');

/** The page's address: models/ and the manifest are relative to it, and its query has the settings. */
const page = new URL(self.name.startsWith(WORKER_NAME) ? self.name.slice(WORKER_NAME.length) : location.href);

function failure(name: string, error: unknown): FromWorker {
  if (error instanceof DuetError) return { type: 'failed', name, title: error.title, detail: error.detail };
  return { type: 'failed', name, title: 'Something went wrong', detail: String((error as Error)?.message ?? error) };
}

/** The loading bar moves in whole percents: one message per percent is enough. */
let shownPercent = -1;
let shownSized = false;
const progress = new DownloadProgress((loaded, total, sized) => {
  const percent = total > 0 ? Math.floor((100 * loaded) / total) : 0;
  if (percent === shownPercent && sized === shownSized && loaded < total) return;
  shownPercent = percent;
  shownSized = sized;
  post({ type: 'progress', loaded, total, sized });
});
const slots = new DownloadSlots();

const wasm = loadWasm(progress, slots);
bootSpan('download:wasm', () => wasm.received);
bootSpan('compile:wasm', () => wasm.module).then(
  // The files so far go with it too: a model that arrived before the wasm had finished could not
  // name it, and the page keeps the last list it was sent (fetcher.ts).
  (module) => post({ type: 'wasm', module, files: fetchedFiles() }),
  (error) => post(failure('wasm', error)),
);

// The page shows its own error if the manifest is missing or wrong; here it only fails the models.
const manifest = bootSpan('worker:manifest', () => loadManifest(new URL('models/manifest.json', page).href));
manifest.catch(() => undefined);

const models = new Set<string>();

/** Download one model (once per name) and send its bytes to the page. */
function load(name: string): void {
  if (models.has(name)) return;
  models.add(name);
  manifest
    .then((loaded) => {
      // The manifest came by its own request: of this build's deployment, or no models at all.
      const other = otherDeployment(loaded);
      if (other) throw new DuetError('duet is being updated', other);
      const entry = loaded.models[name];
      if (!entry) throw new DuetError('Model not found', `"${name}" is not in manifest.json`);
      progress.expect(name, entry.bytes, 'model');
      const version = assetVersion(loaded);
      return slots.run(entry.bytes, () =>
        bootSpan(`download:${name}`, () => fetchModelBytes(loaded, name, (n) => progress.add(name, n), version, page.href, (n) => progress.wire(name, n))),
      );
    })
    .then(
      (bytes) => post({ type: 'model', name, bytes, files: fetchedFiles() }, [bytes.buffer as ArrayBuffer]),
      (error) => post(failure(name, error)),
    );
}

// The first dance's models, largest first, the moment the manifest is in.
manifest.then((loaded) => firstDanceModels(loaded, page.search).forEach(load), () => undefined);

function fetchedFiles(): FetchedFile[] {
  const at = (ms: number) => performance.timeOrigin + ms;
  return (performance.getEntriesByType('resource') as PerformanceResourceTiming[]).map((e) => ({
    url: e.name,
    transferSize: e.transferSize,
    encodedBodySize: e.encodedBodySize,
    start: at(e.startTime),
    firstByte: at(e.responseStart),
    end: at(e.responseEnd),
  }));
}

self.onmessage = (event: MessageEvent<ToWorker>) => {
  if (event.data.type === 'load') load(event.data.name);
};
