// Which models a dance needs, and which the first dance of this page needs: the leader and the
// follower choice of the page's URL (?model=). Read by the fetcher worker, which starts
// downloading them on its own (fetcher.worker.ts), and by the page.

import type { FollowerChoice, Manifest } from './types';
import { defaultSettings, readSettings } from '../ui/share';

/** The follower model(s) of each choice in the panel and the URL. */
export const FOLLOWER_MODELS: Record<FollowerChoice, string[]> = {
  ours: ['follower'],
  ccm: ['follower_ccm'],
  compare: ['follower', 'follower_ccm'],
};

/** The first dance's follower choice ('ours' when the manifest has no CCM follower) and threads. */
export function firstDanceSettings(manifest: Manifest, search: string): { choice: FollowerChoice; threads: number | null } {
  const settings = readSettings(search, defaultSettings(manifest.defaultTemperature));
  return { choice: 'follower_ccm' in manifest.models ? settings.model : 'ours', threads: settings.threads };
}

/** The first dance's models, largest first: the smallest comes in last (slots.ts). */
export function firstDanceModels(manifest: Manifest, search: string): string[] {
  const size = (name: string) => manifest.models[name]?.bytes ?? 0;
  return ['leader', ...FOLLOWER_MODELS[firstDanceSettings(manifest, search).choice]].sort((a, b) => size(b) - size(a));
}
