// What the page does when its start stands still or the site changes under it: start again by
// itself (the watchdog's restart, engine/watchdog.ts), say what stalled after too many restarts,
// and tell a visitor whose tab outlived a deployment to reload (engine/offline.ts, sw.js).

import { bootTimings } from '../engine/boot';
import { MAX_RESTARTS, clearRestarts } from '../engine/watchdog';
import { DuetError, showError } from './errors';
import { showToast } from './toast';

let replaced = false;
let reloading = false;

/** Whether a worker of a newer site took this page over: its own files may be gone from the
 *  server now, and the server's models are not its models. */
export function siteReplaced(): boolean {
  return replaced;
}

/** A model this page never loaded, asked for after a newer site went up: the server's file is
 *  another version's now, so it is not fetched (the partner already dancing dances on). */
export class SiteUpdatedError extends DuetError {
  constructor(model: string) {
    super('duet was updated', `A newer version of the site went up while this page was open, so "${model}" cannot be loaded for this one: reload the page.`);
  }
}

/** A newer site went up while this page was open: say so, once. */
export function siteUpdated(): void {
  if (replaced) return;
  replaced = true;
  showToast('duet was updated', 'A newer version of the site went up. This page dances on; reload it for the new one (switching partner or dressing an avatar needs the reload).', 'info', 60_000);
}

// A chunk of this build asked for after a newer deployment removed it (an avatar, the baseline):
// say why instead of "Failed to fetch dynamically imported module".
window.addEventListener('vite:preloadError', () => siteUpdated());

/** Whether the page is about to reload itself (restart). */
export function restarting(): boolean {
  return reloading;
}

/** Start again by reloading, after saying why (the watchdog's restart, or a page and manifest of
 *  two deployments). */
export function restart(why: string): void {
  if (reloading) return;
  reloading = true;
  console.warn('[duet]', why);
  showToast('Starting again', why, 'info', 10_000);
  setTimeout(() => location.reload(), 500);
}

/** The watchdog saw no progress for `stalledMs`: start again, or say what stalled. */
export function stalled(stalledMs: number, again: boolean): void {
  const stages = Object.keys(bootTimings);
  const after = stages.length ? ` after "${stages[stages.length - 1]}"` : '';
  const seconds = Math.round(stalledMs / 1000);
  if (again) {
    restart(`The start stood still for ${seconds} s${after}: starting again.`);
    return;
  }
  clearRestarts();
  showError(new DuetError('The start stalled', `Nothing moved for ${seconds} s${after}, also after ${MAX_RESTARTS} restarts. Reload the page to try again; if it stalls again, add ?threads=1 to the address.`));
}
