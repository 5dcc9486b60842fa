// Mirror of training/mirror/footik.py. Foot locking for drawing: while the model says a foot is
// planted (its contact above the lock's threshold), keep it where the contact began, with a
// two-bone IK on thigh - shin - foot, and never below the floor.
//
// This touches only the DRAWN positions (DancerView.positions). The Track the features read stays
// exactly what the model produced, so the page's features remain identical to Python's.

import { FEET, PARENTS } from './skeleton';

/** Lowest height of the ankle joint: a flat foot's ankle sits 7-11 cm up in the data, so 6 cm
 *  keeps the sole above the floor without ever lifting a real flat foot. */
export const ANKLE_FLOOR = 0.06;
/** A lock never trails the model's foot by more than this: when the model slides a planted foot on,
 *  the lock slides along behind it (re-planting it at the foot was a jump that counted as skate).
 *  Further, the legs stretch out of the recorded range (training/mirror/footik.py: measured). */
export const MAX_LOCK_DISTANCE = 0.25;
/** Radians: a knee never straightens further than this to reach a lock (the recorded knees bend at
 *  least 0.19-0.30 in 99.5 % of frames; a leg pulled fully straight read as out of that range). */
export const MIN_KNEE_BEND = 0.2;
/** After a contact ends, the lock's pull decays by this factor per step (no pop on release). */
export const RELEASE_DECAY = 0.5;
/** The locks never hold the feet further apart than this (ankle to ankle): a lock trailing behind
 *  a dancer that travels on spread his stance past the recording's widest (1.07 m). */
export const MAX_STANCE = 0.9;
/** A foot locks while the model's contact for it is above this (both dancers; training/mirror/contact.py
 *  says why the follower's no longer locks from 0.3). */
export const CONTACT_THRESHOLD = 0.5;

/**
 * Two-bone IK in place on `positions` (17 × 3): joints a (thigh) -> b (knee) -> c (foot) keep
 * their bone lengths, c goes to the target (or as near as the leg reaches), and the knee stays
 * on the side it bends to now (the pole direction when the leg is straight).
 */
export function twoBoneIk(
  positions: Float32Array | Float64Array, a: number, b: number, c: number,
  tx: number, ty: number, tz: number, poleX: number, poleY: number, poleZ: number, minBend = 0,
): void {
  const ax = positions[3 * a], ay = positions[3 * a + 1], az = positions[3 * a + 2];
  const abx = positions[3 * b] - ax, aby = positions[3 * b + 1] - ay, abz = positions[3 * b + 2] - az;
  const upper = Math.hypot(abx, aby, abz);
  const lower = Math.hypot(positions[3 * c] - positions[3 * b], positions[3 * c + 1] - positions[3 * b + 1], positions[3 * c + 2] - positions[3 * b + 2]);
  let nx = tx - ax, ny = ty - ay, nz = tz - az;
  const reach = Math.hypot(nx, ny, nz);
  if (reach < 1e-9 || upper < 1e-9 || lower < 1e-9) return;
  nx /= reach;
  ny /= reach;
  nz /= reach;
  // The chain straightens up to minBend, or up to how straight the pose already is.
  const longest = Math.max(
    Math.sqrt(upper * upper + lower * lower + 2 * upper * lower * Math.cos(minBend)),
    Math.hypot(positions[3 * c] - ax, positions[3 * c + 1] - ay, positions[3 * c + 2] - az),
  );
  const d = Math.min(Math.max(reach, Math.abs(upper - lower) + 1e-6), Math.min(upper + lower - 1e-6, longest));
  // Bend direction: the knee's side of the thigh-foot line as posed now (so a knee bent forward
  // stays forward), made perpendicular to the new line; the pole for a straight leg.
  let ux = positions[3 * c] - ax, uy = positions[3 * c + 1] - ay, uz = positions[3 * c + 2] - az;
  const u = Math.hypot(ux, uy, uz);
  let mx = poleX, my = poleY, mz = poleZ;
  if (u > 1e-9) {
    ux /= u;
    uy /= u;
    uz /= u;
    const along = abx * ux + aby * uy + abz * uz;
    const bx = abx - along * ux, by = aby - along * uy, bz = abz - along * uz;
    if (Math.hypot(bx, by, bz) > 1e-6) {
      mx = bx;
      my = by;
      mz = bz;
    }
  }
  const along = mx * nx + my * ny + mz * nz;
  mx -= along * nx;
  my -= along * ny;
  mz -= along * nz;
  const m = Math.hypot(mx, my, mz);
  if (m < 1e-9) return;
  mx /= m;
  my /= m;
  mz /= m;
  // Triangle with sides upper, lower, d: the knee sits x along the line and h off it.
  const x = (upper * upper - lower * lower + d * d) / (2 * d);
  const h = Math.sqrt(Math.max(0, upper * upper - x * x));
  positions[3 * b] = ax + x * nx + h * mx;
  positions[3 * b + 1] = ay + x * ny + h * my;
  positions[3 * b + 2] = az + x * nz + h * mz;
  positions[3 * c] = ax + d * nx;
  positions[3 * c + 1] = ay + d * ny;
  positions[3 * c + 2] = az + d * nz;
}

