// `npm run poster`: pictures of the loading scene (floor and the standing pair), drawn by the
// page itself in headless Chromium, that index.html shows from its first paint until the live
// scene is on screen (web/ui/poster-*.webp). On the phone profile the live scene needs about
// 2 s (the main script, the renderer, the bodies, the first frame: docs/measurements.md); the
// picture is there with the page's first paint.
//
// The picture must look like the live scene (tests/e2e/loading.test.mjs measures how closely): the camera keeps its vertical field of view
// whatever the window's shape, so a narrower window sees the middle of a wider one, and one
// picture drawn wide enough, scaled to the window's height and centred (CSS object-fit: cover),
// is what any narrower window would draw. Two pictures: a tall one for portrait windows and a
// wide one for the rest (index.html picks by aspect ratio). The standing pair does not depend on
// the seed or the models' weights, only on the manifest's skeleton and the scene's look, so
// rerun this after changing bodies, colours, lights or the camera; tests/e2e/loading.test.mjs
// fails when a picture no longer matches the live scene.
//
//   npm run poster                      # build, render both, write web/ui/poster-*.webp
//   npm run poster -- --dist /tmp/dist  # from a build made before

import { existsSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { ROOT, build, launch, pngCanvas } from '../tests/e2e/harness.mjs';
import { serve } from './serve.mjs';

/**
 * Each picture: its file, the window it is drawn in (CSS px, device pixel ratio) and the aspect
 * ratios it serves (index.html's <source media>). Both windows are ones in which the settings
 * panel starts folded (web/ui/panel.ts: width ≤ 600 or height ≤ 500 px), so the camera has no view
 * offset; index.html shifts the wide picture itself where the panel starts open.
 */
export const POSTERS = [
  // Portrait phones (aspect ≤ 3:4): 1080 × 1440 pixels, sharp on a phone 820 px tall at 1.75×.
  { file: 'web/ui/poster-tall.webp', viewport: { width: 600, height: 800 }, deviceScaleFactor: 1.8 },
  // Everything wider, up to 2.6:1 (with the open panel's shift of 154 px, 1280 × 800 needs 1.99:1).
  { file: 'web/ui/poster-wide.webp', viewport: { width: 1300, height: 500 }, deviceScaleFactor: 2 },
];
// WebP quality. Measured on 2026-11-24 against the screenshot at full size (tall / wide picture):
// 0.82 gives 30.2 / 60.3 kB, mean error 1.37 / 1.36 of 255 (worst pixel 49 / 124); 0.7 saves
// 8 / 16 kB for 1.51 / 1.50 (worst 63 / 113); 0.9 costs 15 / 29 kB more for 1.23 / 1.20.
const QUALITY = 0.82;

/** Everything drawn over the canvas hidden: the picture is the 3D scene alone. */
const SCENE_ONLY = 'body > *:not(#app) { visibility: hidden !important; }';

/** Draw the loading scene in `viewport` and return it as WebP bytes (at `quality`, 0..1). */
export async function render(url, { viewport, deviceScaleFactor }, quality = QUALITY) {
  const browser = await launch({ viewport, deviceScaleFactor });
  try {
    const { page } = browser;
    // Hold the models back for good: the page stays on the standing pair.
    await page.route('**/models/*.onnx', () => undefined);
    await page.goto(url);
    await page.waitForFunction(() => window.duet?.sceneMs || window.duet?.error, null, { timeout: 60_000, polling: 50 });
    const error = await page.evaluate(() => window.duet.error);
    if (error) throw new Error(`the page failed: ${error}`);
    await page.addStyleTag({ content: SCENE_ONLY });
    await page.waitForTimeout(500); // the shadows and the camera's damping settle
    const png = await page.screenshot({ type: 'png' });
    // Chromium encodes WebP (playwright screenshots are PNG or JPEG only).
    const canvas = await pngCanvas(page, png);
    const webp = await canvas.evaluate((canvas, quality) => canvas.toDataURL('image/webp', quality).split(',')[1], quality);
    return Buffer.from(webp, 'base64');
  } finally {
    await browser.close();
  }
}

async function main() {
  const at = process.argv.indexOf('--dist');
  const dist = at > 0 ? process.argv[at + 1] : null;
  if (!dist) await build('dist');
  else if (!existsSync(join(dist, 'index.html'))) throw new Error(`--dist ${dist}: no index.html there (build one with: npx vite build --outDir ${dist})`);
  const server = await serve({ dir: dist ?? join(ROOT, 'dist') });
  try {
    for (const poster of POSTERS) {
      const bytes = await render(`${server.url}?seed=1`, poster);
      writeFileSync(join(ROOT, poster.file), bytes);
      const { width, height } = poster.viewport;
      console.log(`${poster.file}: ${Math.round(width * poster.deviceScaleFactor)} × ${Math.round(height * poster.deviceScaleFactor)} px, ${(bytes.length / 1e3).toFixed(1)} kB`);
    }
  } finally {
    await server.stop();
  }
  console.log('rebuild the site (npm run build) to ship them');
}

if (import.meta.url === `file://${process.argv[1]}`) {
  main().catch((error) => {
    console.error(error);
    process.exit(1);
  });
}
