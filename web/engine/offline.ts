// The service worker (public/sw.js) keeps the models, the wasm and the page in the browser's
// cache, so a second visit starts without downloading them and an offline visit still dances.
// Registered only by production builds (the dev server's modules change on every edit) and only
// on http(s) pages (file: and other schemes have no service workers).
//
// After a new deployment the new version's worker installs and waits; this page tells it to take
// over once the page dances (keepForOffline), never while onnxruntime is starting (sw.js says why).

import type { Manifest } from './types';
import { shortHash } from './download';
import { WASM_URL } from './wasm';

/** The models version of this build's own manifest (vite.config.ts, modelsStamp); '' in
 *  development (the dev server's manifest may be exported anew while it runs) and under the test
 *  runners. */
declare const __DUET_MODELS__: string | undefined;
export const BUILD_MODELS = import.meta.env.PROD && typeof __DUET_MODELS__ === 'string' ? __DUET_MODELS__ : '';

/** The version of the models a manifest names (their files, sizes and fingerprints). */
export function modelsVersion(manifest: Manifest): string {
  return shortHash(JSON.stringify(manifest.models));
}

/** Why `manifest` is not of this build's deployment (the site changed between the page's request
 *  and the manifest's), or null when it is, or when the build has no stamp. */
export function otherDeployment(manifest: Manifest): string | null {
  const models = modelsVersion(manifest);
  if (!BUILD_MODELS || models === BUILD_MODELS) return null;
  return `This page is from one version of the site and its models from another (page ${BUILD_MODELS}, models ${models}): reload in a moment.`;
}

/** The version of what the page downloads: the models and the wasm. */
export function assetVersion(manifest: Manifest): string {
  return shortHash(JSON.stringify(manifest.models) + WASM_URL);
}

function available(): boolean {
  return import.meta.env.PROD && /^https?:$/.test(location.protocol) && 'serviceWorker' in navigator;
}

const scriptVersion = (worker: ServiceWorker) => new URL(worker.scriptURL).searchParams.get('v');

let registered: Promise<ServiceWorkerRegistration | undefined> = Promise.resolve(undefined);

/**
 * Register sw.js for this version (a new version installs a new worker, which waits). `onReplaced`
 * is called when a worker of another version takes this page over: a newer site went up while
 * this page was open (another tab of it danced), and what this page has not loaded yet is gone.
 */
export function registerOffline(version: string, onReplaced: () => void): void {
  if (!available()) return;
  registered = navigator.serviceWorker.register(`sw.js?v=${version}`).catch(() => undefined); // the page works without it
  navigator.serviceWorker.addEventListener('controllerchange', () => {
    const controller = navigator.serviceWorker.controller;
    if (controller && scriptVersion(controller) !== version) onReplaced();
  });
}

/** Resolves at the registration's next updatefound, or after `ms`. */
function updateFound(registration: ServiceWorkerRegistration, ms: number): Promise<void> {
  return new Promise((done) => {
    registration.addEventListener('updatefound', () => done(), { once: true });
    setTimeout(done, ms);
  });
}

/** Resolves once `worker` is no longer installing (installed, or failed: redundant). */
function installed(worker: ServiceWorker): Promise<void> {
  return new Promise((done) => {
    const check = () => {
      if (worker.state === 'installing') return;
      worker.removeEventListener('statechange', check);
      done();
    };
    worker.addEventListener('statechange', check);
    check();
  });
}

/** This version's worker once it is installed (waiting or active), or null. */
async function workerOf(version: string): Promise<ServiceWorker | null> {
  const registration = await registered;
  if (!registration) return null;
  const find = () => [registration.installing, registration.waiting, registration.active].find((w) => w && scriptVersion(w) === version) ?? null;
  let worker = find();
  // register() can resolve before the new version's script is even fetched: nothing of this
  // version yet, and the keep (and the new worker's taking over) would be lost until a next visit.
  if (!worker) {
    await updateFound(registration, 10_000);
    worker = find();
  }
  if (worker?.state === 'installing') await installed(worker);
  return worker && worker.state !== 'redundant' ? worker : null;
}

/**
 * Once the dance runs: ask this version's worker to keep everything this visit downloaded from
 * this origin (the first visit is not controlled by the worker yet, so it saw none of it): what
 * this page's resource timing lists, and `fetchedElsewhere` (the fetcher worker's downloads,
 * which it does not). Most of it comes out of the HTTP cache, not the network. A new version's
 * worker, waiting since this page registered it, takes over with the same message.
 */
export function keepForOffline(version: string, fetchedElsewhere: string[] = []): void {
  if (!available()) return;
  // The wasm by name too: the fetcher worker lists its files as of its last message, and on a fast
  // link the wasm's own entry can come after that (its body is read by the compiler); without it
  // the repeat visit downloaded the wasm again (tests/e2e/offline.test.mjs failed once in two runs).
  const urls = [location.href, new URL(WASM_URL, location.href).href,
    ...performance.getEntriesByType('resource').map((entry) => entry.name), ...fetchedElsewhere]
    .filter((url) => url.startsWith(location.origin));
  workerOf(version)
    .then((worker) => worker?.postMessage({ type: 'keep', urls, activate: true }))
    .catch(() => undefined);
}
