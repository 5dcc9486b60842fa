// Mirror of training/mirror/contact.py: the run-time contact layer, on what is SHOWN of the duet.
//
// The networks place each dancer on its own; three things they do not guarantee are fixed here,
// on copies of the current poses, never on the Track the features read (so the networks' own
// motion stays what they made, and every metric can be read with and without this layer):
// 1. bodies do not pass through each other: where the two spines come closer than 2 x TORSO_RADIUS,
//    both bodies move apart horizontally, half the shortfall each;
// 2. hands meet when the model brings them within reach: the closest hand pair, once closer than
//    HAND_REACH, is drawn toward a grip around its midpoint by two-bone IK of both arms, fully at
//    HAND_FULL and closer, with a weight that rises and falls smoothly;
// 3. planted feet stay planted: FootLock on both dancers, last, so a body moved by 1. keeps its feet.
// First of all, each body's path over the floor glides (HIP_GLIDE): the whole body is moved to
// where its hips' smoothed path is, except the feet: a free foot stays where the network put it on
// the floor, a planted one at its lock (FootLock, last), and the legs take up the difference.

import { CONTACT_THRESHOLD, FootLock, twoBoneIk } from './footik';
import { HANDS, PARENTS, SPINE } from './skeleton';

/** About half a torso's depth at the chest: spines closer than twice this pass through each other
 *  (training/evaluation/metrics.py). */
export const TORSO_RADIUS = 0.14;
/** m between the spines after the push (1 cm to spare). */
export const SEPARATION = 2 * TORSO_RADIUS + 0.01;
// The layer completes a hold the networks nearly make; it does not drag a hand across the gap.
// Reaching from 45 cm (fully from 25 cm), the hands met in 4-5x as many steered frames as the
// recorded couple's and the arm bent outside its recorded range; from 25 cm still 2x. From 20
// cm (the distance the hand-hold measure counts) it adds little to what the networks do
// (docs/plausibility.md).
/** m: a hand pair closer than this starts to meet. */
export const HAND_REACH = 0.2;
/** m: at or below this the hands meet fully. */
export const HAND_FULL = 0.1;
/** m between the two hands' joints when they meet (palm to palm). */
export const GRIP = 0.06;
/** Share of the way the hold weight moves up to its target every step. */
export const HOLD_RATE = 0.3;
/** ... and down: a hold ends in about two steps once the networks' hands part (contact.py says why). */
export const RELEASE_RATE = 0.7;
/** A straight arm bends its elbow downward. */
export const ELBOW_POLE = [0, -1, 0];
/** Radians: the recorded elbows bend at least 0.6-0.7 in 99.5 % of frames. */
export const MIN_ELBOW_BEND = 0.6;
/** Each step the shown hips take this share of the way from the step they last made to the
 *  network's new step over the floor (a running mean of its steps; horizontal only). Smoothing the
 *  velocity, not the place, the shown hips turn back only when the network's keep going back
 *  (training/mirror/contact.py: measured). */
export const HIP_GLIDE = 0.3;

type Positions = Float32Array | Float64Array;

const clamp01 = (v: number): number => Math.min(Math.max(v, 0), 1);

/** Parameters [s, t] in [0, 1] of the closest points p0 + s (p1 - p0), q0 + t (q1 - q0) of two
 *  segments given by joint indices into a (p) and b (q); written into `out` (training/evaluation/metrics.py
 *  closest_on_segments, for many pairs at once). */
export function closestOnSegments(
  a: Positions, p0: number, p1: number, b: Positions, q0: number, q1: number, out: Float64Array,
): void {
  const d1x = a[3 * p1] - a[3 * p0], d1y = a[3 * p1 + 1] - a[3 * p0 + 1], d1z = a[3 * p1 + 2] - a[3 * p0 + 2];
  const d2x = b[3 * q1] - b[3 * q0], d2y = b[3 * q1 + 1] - b[3 * q0 + 1], d2z = b[3 * q1 + 2] - b[3 * q0 + 2];
  const rx = a[3 * p0] - b[3 * q0], ry = a[3 * p0 + 1] - b[3 * q0 + 1], rz = a[3 * p0 + 2] - b[3 * q0 + 2];
  const aa = d1x * d1x + d1y * d1y + d1z * d1z;
  const e = d2x * d2x + d2y * d2y + d2z * d2z;
  const bb = d1x * d2x + d1y * d2y + d1z * d2z;
  const c = d1x * rx + d1y * ry + d1z * rz;
  const f = d2x * rx + d2y * ry + d2z * rz;
  const denom = aa * e - bb * bb;
  let s = denom > 1e-12 ? clamp01((bb * f - c * e) / denom) : 0;
  let t = e > 1e-12 ? (bb * s + f) / e : 0;
  if (t < 0 || t > 1 || e <= 1e-12) {
    t = clamp01(t);
    s = aa > 1e-12 ? clamp01((bb * t - c) / aa) : 0;
  }
  out[0] = s;
  out[1] = t;
}

