// Heads-up display: one line that says who is who (a colour legend, which also explains compare
// mode), a status line ("loading the dancers…", "paused"), and the engine's figures (step time, frame
// rate, WASM threads, model bytes, guard counts) in an element the help overlay shows inside its
// "about / details" fold. Updated a few times a second with textContent (cheap, and never
// interprets markup).

import type { FollowerChoice } from '../engine/types';

export interface HudStats {
  stepMs: { median: number; p95: number };
  fps: number;
  threads: number;
  modelBytes: number;
  /** Guard counts (resets after absurd output, leashed frames, steps the upright guard chose
   *  another sample); shown only once one acted. */
  guards: { resets: number; leashed: number; upright: number };
}

/** Legend entries per follower choice: [colour class, words]. */
const LEGENDS: Record<FollowerChoice, [string, string][]> = {
  ours: [['you', 'you lead'], ['partner', 'partner follows']],
  ccm: [['you', 'you lead'], ['partner', 'baseline partner']],
  compare: [['you', 'you (twice)'], ['partner', 'reads your intention'], ['baseline', 'baseline']],
};

export class Hud {
  private readonly legend: HTMLElement;
  private readonly status: HTMLElement;
  /** The engine's figures; the help overlay moves this element into its details fold. */
  readonly details: HTMLElement;
  private lastUpdate = 0;
  private choice: FollowerChoice | null = null;

  constructor(parent: HTMLElement) {
    this.legend = document.createElement('div');
    this.legend.className = 'hud';
    this.status = document.createElement('div');
    this.status.className = 'status';
    this.status.hidden = true;
    this.details = document.createElement('div');
    this.details.className = 'engine-figures';
    parent.append(this.legend, this.status);
    this.setLegend('ours');
  }

  /** Who is who, for the follower choice on screen. */
  setLegend(choice: FollowerChoice): void {
    if (choice === this.choice) return;
    this.choice = choice;
    this.legend.replaceChildren(
      ...LEGENDS[choice].map(([kind, words]) => {
        const item = document.createElement('span');
        item.className = `legend legend-${kind}`;
        item.textContent = words;
        return item;
      }),
    );
  }

  /** A line under the legend: "loading the dancers…", "paused", or nothing. */
  setStatus(text: string): void {
    this.status.textContent = text;
    this.status.hidden = text === '';
  }

  update(now: number, stats: HudStats): void {
    if (now - this.lastUpdate < 250) return;
    this.lastUpdate = now;
    const { median, p95 } = stats.stepMs;
    this.details.textContent =
      `step ${median.toFixed(1)} ms (p95 ${p95.toFixed(1)})  ·  ${Math.round(stats.fps)} fps  ·  ` +
      `${stats.threads} WASM thread${stats.threads === 1 ? '' : 's'}  ·  models ${formatBytes(stats.modelBytes)}` +
      (stats.guards.resets || stats.guards.leashed || stats.guards.upright
        ? `  ·  guards: ${stats.guards.resets} reset${stats.guards.resets === 1 ? '' : 's'}, ${stats.guards.leashed} leashed frames, ` +
          `${stats.guards.upright} upright choice${stats.guards.upright === 1 ? '' : 's'}`
        : '');
  }
}

export function formatBytes(bytes: number): string {
  if (bytes >= 1e6) return `${(bytes / 1e6).toFixed(1)} MB`;
  if (bytes >= 1e3) return `${(bytes / 1e3).toFixed(0)} kB`;
  return `${bytes} B`;
}

/** The pause / resume button by the title: Space's twin, for phones (no keyboard) and mice. */
export class PauseButton {
  readonly element: HTMLButtonElement;

  constructor(onClick: () => void) {
    this.element = document.createElement('button');
    this.element.type = 'button';
    this.element.className = 'pause-button';
    this.element.addEventListener('click', onClick);
    // Next to the title (the overlay lets drags through; the button takes its own clicks).
    const title = document.querySelector('#overlay .title-row');
    (title ?? document.body).append(this.element);
    this.show(false);
  }

  /** Say what a press does next. */
  show(paused: boolean): void {
    this.element.textContent = paused ? 'resume' : 'pause';
    this.element.title = paused ? 'resume the dance (Space)' : 'pause the dance (Space)';
  }
}
