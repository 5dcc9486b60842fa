// duet's service worker: a second visit, and an offline one, start without the network.
//
// - Models (.onnx), onnxruntime's wasm and the build's hashed assets: cache first. The page sends
//   the version it expects in the x-duet-version header (web/engine/download.ts); a worker of
//   another version answers those from the network, so new models are never shadowed by old ones.
// - Everything else of this origin (the page, manifest.json): network first, the cache when offline.
// - The version (?v= in this script's URL, web/engine/offline.ts) names the cache; a new version
//   deletes the old caches when it activates.
// The first visit is not controlled by this worker: the page posts the URLs it downloaded
// ({type: 'keep'}) and the worker stores them.
//
// A new version waits until the page of that version dances and says so ({type: 'keep',
// activate: true}); only then does it take over and delete the old caches. Taking over at once
// (skipWaiting on install) changed the worker under a page that was still starting onnxruntime:
// its thread's script, asked for in that moment, never came, and the start hung for good in 4 of
// 52 visits after a deploy (scripts/deploy_trials.mjs; docs/reliability.md). While the new one
// waits, the old worker answers the new page's requests for models of another version from the
// network (the x-duet-version header), and everything else by its hashed name or network first.

const VERSION = new URL(self.location.href).searchParams.get('v') || 'dev';
const CACHE = `duet-${VERSION}`;
const VERSION_HEADER = 'x-duet-version';

const immutable = (url) => /\.(onnx|wasm)$/.test(url.pathname) || /\/assets\/[^/]+-[\w-]{8,}\.\w+$/.test(url.pathname);

self.addEventListener('activate', (event) => {
  event.waitUntil(
    caches.keys().then((names) => Promise.all(names.filter((n) => n.startsWith('duet-') && n !== CACHE).map((n) => caches.delete(n)))),
  );
});

self.addEventListener('message', (event) => {
  const data = event.data;
  if (!data || data.type !== 'keep' || !Array.isArray(data.urls)) return;
  // The page of this version dances: take over (a waiting worker), now that nothing is starting.
  if (data.activate) self.skipWaiting();
  event.waitUntil(
    caches.open(CACHE).then((cache) =>
      Promise.all(
        data.urls.map(async (href) => {
          const url = new URL(href);
          if (url.origin !== self.location.origin || url.pathname.endsWith('/sw.js')) return;
          if (await cache.match(href)) return;
          try {
            const response = await fetch(href);
            if (response.ok && response.type === 'basic') await cache.put(href, response);
          } catch {
            // offline or gone: kept next time
          }
        }),
      ),
    ),
  );
});

async function cacheFirst(request) {
  const cache = await caches.open(CACHE);
  const hit = await cache.match(request, { ignoreSearch: true });
  if (hit) return hit;
  const response = await fetch(request);
  if (response.ok && response.type === 'basic') cache.put(request, response.clone()).catch(() => undefined);
  return response;
}

async function networkFirst(request) {
  const cache = await caches.open(CACHE);
  try {
    const response = await fetch(request);
    if (response.ok && response.type === 'basic') cache.put(request, response.clone()).catch(() => undefined);
    return response;
  } catch (error) {
    // The page under any query string (?seed=…) is the same page.
    const hit = await cache.match(request, { ignoreSearch: request.mode === 'navigate' });
    if (hit) return hit;
    throw error;
  }
}

self.addEventListener('fetch', (event) => {
  const request = event.request;
  if (request.method !== 'GET') return;
  const url = new URL(request.url);
  if (url.origin !== self.location.origin) return;
  if (immutable(url)) {
    const expected = request.headers.get(VERSION_HEADER);
    if (expected && expected !== VERSION) return; // another version's page: the network decides
    event.respondWith(cacheFirst(request));
  } else {
    event.respondWith(networkFirst(request));
  }
});