const st = new Float64Array(2);

/** Closest distance between the two spines (positions 17 x 3), and in `away` the horizontal unit
 *  direction from b's closest point to a's (the way to push a; b goes the other way). */
export function spineGap(a: Positions, b: Positions, away: Float64Array): number {
  let best = Infinity, ax = 0, az = 0;
  for (let i = 0; i < SPINE.length - 1; i++) {
    for (let j = 0; j < SPINE.length - 1; j++) {
      const p0 = SPINE[i], p1 = SPINE[i + 1], q0 = SPINE[j], q1 = SPINE[j + 1];
      closestOnSegments(a, p0, p1, b, q0, q1, st);
      const s = st[0], t = st[1];
      const dx = a[3 * p0] + s * (a[3 * p1] - a[3 * p0]) - (b[3 * q0] + t * (b[3 * q1] - b[3 * q0]));
      const dy = a[3 * p0 + 1] + s * (a[3 * p1 + 1] - a[3 * p0 + 1]) - (b[3 * q0 + 1] + t * (b[3 * q1 + 1] - b[3 * q0 + 1]));
      const dz = a[3 * p0 + 2] + s * (a[3 * p1 + 2] - a[3 * p0 + 2]) - (b[3 * q0 + 2] + t * (b[3 * q1 + 2] - b[3 * q0 + 2]));
      const dist = Math.hypot(dx, dy, dz);
      if (dist < best) {
        best = dist;
        ax = dx;
        az = dz;
      }
    }
  }
  let n = Math.hypot(ax, az);
  if (n < 1e-6) {
    // One spine right above the other: push along the line between the hips.
    ax = a[0] - b[0];
    az = a[2] - b[2];
    n = Math.hypot(ax, az);
    if (n < 1e-6) {
      ax = 1;
      az = 0;
      n = 1;
    }
  }
  away[0] = ax / n;
  away[1] = 0;
  away[2] = az / n;
  return best;
}

const away = new Float64Array(3);

/** Move both bodies apart (in place) until their spines are SEPARATION apart; returns the distance
 *  each moved (0 when they were apart already). */
export function separate(a: Positions, b: Positions): number {
  const gap = spineGap(a, b, away);
  if (gap >= SEPARATION) return 0;
  const push = (SEPARATION - gap) / 2;
  for (let j = 0; j < a.length / 3; j++) {
    a[3 * j] += away[0] * push;
    a[3 * j + 2] += away[2] * push;
  }
  for (let j = 0; j < b.length / 3; j++) {
    b[3 * j] -= away[0] * push;
    b[3 * j + 2] -= away[2] * push;
  }
  return push;
}

/** Indices into HANDS of the closest hand pair of the two dancers, and its distance ([i, j, d]). */
export function closestHands(a: Positions, b: Positions, out: Float64Array): void {
  out[2] = Infinity;
  for (let i = 0; i < HANDS.length; i++) {
    for (let j = 0; j < HANDS.length; j++) {
      const ha = HANDS[i], hb = HANDS[j];
      const d = Math.hypot(a[3 * ha] - b[3 * hb], a[3 * ha + 1] - b[3 * hb + 1], a[3 * ha + 2] - b[3 * hb + 2]);
      if (d < out[2]) {
        out[0] = i;
        out[1] = j;
        out[2] = d;
      }
    }
  }
}

/** 1 at HAND_FULL and closer, 0 at HAND_REACH and beyond, linear between. */
export function reachWeight(distance: number): number {
  return clamp01((HAND_REACH - distance) / (HAND_REACH - HAND_FULL));
}

/** Two-bone IK of the arm (shoulder - forearm - hand) that ends at `hand`. */
export function moveHand(positions: Positions, hand: number, tx: number, ty: number, tz: number): void {
  const elbow = PARENTS[hand];
  twoBoneIk(positions, PARENTS[elbow], elbow, hand, tx, ty, tz, ELBOW_POLE[0], ELBOW_POLE[1], ELBOW_POLE[2], MIN_ELBOW_BEND);
}

const pair = new Float64Array(3);

/** One dancer's shown path over the floor (HIP_GLIDE): where its hips were shown, the step they
 *  made last, and where the network put them last. */
export class HipGlide {
  /** The shown hips (x, z); NaN: not yet shown. */
  readonly shown = new Float64Array([NaN, NaN]);
  /** The shown hips' last step (x, z). */
  readonly step = new Float64Array(2);
  /** Where the network put the hips last (x, z). */
  readonly network = new Float64Array(2);
  private readonly moved = new Float64Array(2);

