// Boot timings: when each stage of the start happened (ms since navigation, performance.now()),
// so that the phone bench (scripts/bench_phone.mjs) can say where the time to the first dancing
// frame goes instead of guessing. Published as window.duet.bootTimings; each stage is also a
// performance.mark('duet:<stage>'), visible in a DevTools performance recording.
//
// A stage is recorded once (the first time), so a later model switch does not overwrite the
// numbers of the first dance.

export type BootTimings = Record<string, number>;

export const bootTimings: BootTimings = {};

/** Record `stage` now, unless it was recorded already. */
export function bootMark(stage: string): void {
  if (stage in bootTimings) return;
  bootTimings[stage] = performance.now();
  performance.mark?.(`duet:${stage}`);
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
