// How far the camera must stand for the pair to fit the part of the screen the page leaves them
// (web/ui/layout.ts measures it: below the title card, above a phone's settings sheet, left of an
// open panel card or drawer). The picture's centre is moved to the middle of that part (a view
// offset, Stage.setFrame), so the orbit target (the pair's midpoint at hip height) is drawn there,
// and a point q (metres from the target) with camera-space coordinates x (right), y (up) and depth
// d + q·forward is drawn K·x / depth pixels right of that middle, K = (canvas height / 2) /
// tan(fov / 2). It stays inside a half-width of w pixels while depth ≥ K·|x| / w: a distance d
// that fits each point follows in closed form, with no search.
//
// Two uses, each frame, for the angle the camera looks from: the closest a wheel or a pinch may
// bring it (a body-sized cylinder around the target fits), and the distance the dancers' own heads
// and feet need (a dancer stepping out of the cylinder backs the camera off until it is back in).
// Plain numbers only (no three.js), so the unit tests can check it (tests/web/framing.test.ts).

/** A part of the canvas, CSS pixels from its top-left corner. */
export interface Rect {
  left: number;
  top: number;
  right: number;
  bottom: number;
}

/** The camera's axes (unit vectors, world): right, up and forward (where it looks). */
export interface Basis {
  right: readonly [number, number, number];
  up: readonly [number, number, number];
  forward: readonly [number, number, number];
}

/** What a fit depends on: the canvas's height and the vertical field of view (degrees), and the
 *  half-width and half-height (pixels) of the free part, less a margin. */
export interface FrameWindow {
  height: number;
  fov: number;
  halfWidth: number;
  halfHeight: number;
}

/** The pair as the closest distance sees it: a cylinder this high (from the floor) around the
 *  orbit target's vertical axis, its radius set per mode (Stage.keepInView). Heads reach 1.85 m. */
export const PAIR_TOP = 1.9;
/** Pixels kept between a dancer and the edge of the free part. */
export const FRAME_MARGIN = 6;
/** Nearer than this the camera would be inside a dancer. */
const NEAREST = 0.5;

/** The window a free part of the canvas gives (its middle is where the picture is centred). */
export function frameWindow(free: Rect, height: number, fov: number, margin = FRAME_MARGIN): FrameWindow {
  return {
    height,
    fov,
    halfWidth: Math.max(1, (free.right - free.left) / 2 - margin),
    halfHeight: Math.max(1, (free.bottom - free.top) / 2 - margin),
  };
}

/** The view offset that draws the picture's centre in the middle of `free`: [x, y] pixels that
 *  the canvas's centre moves left and up (Camera.setViewOffset's offsets). */
export function viewShift(free: Rect, width: number, height: number): [number, number] {
  return [width / 2 - (free.left + free.right) / 2, height / 2 - (free.top + free.bottom) / 2];
}

/**
 * The least distance from the target at which every point fits the window, the camera looking
 * along `basis.forward` at the target. `points`: xyz, metres from the target; `count` of them.
 */
export function distanceToFit(points: ArrayLike<number>, count: number, basis: Basis, window: FrameWindow): number {
  const k = window.height / 2 / Math.tan(((window.fov / 2) * Math.PI) / 180);
  const { right, up, forward } = basis;
  let need = NEAREST;
  for (let i = 0; i < count; i++) {
    const qx = points[3 * i], qy = points[3 * i + 1], qz = points[3 * i + 2];
    const x = qx * right[0] + qy * right[1] + qz * right[2];
    const y = qx * up[0] + qy * up[1] + qz * up[2];
    const ahead = qx * forward[0] + qy * forward[1] + qz * forward[2];
    // The depth this point needs, less how much deeper than the target it lies.
    const depth = Math.max(NEAREST, (k * Math.abs(x)) / window.halfWidth, (k * Math.abs(y)) / window.halfHeight);
    need = Math.max(need, depth - ahead);
  }
  return need;
}

/** Points around a cylinder of `radius` around the target's axis, from the floor to PAIR_TOP
 *  (the target `targetHeight` above the floor): two rings of 48. */
export function cylinderPoints(radius: number, targetHeight: number): Float32Array {
  const n = 48;
  const points = new Float32Array(3 * 2 * n);
  for (let ring = 0; ring < 2; ring++) {
    const y = (ring === 0 ? 0 : PAIR_TOP) - targetHeight;
    for (let i = 0; i < n; i++) {
      const a = (2 * Math.PI * i) / n, o = 3 * (ring * n + i);
      points[o] = radius * Math.cos(a);
      points[o + 1] = y;
      points[o + 2] = radius * Math.sin(a);
    }
  }
  return points;
}
