// Boot timings: when each stage of the start happened (ms since navigation, performance.now()),
// so that the phone bench (npm run bench -- --phone) can say where the time to the first dancing
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

/** Chromium's prioritized task scheduler (window.scheduler), where the browser has it. */
interface Scheduler {
  postTask(task: () => void, options: { priority: 'user-blocking' }): Promise<void>;
}

/**
 * Call `painted` with the time at which a frame drawn now is on screen, as far as this thread
 * can tell: after the rendering update that paints it (style, layout and paint of the page's
 * DOM, the canvas composited) has run. Drawn outside an animation-frame callback, that update is
 * the next one; drawn inside one, it is the current one, which runs once the callbacks and the
 * microtasks they queued are done. A task queued from there runs after it.
 */
export function afterPaint(painted: (at: number) => void, insideFrame: boolean): void {
  // A task of the highest priority where the browser has them (Chromium's scheduler.postTask):
  // a plain timeout would run after timeouts queued before it, such as the page's steps.
  const now = () => painted(performance.now());
  const scheduler = (globalThis as { scheduler?: Scheduler }).scheduler;
  const later = () => (scheduler ? scheduler.postTask(now, { priority: 'user-blocking' }) : setTimeout(now, 0));
  if (insideFrame) later();
  else requestAnimationFrame(later);
}
