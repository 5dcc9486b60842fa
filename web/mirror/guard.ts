// Mirror of training/mirror/guard.py: the dancers' upright guard, the follower's first.
//
// When the body a follower's step would draw (the decoded hip and joint rotations through its
// bones, lifted as applyOutput lifts it) comes within the manifest's margin of the recording's
// range (hips low, head low over the hips, feet too wide, the torso leaning further than the
// recording's steepest), the page runs the same input again with fresh Gumbel draws and takes the
// most upright sample (simulation.ts). Every candidate is one step on from the same state, so the
// body never jumps; the guard only chooses among the network's own reactions. Measured in Python:
// it chose in 210 of 1.8 M follower steps of the 100 x 10 min soak (docs/reliability.md). A
// manifest's leaderGuard.headMargin judges the leader's head over his hips from a smaller margin
// (0.03 m shipped), except while he leads a turn, and its leaderGuard.hipMargin his hips from a
// larger one (0.10 m: a crouch caught before it is too deep); its guard.hipMargin judges the
// follower's hips from a larger one (0.20 m shipped): her hips drop fast when
// she falls (guard.py, LEADER_HEAD_MARGIN and FOLLOWER_HIP_MARGIN).
// A manifest's leaderGuard.keepPlan keeps his lead hand to a request's hands plan: while his input
// shows one, every step draws the samples and, among the keepPlan standing ones whose lead hand is
// nearest the plan's height one step on (nearPlan), takes the one on the count (nearestPlan when
// keepPlan is 1; guard.py, LEADER_KEEP_PLAN).

import { KEY_STEP, LEADER_INPUT_LAYOUT, LEADER_INPUT_SIZE, N_JOINTS, OUTPUT_LAYOUT, blockSlices } from './features';
import { MIN_ANKLE_HEIGHT, rotationsFromVectors } from './rollout';
import { FEET, HANDS, HEAD, forwardKinematicsReduced } from './skeleton';

/** The chest joint, whose offset over the hips is the torso's lean (evaluation/plausibility.py CHEST). */
export const CHEST = 2;

/** The recording's range as the manifest carries it ("plausibility", evaluation/plausibility.py). */
export interface Ranges {
  hip_low: number;
  head_above_hip_low: number;
  feet_wide: number;
  /** Highest bend of each measured angle; the last is the torso's lean. */
  angle_high: number[];
}

/** The manifest's "guard": fresh samples to choose among, and metres before the range's edge it acts. */
export interface GuardSettings {
  samples: number;
  margin: number;
  /** The leader's: metres before the edge of the head over the hips (a narrow range) it acts. */
  headMargin?: number;
  /** Metres before the edge of the hips it acts: hers drop fast once she falls, his in a crouch
   *  that no sample brings back up once it is low (guard.py, LEADER_HIP_MARGIN). */
  hipMargin?: number;
  /** The leader's: while a request runs, keep his lead hand to its plan: the sample on the count
   *  among the keepPlan standing ones nearest it (nearPlan; 1 or true: the nearest, nearestPlan). */
  keepPlan?: number | boolean;
}

const POSE = blockSlices(OUTPUT_LAYOUT).pose;
/** The leader input's column that is 1 while a request runs (the hands plan's "shown"). */
export const HANDS_PLAN_SHOWN = blockSlices(LEADER_INPUT_LAYOUT).hands_plan.start;
/** In a leader's input: each hand's height now (his own pose block, y, his root space), left then right. */
export const HAND_HEIGHTS: readonly number[] = HANDS.map((h) => blockSlices(LEADER_INPUT_LAYOUT).self_pose.start + 12 * h + 1);
/** ... and its planned move to the first future key (the hands plan's first key, y). */
export const HAND_PLAN_FIRST: readonly number[] = HANDS.map((_, k) => HANDS_PLAN_SHOWN + 1 + 3 * k + 1);
const forward = new Float64Array(3 * N_JOINTS);
const up = new Float64Array(3 * N_JOINTS);
const rotations = new Float64Array(9 * N_JOINTS);
const joints = new Float64Array(3 * N_JOINTS);

