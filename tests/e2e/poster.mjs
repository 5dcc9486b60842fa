// The loading scene's picture (index.html's #poster, drawn by scripts/poster.mjs) against the live
// loading scene, as a visitor's screen shows them: shared by tests/e2e/loading.test.mjs.

import { WAIT_MS, launch, pngCanvas } from './harness.mjs';

/** Everything over the canvas hidden except the picture: the two screens show the scene alone. */
const SCENE_ONLY = 'body > *:not(#app):not(#poster) { visibility: hidden !important; }';

/**
 * Two screenshots of `url` in a browser with `options` (viewport...): the picture alone (the
 * page's script held back, so nothing replaces it) and the live scene (the models held back, so
 * it stays the standing pair). `css` is added to the picture's page (a test's negative control).
 */
export async function posterAndScene(url, options, css = '') {
  const browser = await launch(options);
  try {
    const { page } = browser;
    await page.route('**/assets/index-*.js', (route) => route.abort());
    await page.goto(url);
    await page.addStyleTag({ content: SCENE_ONLY + css });
    await page.waitForFunction(() => document.querySelector('#poster img')?.complete, null, { timeout: WAIT_MS, polling: 50 });
    const source = await page.evaluate(() => document.querySelector('#poster img').currentSrc.replace(location.origin, ''));
    await page.waitForTimeout(200);
    const poster = await page.screenshot({ type: 'png' });
    await page.unroute('**/assets/index-*.js');

    await page.route('**/models/*.onnx', () => undefined); // never answered: the pair stays standing
    await page.goto(url);
    await page.waitForFunction(() => window.duet?.sceneMs || window.duet?.error, null, { timeout: WAIT_MS, polling: 50 });
    await page.addStyleTag({ content: SCENE_ONLY });
    const removed = await page.evaluate(() => !document.getElementById('poster'));
    await page.waitForTimeout(500); // as scripts/poster.mjs: shadows and camera damping settle
    const scene = await page.screenshot({ type: 'png' });
    const difference = await compare(page, poster, scene);
    return { source, removed, difference };
  } finally {
    await browser.close();
  }
}

/**
 * How far two screenshots differ: both scaled down 4× in the page (the picture is drawn at another
 * pixel ratio than the screen, which sharpens edges differently), then per pixel the largest
 * channel difference. Returns its mean and the share of pixels off by more than 32 of 255: a
 * picture shifted or scaled against the scene moves the dancers and the grid lines, and that share
 * grows with it.
 */
export async function compare(page, a, b) {
  const [p, q] = [await pngCanvas(page, a, 0.25), await pngCanvas(page, b, 0.25)];
  return page.evaluate(([p, q]) => {
    const pixels = (canvas) => canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    const [x, y] = [pixels(p), pixels(q)];
    let sum = 0, off = 0;
    const n = x.length / 4;
    for (let i = 0; i < x.length; i += 4) {
      const d = Math.max(Math.abs(x[i] - y[i]), Math.abs(x[i + 1] - y[i + 1]), Math.abs(x[i + 2] - y[i + 2]));
      sum += d;
      if (d > 32) off++;
    }
    return { mean: sum / n, off: off / n };
  }, [p, q]);
}
