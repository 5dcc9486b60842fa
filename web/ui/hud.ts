// Heads-up numbers: how long a simulation step takes, how fast the page draws, how many WASM
// threads run the models and how many bytes of model were downloaded. Updated a few times a
// second with textContent (cheap, and never interprets markup).

export interface HudStats {
  stepMs: { median: number; p95: number };
  fps: number;
  threads: number;
  modelBytes: number;
  /** Guard counts (resets after absurd output, leashed frames); shown only once one acted. */
  guards: { resets: number; leashed: number };
}

export class Hud {
  private readonly element: HTMLElement;
  private readonly status: HTMLElement;
  private lastUpdate = 0;

  constructor(parent: HTMLElement) {
    this.element = document.createElement('div');
    this.element.className = 'hud';
    this.status = document.createElement('div');
    this.status.className = 'status';
    parent.append(this.element, this.status);
  }

  /** A line under the numbers: "loading models…", "paused", or nothing. */
  setStatus(text: string): void {
    this.status.textContent = text;
    this.status.hidden = text === '';
  }

  update(now: number, stats: HudStats): void {
    if (now - this.lastUpdate < 250) return;
    this.lastUpdate = now;
    const { median, p95 } = stats.stepMs;
    this.element.textContent =
      `step ${median.toFixed(1)} ms (p95 ${p95.toFixed(1)})  ·  ${Math.round(stats.fps)} fps  ·  ` +
      `${stats.threads} thread${stats.threads === 1 ? '' : 's'}  ·  models ${formatBytes(stats.modelBytes)}` +
      (stats.guards.resets || stats.guards.leashed
        ? `  ·  guards: ${stats.guards.resets} reset${stats.guards.resets === 1 ? '' : 's'}, ${stats.guards.leashed} leashed frames`
        : '');
  }
}

export function formatBytes(bytes: number): string {
  if (bytes >= 1e6) return `${(bytes / 1e6).toFixed(1)} MB`;
  if (bytes >= 1e3) return `${(bytes / 1e3).toFixed(0)} kB`;
  return `${bytes} B`;
}
