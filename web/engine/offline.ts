// The service worker (public/sw.js) keeps the models, the wasm and the page in the browser's
// cache, so a second visit starts without downloading them and an offline visit still dances.
// Registered only by production builds (the dev server's modules change on every edit) and only
// on http(s) pages (file: and other schemes have no service workers).

import type { Manifest } from './types';
import { shortHash } from './download';
import { WASM_URL } from './wasm';

/** The version of what the page downloads: the models (sizes and fingerprints) and the wasm. */
export function assetVersion(manifest: Manifest): string {
  return shortHash(JSON.stringify(manifest.models) + WASM_URL);
}

function available(): boolean {
  return import.meta.env.PROD && /^https?:$/.test(location.protocol) && 'serviceWorker' in navigator;
}

/** Register sw.js for this version (a new version installs a new worker, which drops old caches). */
export function registerOffline(version: string): void {
  if (!available()) return;
  navigator.serviceWorker.register(`sw.js?v=${version}`).catch(() => undefined); // the page works without it
}

/**
 * Once the dance runs: ask the worker to keep everything this visit downloaded from this origin
 * (the first visit is not controlled by the worker yet, so it saw none of it): what this page's
 * resource timing lists, and `fetchedElsewhere` (the fetcher worker's downloads, which it does
 * not). Most of it comes out of the HTTP cache, not the network.
 */
export function keepForOffline(fetchedElsewhere: string[] = []): void {
  if (!available()) return;
  // The wasm by name too: the fetcher worker lists its files as of its last model, and on a fast
  // link the wasm's own entry can come after that (its body is read by the compiler); without it
  // the repeat visit downloaded the wasm again (tests/e2e/offline.test.mjs failed once in two runs).
  const urls = [location.href, new URL(WASM_URL, location.href).href,
    ...performance.getEntriesByType('resource').map((entry) => entry.name), ...fetchedElsewhere]
    .filter((url) => url.startsWith(location.origin));
  navigator.serviceWorker.ready
    .then((registration) => registration.active?.postMessage({ type: 'keep', urls }))
    .catch(() => undefined);
}