  clear(): void {
    this.shown.fill(NaN);
  }

  /** Move the body (world 17 x 3, in place) to its hips' smoothed path over the floor: the shown
   *  hips step by the running mean of the network's steps. Planted feet stay where they are by the
   *  foot locks, applied last. */
  apply(positions: Positions): void {
    const hx = positions[0], hz = positions[2], shown = this.shown, step = this.step, net = this.network;
    if (Number.isNaN(shown[0])) {
      shown[0] = net[0] = hx;
      shown[1] = net[1] = hz;
      step.fill(0);
    }
    step[0] += HIP_GLIDE * (hx - net[0] - step[0]);
    step[1] += HIP_GLIDE * (hz - net[1] - step[1]);
    net[0] = hx;
    net[1] = hz;
    shown[0] += step[0];
    shown[1] += step[1];
    const ox = shown[0] - hx, oz = shown[1] - hz;
    for (let i = 0; i < positions.length; i += 3) {
      positions[i] += ox;
      positions[i + 2] += oz;
    }
  }

  /** How far (x, z) the last apply moved the body from where the network put it. */
  glided(): Float64Array {
    const g = this.moved, shown = this.shown;
    g[0] = Number.isNaN(shown[0]) ? 0 : shown[0] - this.network[0];
    g[1] = Number.isNaN(shown[0]) ? 0 : shown[1] - this.network[1];
    return g;
  }
}

/** State kept between steps: both dancers' glides, foot locks and the hand hold. */
export class ContactLayer {
  readonly leaderFeet = new FootLock(CONTACT_THRESHOLD);
  readonly followerFeet = new FootLock(CONTACT_THRESHOLD);
  /** 0..1: how far the closest hands are drawn together. */
  hold = 0;
  /** The pair held: indices into HANDS of the leader's and the follower's hand. */
  readonly hands = [0, 0];
  /** m each body was moved apart this step. */
  pushed = 0;
  /** Each dancer's path over the floor (HipGlide). */
  readonly leaderGlide = new HipGlide();
  readonly followerGlide = new HipGlide();

  /** Forget every lock, the hold and the glides (after a reset or a jump of either dancer). */
  clear(): void {
    this.leaderFeet.clear();
    this.followerFeet.clear();
    this.hold = 0;
    this.leaderGlide.clear();
    this.followerGlide.clear();
  }

  /** Make the shown poses (world 17 x 3, copies: changed in place) read as partner dancing. */
  apply(
    leader: Positions, follower: Positions, leaderContacts: ArrayLike<number>, followerContacts: ArrayLike<number>,
    leaderHeading: number, followerHeading: number,
  ): void {
    this.leaderGlide.apply(leader);
    this.followerGlide.apply(follower);
    this.pushed = separate(leader, follower);
    closestHands(leader, follower, pair);
    const i = pair[0], j = pair[1], d = pair[2];
    const target = reachWeight(d);
    this.hold += (target - this.hold) * (target > this.hold ? HOLD_RATE : RELEASE_RATE);
    this.hands[0] = i;
    this.hands[1] = j;
    if (this.hold > 1e-3 && d > 1e-6) {
      const hl = HANDS[i], hf = HANDS[j];
      const lx = leader[3 * hl], ly = leader[3 * hl + 1], lz = leader[3 * hl + 2];
      const fx = follower[3 * hf], fy = follower[3 * hf + 1], fz = follower[3 * hf + 2];
      const mx = (lx + fx) / 2, my = (ly + fy) / 2, mz = (lz + fz) / 2;
      const ux = (lx - fx) / d, uy = (ly - fy) / d, uz = (lz - fz) / d;
      const g = GRIP / 2, w = this.hold;
      moveHand(leader, hl, lx + (mx + ux * g - lx) * w, ly + (my + uy * g - ly) * w, lz + (mz + uz * g - lz) * w);
      // The follower's hand goes to where the leader's hand got (an arm too short to reach the
      // midpoint leaves the rest of the way to the partner's arm).
      const rx = leader[3 * hl] - ux * GRIP, ry = leader[3 * hl + 1] - uy * GRIP, rz = leader[3 * hl + 2] - uz * GRIP;
      moveHand(follower, hf, fx + (rx - fx) * w, fy + (ry - fy) * w, fz + (rz - fz) * w);
    }
    this.leaderFeet.apply(leader, leaderContacts, leaderHeading, this.leaderGlide.glided());
    this.followerFeet.apply(follower, followerContacts, followerHeading, this.followerGlide.glided());
  }
}
