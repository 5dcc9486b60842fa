// Boot timings: when each stage of the start happened (ms since navigation, performance.now()),
// so that the phone bench (scripts/bench_phone.mjs) can say where the time to the first dancing
// frame goes instead of guessing. Published as window.duet.bootTimings; each stage is also a
// performance.mark('duet:<stage>'), visible in a DevTools performance recording. The fetcher
// worker's stages (downloads, the wasm's compilation) reach the page as messages.
//
// A stage is recorded once (the first time), so a later model switch does not overwrite the
// numbers of the first dance.

export type BootTimings = Record<string, number>;

export const bootTimings: BootTimings = {};

let listener: ((stage: string, at: number) => void) | null = null;

/** Also tell `listen` about every stage recorded from now on (the fetcher worker forwards its
 *  stages to the page this way). */
export function onBootMark(listen: (stage: string, at: number) => void): void {
  listener = listen;
}

/** Record `stage` now (or at `at`, ms since this context's timeOrigin), unless it was recorded already. */
export function bootMark(stage: string, at = performance.now()): void {
  if (stage in bootTimings) return;
  bootTimings[stage] = at;
  performance.mark?.(`duet:${stage}`, { startTime: at });
  listener?.(stage, at);
}

/** Record `<stage>:start`, run `start`, and record `<stage>:end` when its promise fulfils. */
export function bootSpan<T>(stage: string, start: () => Promise<T>): Promise<T> {
  bootMark(`${stage}:start`);
  const task = start();
  task.then(
    () => bootMark(`${stage}:end`),
    () => undefined, // failures are reported where the task is awaited
  );
  return task;
}