/**
 * Move the lock target t[o..o+2] (in place) along the line to the model's foot (fx, fy, fz) until
 * it is within MAX_STANCE of the other foot (positions[q..q+2], as shown now); at the foot itself
 * if even that is further. The distance to a point is convex along a line, so the linear share
 * never overshoots.
 */
export function capStance(
  t: Float64Array, o: number, fx: number, fy: number, fz: number,
  positions: Float32Array | Float64Array, q: number,
): void {
  const ox = positions[q], oy = positions[q + 1], oz = positions[q + 2];
  const near = Math.hypot(fx - ox, fy - oy, fz - oz);
  const far = Math.hypot(t[o] - ox, t[o + 1] - oy, t[o + 2] - oz);
  if (far <= MAX_STANCE) return;
  const share = near >= MAX_STANCE ? 0 : (MAX_STANCE - near) / (far - near);
  t[o] = fx + (t[o] - fx) * share;
  t[o + 1] = Math.max(fy + (t[o + 1] - fy) * share, ANKLE_FLOOR);
  t[o + 2] = fz + (t[o + 2] - fz) * share;
}

/** A body the contact layer did not move (FootLock.apply's default glide). */
const NO_GLIDE = [0, 0] as const;

/** The lock state of one dancer's two feet, kept between steps. */
export class FootLock {
  constructor(readonly threshold: number = CONTACT_THRESHOLD) {}

  private readonly locked = [false, false];
  private readonly target = new Float64Array(6);
  private readonly weight = new Float64Array(2);

  /** Forget every lock (after a reset or a jump of the dancer). */
  clear(): void {
    this.locked[0] = this.locked[1] = false;
    this.weight.fill(0);
  }

  /**
   * Lock or release each foot from `contacts` (left, right) and bend the legs of `positions`
   * (17 × 3 world, modified in place). `heading` gives the knee's bend direction for a straight leg.
   * `glide` (x, z) is how far the contact layer's hip glide moved the body from where the network
   * put it (contact.ts HipGlide). The feet do not glide: a free foot goes where the network put it
   * on the floor, a planted one stays at its lock, and the legs take up the glide, so the drawn
   * steps land when the network's do (training/mirror/footik.py: measured).
   */
  apply(positions: Float32Array | Float64Array, contacts: ArrayLike<number>, heading: number, glide: ArrayLike<number> = NO_GLIDE): void {
    const glides = glide[0] !== 0 || glide[1] !== 0;
    for (let i = 0; i < FEET.length; i++) {
      const foot = FEET[i];
      const knee = PARENTS[foot];
      const thigh = PARENTS[knee];
      // The network's own foot on the floor.
      const fx = positions[3 * foot] - glide[0], fy = positions[3 * foot + 1], fz = positions[3 * foot + 2] - glide[1];
      const t = this.target;
      const o = 3 * i;
      if (contacts[i] > this.threshold) {
        if (!this.locked[i]) {
          t[o] = fx;
          t[o + 1] = Math.max(fy, ANKLE_FLOOR);
          t[o + 2] = fz;
          this.locked[i] = true;
        } else {
          const behind = Math.hypot(t[o] - fx, t[o + 1] - fy, t[o + 2] - fz);
          if (behind > MAX_LOCK_DISTANCE) {
            // slide along, MAX_LOCK_DISTANCE behind the foot
            const k = MAX_LOCK_DISTANCE / behind;
            t[o] = fx + (t[o] - fx) * k;
            t[o + 1] = Math.max(fy + (t[o + 1] - fy) * k, ANKLE_FLOOR);
            t[o + 2] = fz + (t[o + 2] - fz) * k;
          }
        }
        this.weight[i] = 1;
      } else {
        this.locked[i] = false;
        this.weight[i] = this.weight[i] * RELEASE_DECAY < 0.01 ? 0 : this.weight[i] * RELEASE_DECAY;
      }
      const w = this.weight[i];
      if (w > 0) capStance(t, o, fx, fy, fz, positions, 3 * FEET[1 - i]);
      const tx = fx + (t[o] - fx) * w;
      const ty = Math.max(fy + (t[o + 1] - fy) * w, ANKLE_FLOOR);
      const tz = fz + (t[o + 2] - fz) * w;
      if (w > 0 || glides || fy < ANKLE_FLOOR) twoBoneIk(positions, thigh, knee, foot, tx, ty, tz, Math.sin(heading), 0, Math.cos(heading), MIN_KNEE_BEND);
    }
  }
}
