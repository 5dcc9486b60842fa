// Mirror of training/mirror/view.py: how the follower sees her leader's height.
//
// Our leader lunges deeper and more often than the recorded one, and beside a deep lunge the
// follower went down with him and fell (docs/results.md, "She follows his lunge down"). So her
// input shows him no lower than the manifest's followerView.partnerHipFloor: when his hips (in the
// pose block) are lower, every height of his pose and past key joints in her input is raised by
// the difference, one rigid lift. His path on the floor, velocities and directions stay; what she
// does still comes from his motion alone. Without the manifest field the input is left as it is.

import { FOLLOWER_INPUT_LAYOUT, blockSlices } from './features';

/** The manifest's "followerView". */
export interface ViewSettings {
  /** Metres: her leader's hips read at least this high. */
  partnerHipFloor: number;
}

const SLICES = blockSlices(FOLLOWER_INPUT_LAYOUT);
export const PARTNER_POSE = SLICES.partner_pose;
export const PARTNER_KEY_JOINTS = SLICES.partner_key_joints_past;
const POSE_WIDTH = 12; // position, velocity, forward, up per joint
const KEY_WIDTH = 3; // a key joint's position

/** Metres her leader's body in the follower input at `at` is to be raised (0: his hips are not below `floor`). */
export function partnerLift(x: ArrayLike<number>, floor: number, at = 0): number {
  return Math.max(0, floor - x[at + PARTNER_POSE.start + 1]);
}

/**
 * Raise, in place, every height of her leader's pose and past key joints in the follower input at
 * `at` by partnerLift, so his hips read at least `floor` metres high. Returns the lift.
 */
export function liftPartner(x: Float32Array, floor: number, at = 0): number {
  const lift = partnerLift(x, floor, at);
  if (lift <= 0) return 0;
  for (let i = at + PARTNER_POSE.start + 1; i < at + PARTNER_POSE.end; i += POSE_WIDTH) x[i] += lift;
  for (let i = at + PARTNER_KEY_JOINTS.start + 1; i < at + PARTNER_KEY_JOINTS.end; i += KEY_WIDTH) x[i] += lift;
  return lift;
}