/** The body output[at..] (raw, 323) draws, into `joints`: the decoded hip and joint rotations
 *  through the dancer's bones in the next root's space, before applyOutput's lift (returned). */
function drawnJoints(output: ArrayLike<number>, at: number, offsets: ArrayLike<number>): number {
  const pose = at + POSE.start;
  for (let j = 0; j < N_JOINTS; j++) {
    for (let k = 0; k < 3; k++) {
      forward[3 * j + k] = output[pose + 12 * j + 6 + k];
      up[3 * j + k] = output[pose + 12 * j + 9 + k];
    }
  }
  rotationsFromVectors(forward, up, N_JOINTS, rotations, 0);
  forwardKinematicsReduced(offsets, output, pose, rotations, 0, joints, 0);
  // applyOutput's lift: a body whose ankles would go below the floor is raised whole.
  return Math.max(MIN_ANKLE_HEIGHT - Math.min(joints[3 * FEET[0] + 1], joints[3 * FEET[1] + 1]), 0);
}

/**
 * Metres by which the body that output[at..] (raw, 323) draws stays inside the recording's range on
 * hips, head over hips, feet apart and the torso's lean (negative: that far outside). The pose is
 * in the next root's space, whose y is the height above the floor; the lean is how far the chest
 * may still move sideways over the hips before the torso leans more than the recording's steepest.
 * `headSlack` metres are added to the head-over-hips part alone, `hipSlack` to the hips' part alone.
 */
export function uprightMargin(
  output: ArrayLike<number>, at: number, r: Ranges, offsets: ArrayLike<number>, headSlack = 0, hipSlack = 0,
): number {
  return drawnMargin(drawnJoints(output, at, offsets), r, headSlack, hipSlack);
}

/**
 * uprightMargin of output[at..], the body it draws copied into `body` [17 · 3], lifted (guard.py
 * drawn_joints then drawn_margin): the choice on the count reads that body's steps (on_count.ts).
 */
export function uprightBody(
  output: ArrayLike<number>, at: number, r: Ranges, offsets: ArrayLike<number>, headSlack: number, hipSlack: number, body: Float64Array,
): number {
  const lift = drawnJoints(output, at, offsets);
  for (let i = 0; i < joints.length; i++) body[i] = joints[i] + (i % 3 === 1 ? lift : 0);
  return drawnMargin(lift, r, headSlack, hipSlack);
}

/** uprightMargin of the body drawnJoints last left in `joints`, lifted by `lift`. */
function drawnMargin(lift: number, r: Ranges, headSlack: number, hipSlack: number): number {
  const hip = joints[1] + lift;
  const head = joints[3 * HEAD + 1] + lift;
  const feet = Math.hypot(
    joints[3 * FEET[0]] - joints[3 * FEET[1]],
    joints[3 * FEET[0] + 1] - joints[3 * FEET[1] + 1],
    joints[3 * FEET[0] + 2] - joints[3 * FEET[1] + 2],
  );
  const tx = joints[3 * CHEST] - joints[0];
  const ty = joints[3 * CHEST + 1] - joints[1];
  const tz = joints[3 * CHEST + 2] - joints[2];
  const sideways = Math.hypot(tx, tz);
  const allowed = Math.hypot(tx, ty, tz) * Math.sin(r.angle_high[r.angle_high.length - 1]);
  return Math.min(hip - r.hip_low + hipSlack, head - hip - r.head_above_hip_low + headSlack, r.feet_wide - feet, allowed - sideways);
}

/** Whether this is a leader's input that shows a hands plan (a request runs). */
export function showsPlan(input: ArrayLike<number>): boolean {
  return input.length === LEADER_INPUT_SIZE && input[HANDS_PLAN_SHOWN] >= 0.5;
}

/**
 * Metres by which the lead hand that output[at..] draws misses the height the hands plan in the
 * leader's `input` puts it at one step on (a KEY_STEP-th of its move to the first key). The lead
 * hand is the one the plan puts higher at that key. Height alone: it is the same in this root's
 * space and the next one's, and it is what she sees rise.
 */
