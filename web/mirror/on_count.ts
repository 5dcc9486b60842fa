// Mirror of training/mirror/on_count.py: steps on the count.
//
// Both networks hear the music, yet the last second of motion says more about when the next step
// falls than the count does, so left to their own samples each keeps a tempo of its own. A dancer on
// the count moves the feet between beats and lands them on the beat (the recorded footwork, the
// summed speed of both ankles, swings once a beat, lowest where a foot lands). So each step the
// dancer's guard draws `samples` of the network's next step from the same input and takes the
// standing one whose footwork is nearest mean · (1 − strength · cos 2π·count at the next step), where
// mean is the dancer's own footwork over about the last second (simulation.ts). Every candidate is
// the network's own reaction from the same state: nothing jumps, and nobody's input changes. While
// a dancer turns faster than TURNING the network's own sample is taken: a spin moves the ankles fast
// whatever the count, and the pull broke her turns off.

import { FOLLOWER_INPUT_LAYOUT, KEY_STEP, KEYS, LEADER_INPUT_LAYOUT, OUTPUT_LAYOUT, POSE_SIZE, blockSlices } from './features';
import { MUSIC_OFFSETS, MUSIC_SIZE } from './music';
import { FEET, FPS, N_JOINTS } from './skeleton';

export const SAMPLES = 8;
export const STRENGTH = 1.0;
export const MEAN_SECONDS = 1.0;
/** rad/s: faster than this the dancer is in a turn, left to the network (a spin: 6-9). */
export const TURNING = 3.0;

/** The manifest's "onCount": samples each step, and how far the footwork aimed at swings (0-1). */
export interface OnCountSettings {
  samples: number;
  strength: number;
}

export type Role = 'leader' | 'follower';

const POSE_JOINT = POSE_SIZE / N_JOINTS;
const NOW_KEY = MUSIC_OFFSETS.indexOf(0) * 4;
export const ANKLE_VELOCITY_IN: Readonly<Record<Role, readonly number[]>> = {
  leader: FEET.map((j) => blockSlices(LEADER_INPUT_LAYOUT).self_pose.start + POSE_JOINT * j + 3),
  follower: FEET.map((j) => blockSlices(FOLLOWER_INPUT_LAYOUT).self_pose.start + POSE_JOINT * j + 3),
};
/** The facing of the dancer's newest past trajectory key (KEY_STEP frames ago) in its root space now. */
export const LAST_FACING: Readonly<Record<Role, number>> = {
  leader: blockSlices(LEADER_INPUT_LAYOUT).self_trajectory_past.start + (KEYS - 1) * 4 + 2,
  follower: blockSlices(FOLLOWER_INPUT_LAYOUT).self_trajectory_past.start + (KEYS - 1) * 4 + 2,
};
export const ANKLE_VELOCITY_OUT: readonly number[] = FEET.map((j) => blockSlices(OUTPUT_LAYOUT).pose.start + POSE_JOINT * j + 3);

function speedAt(x: ArrayLike<number>, c: number): number {
  return Math.hypot(x[c], x[c + 1], x[c + 2]);
}

/** The dancer's footwork now (m/s: the summed speed of both ankles) from its input. */
export function footworkNow(input: ArrayLike<number>, role: Role): number {
  let sum = 0;
  for (const c of ANKLE_VELOCITY_IN[role]) sum += speedAt(input, c);
  return sum;
}

/** The footwork the output at output[at..] would draw at the next step. */
export function footworkNext(output: ArrayLike<number>, at = 0): number {
  let sum = 0;
  for (const c of ANKLE_VELOCITY_OUT) sum += speedAt(output, at + c);
  return sum;
}

/** How fast the dancer turns now (rad/s, unsigned): its facing KEY_STEP frames ago, seen from its root now. */
export function turnRate(input: ArrayLike<number>, role: Role): number {
  const c = LAST_FACING[role];
  return (Math.abs(Math.atan2(input[c], input[c + 1])) * FPS) / KEY_STEP;
}

/** The count at the next step (beats, its fraction only) from the music block ending the input. */
export function countNext(input: ArrayLike<number>): number {
  const music = input.length - MUSIC_SIZE;
  const now = Math.atan2(input[music + NOW_KEY], input[music + NOW_KEY + 1]) / (2 * Math.PI);
  return now + input[input.length - 1] / FPS;
}

/** One dancer's footwork mean, kept across steps, and the footwork its next step aims at. */
export class OnCount {
  mean: number | null = null;

  constructor(
    readonly role: Role,
    readonly samples: number = SAMPLES,
    readonly strength: number = STRENGTH,
  ) {
    if (samples < 2) throw new Error('choosing on the count needs at least 2 samples');
  }

  /** The footwork the next step aims at, for this step's input (it moves the mean on); null while
   *  the dancer turns faster than TURNING (the network's own sample is taken). */
  target(input: ArrayLike<number>): number | null {
    const now = footworkNow(input, this.role);
    this.mean = this.mean === null ? now : this.mean + (now - this.mean) / (MEAN_SECONDS * FPS);
    if (turnRate(input, this.role) > TURNING) return null;
    return this.mean * (1 - this.strength * Math.cos(2 * Math.PI * countNext(input)));
  }
}

/**
 * The index of the output (of `count` laid `size` apart) whose footwork is nearest the target among
 * those standing (their upright margins, guard.ts) at least `margin` inside the range; -1 when none does.
 */
export function nearestCount(
  output: ArrayLike<number>, count: number, size: number, target: number, standing: ArrayLike<number>, margin: number,
): number {
  let best = -1;
  let bestMiss = Infinity;
  for (let i = 0; i < count; i++) {
    if (!(standing[i] >= margin)) continue;
    const miss = Math.abs(footworkNext(output, i * size) - target);
    if (miss < bestMiss) {
      best = i;
      bestMiss = miss;
    }
  }
  return best;
}
