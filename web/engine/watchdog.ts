// The start's watchdog: a start that stops moving says so and starts again by itself.
//
// Why: a start can hang for good without any error, for example when onnxruntime's thread never
// gets its script (a service worker changing under the page used to do that after a deploy,
// sw.js) — the loading bar then stood still forever, and only the visitor's reload helped. Here
// the page watches its own progress (a new boot stage or more bytes downloaded) and, when none
// comes for STALL_MS while the tab is visible, reloads itself: at most MAX_RESTARTS times in a
// row for one tab, then it shows what stalled instead of reloading on and on.
//
// The count of restarts lives in sessionStorage (one tab, survives the reload): the page that
// finally dances reads it (window.duet.recovered) and clears it.

/** No progress for this long means stalled. The longest quiet stretch of a healthy start is one
 *  session's creation or the wasm's last compilation: under 3 s on the phone bench (4x CPU). */
export const STALL_MS = 20_000;
/** Restarts in a row before the page gives up and shows an error. */
export const MAX_RESTARTS = 2;
const KEY = 'duet:restarts';

function storage(): Storage | null {
  try {
    return window.sessionStorage;
  } catch {
    return null; // storage refused (some private modes): no count, so no restart (takeRestart)
  }
}

/** How many times this tab's start was restarted in a row (0 on a start that follows none). */
export function restartsSoFar(): number {
  return Number(storage()?.getItem(KEY) ?? 0) || 0;
}

/** The start is over (danced or failed with its own message): the next stall starts a new count. */
export function clearRestarts(): void {
  storage()?.removeItem(KEY);
}

/** Count one more restart if one is still allowed; false when the page should stop and say why
 *  (MAX_RESTARTS reached, or no sessionStorage to count them in: no reload without a count). */
export function takeRestart(): boolean {
  const store = storage();
  const restarts = restartsSoFar();
  if (!store || restarts >= MAX_RESTARTS) return false;
  store.setItem(KEY, String(restarts + 1));
  return true;
}

export class BootWatchdog {
  private last = '';
  private since = performance.now();
  private timer: ReturnType<typeof setInterval> | null = null;

  /**
   * `progress()` describes how far the start is (it changes whenever it moves on); `onStall` is
   * called once with the stalled stretch in ms and whether a restart is still allowed.
   */
  constructor(
    private readonly progress: () => string,
    private readonly onStall: (stalledMs: number, restart: boolean) => void,
    private readonly stallMs = STALL_MS,
  ) {}

  start(): void {
    this.last = this.progress();
    this.since = performance.now();
    this.timer = setInterval(this.check, 1000);
    // A hidden tab gets no animation frames and slow timers: the time it was hidden is no stall.
    document.addEventListener('visibilitychange', this.reset);
  }

  stop(): void {
    if (this.timer !== null) clearInterval(this.timer);
    this.timer = null;
    document.removeEventListener('visibilitychange', this.reset);
  }

  private readonly reset = (): void => {
    this.since = performance.now();
  };

  private readonly check = (): void => {
    const now = performance.now();
    const progress = this.progress();
    if (progress !== this.last || document.hidden) {
      this.last = progress;
      this.since = now;
      return;
    }
    if (now - this.since < this.stallMs) return;
    this.stop();
    this.onStall(now - this.since, takeRestart());
  };
}