export function leadHandMiss(output: ArrayLike<number>, at: number, input: ArrayLike<number>, offsets: ArrayLike<number>): number {
  return drawnMiss(drawnJoints(output, at, offsets), input);
}

/** leadHandMiss of the body drawnJoints last left in `joints`, lifted by `lift`. */
function drawnMiss(lift: number, input: ArrayLike<number>): number {
  const lead = input[HAND_HEIGHTS[1]] + input[HAND_PLAN_FIRST[1]] > input[HAND_HEIGHTS[0]] + input[HAND_PLAN_FIRST[0]] ? 1 : 0;
  const target = input[HAND_HEIGHTS[lead]] + input[HAND_PLAN_FIRST[lead]] / KEY_STEP;
  return Math.abs(joints[3 * HANDS[lead] + 1] + lift - target);
}

/**
 * The index of the `count` outputs from output[0..] whose lead hand is nearest the plan
 * (leadHandMiss) among those standing at least `margin` inside the range; the most upright when
 * none does. Each sample's body is drawn once for both judgements (this runs every step of a request).
 */
export function nearestPlan(
  output: ArrayLike<number>, count: number, size: number, input: ArrayLike<number>, r: Ranges, offsets: ArrayLike<number>,
  margin: number, headSlack = 0, hipSlack = 0,
): number {
  let best = -1;
  let bestMiss = Infinity;
  for (let i = 0; i < count; i++) {
    const lift = drawnJoints(output, i * size, offsets);
    if (drawnMargin(lift, r, headSlack, hipSlack) < margin) continue;
    const miss = drawnMiss(lift, input);
    if (miss < bestMiss) {
      best = i;
      bestMiss = miss;
    }
  }
  return best >= 0 ? best : mostUpright(output, count, size, r, offsets, headSlack, hipSlack);
}

const misses: number[] = [];

/**
 * near_plan in guard.py: marks in `near` [count] the `n` outputs standing at least `margin` inside
 * the range whose lead hand is nearest the plan (fewer when fewer stand), the others false. Ties go
 * to the earlier sample, as numpy's stable argsort does.
 */
export function nearPlan(
  output: ArrayLike<number>, count: number, size: number, input: ArrayLike<number>, r: Ranges, offsets: ArrayLike<number>,
  margin: number, n: number, near: boolean[], headSlack = 0, hipSlack = 0,
): void {
  for (let i = 0; i < count; i++) {
    const lift = drawnJoints(output, i * size, offsets);
    misses[i] = drawnMargin(lift, r, headSlack, hipSlack) >= margin ? drawnMiss(lift, input) : Infinity;
    near[i] = false;
  }
  for (let picked = 0; picked < n; picked++) {
    let best = -1;
    for (let i = 0; i < count; i++) if (!near[i] && misses[i] < Infinity && (best < 0 || misses[i] < misses[best])) best = i;
    if (best < 0) return;
    near[best] = true;
  }
}

/**
 * Metres a guard lets off the head-over-hips part for this input: margin - headMargin; none when
 * it has no headMargin, or while the input is a leader's that shows a hands plan (he leads a turn).
 */
export function slackFor(input: ArrayLike<number>, margin: number, headMargin?: number): number {
  if (headMargin === undefined) return 0;
  if (showsPlan(input)) return 0;
  return margin - headMargin;
}

/** Metres a guard adds to the hips' part (negative: they are judged from a larger margin):
 *  margin - hipMargin; none without a hipMargin (guard.py hip_slack_for). */
export function hipSlackFor(margin: number, hipMargin?: number): number {
  return hipMargin === undefined ? 0 : margin - hipMargin;
}

/** The index of the most upright of `count` outputs laid one after another from output[0..]. */
export function mostUpright(
  output: ArrayLike<number>, count: number, size: number, r: Ranges, offsets: ArrayLike<number>, headSlack = 0, hipSlack = 0,
): number {
  let best = 0;
  let bestMargin = -Infinity;
  for (let i = 0; i < count; i++) {
    const m = uprightMargin(output, i * size, r, offsets, headSlack, hipSlack);
    if (m > bestMargin) {
      best = i;
      bestMargin = m;
    }
  }
  return best;
}
