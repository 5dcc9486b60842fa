// One Vite dev server for all the browser test files of an `npm test` (scripts/test.sh starts it
// and gives its address to each file as DUET_DEV_URL: harness.startServer). Vite compiles the
// page's modules on their first request and keeps them in memory, so a server per file paid that
// compile again in each file's first page. This one loads the page once (a half-resolution
// browser) before it says its address, so every file meets a warm server; it prints the address
// on a line of its own and serves until SIGTERM or SIGINT, then stops Vite.
// Run: DUET_DEV_URL= node tests/e2e/devserver.mjs

import { QUICK, launch, startServer, waitReady } from './harness.mjs';

const server = await startServer({ mode: 'dev' });
const stop = async () => {
  await server.stop();
  process.exit(0);
};
process.on('SIGTERM', stop);
process.on('SIGINT', stop);

const warm = await launch(QUICK);
try {
  await warm.page.goto(`${server.url}?seed=1`);
  await waitReady(warm.page);
} catch (error) {
  console.error(`devserver: the first page did not load (${error}); serving anyway`);
} finally {
  await warm.close();
}
process.stdout.write(`${server.url}\n`);
setInterval(() => {}, 1 << 30);
