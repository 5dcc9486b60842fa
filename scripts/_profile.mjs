import { build, launch } from '../tests/e2e/harness.mjs';
import { serve } from './serve.mjs';
await build('dist');
const server = await serve({ dir: 'dist' });
const browser = await launch({ viewport: { width: 412, height: 823 }, deviceScaleFactor: 1.75, isMobile: true, hasTouch: true });
const { page } = browser;
const cdp = await page.context().newCDPSession(page);
await cdp.send('Network.enable');
await cdp.send('Network.emulateNetworkConditions', { offline: false, latency: 40, downloadThroughput: (9e6 / 8) | 0, uploadThroughput: (1.6e6 / 8) | 0 });
await cdp.send('Emulation.setCPUThrottlingRate', { rate: 4 });
await cdp.send('Profiler.enable');
await cdp.send('Profiler.setSamplingInterval', { interval: 200 });
await cdp.send('Profiler.start');
await page.goto(server.url + '?seed=1', { waitUntil: 'commit' });
await page.waitForFunction(() => window.duet && window.duet.sceneMs, null, { timeout: 60000, polling: 50 });
const { profile } = await cdp.send('Profiler.stop');
const t = await page.evaluate(() => ({ scene: window.duet.sceneMs, boot: window.duet.bootTimings }));
console.log(JSON.stringify(t.boot));
const nodes = new Map(profile.nodes.map((n) => [n.id, n]));
const self = new Map();
const dt = profile.timeDeltas;
for (let i = 0; i < profile.samples.length; i++) { const n = nodes.get(profile.samples[i]); const k = `${n.callFrame.functionName || '(anon)'} ${n.callFrame.url.split('/').pop()}:${n.callFrame.lineNumber}`; self.set(k, (self.get(k) ?? 0) + (dt[i] ?? 0)); }
const byUrl = new Map();
for (const [k, v] of self) { const u = k.split(' ').pop().split(':')[0]; byUrl.set(u, (byUrl.get(u) ?? 0) + v); }
console.log([...byUrl].sort((a, b) => b[1] - a[1]).slice(0, 10).map(([k, v]) => `${(v / 1000).toFixed(0)} ms ${k}`).join('\n'));
console.log('---');
console.log([...self].sort((a, b) => b[1] - a[1]).slice(0, 30).map(([k, v]) => `${(v / 1000).toFixed(0)} ms ${k}`).join('\n'));
await browser.close(); await server.stop();
