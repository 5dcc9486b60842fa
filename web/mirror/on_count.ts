// Mirror of training/mirror/on_count.py: steps on the count, the hips going on.
//
// Both networks hear the music, yet the last second of motion says more about when the next step
// falls than the count does, so left to their own samples each keeps a tempo of its own. A dancer on
// the count moves the feet between beats and lands them on the beat (the recorded footwork, the
// summed speed of both ankles, swings once a beat, lowest where a foot lands). So each step the
// dancer's guard draws `samples` of the network's next step from the same input, draws each body as
// the page will (its bones, carried by its root update), and takes the standing one whose footwork
// is nearest mean · (1 − strength · cos 2π·count at the next step), where mean is the dancer's own
// footwork over about the last second. The footwork is read from the drawn ankles, not from the
// velocities the network writes beside them, which follow the drawn ankles only loosely. A sample
// whose hips turn back the way they came has `hips` m/s added to its miss: the networks' own hips
// turn back far more often than the recorded dancers'. While a dancer turns faster than TURNING (a
// fast spin), its footwork is left to the network and only its hips are weighed. Outside a turn the
// choice also reads the figure being led (the input's figure block, what the hands carry; figureTurn,
// FIGURE_TURN): while a turn of the dancer's own runs or begins within FIGURE_AHEAD keys (hers for the
// follower, his own for the leader), the candidates whose planned path turns FIGURE_TURN degrees or
// more its way are preferred; while no figure runs or comes, those that turn less either way. Read by
// the networks alone, the figure moved her turns little (on_count.py has the numbers). The feet are
// read as the contact layer draws them: a
// foot the network calls planted, which the layer locks, counts as still, in each candidate and in the
// dancer's footwork now (the feet of the step last taken, OnCount.took); the networks' feet move while
// they call them planted, and a choice that read them where the network drew them timed the steps by
// feet the page holds still (on_count.py has the numbers).

import {
  FIGURE_KINDS, FIGURE_OFFSETS, FOLLOWER_INPUT_LAYOUT, type FigureName, KEY_STEP, KEYS, LEADER_INPUT_LAYOUT, OUTPUT_LAYOUT, POSE_SIZE,
  blockSlices,
} from './features';
import { CONTACT_THRESHOLD } from './footik';
import { MUSIC_OFFSETS, MUSIC_SIZE } from './music';
import { FEET, FPS, N_JOINTS } from './skeleton';

export const SAMPLES = 8;
export const STRENGTH = 1.0;
export const MEAN_SECONDS = 1.0;
/** rad/s: turning faster than this, the dancer's footwork is left to the network: his turns are
 *  walks round (1.5-3 rad/s), hers spins (6-9). */
export const TURNING: Readonly<Record<Role, number>> = { leader: 1.5, follower: 6.0 };
/** m/s added to the footwork's miss of a candidate whose hips turn back. */
export const HIPS = 1.0;
/** m a frame (6 cm/s): a shorter step of the hips stands still, and turns no way. */
export const STILL = 0.002;
/** Degrees over the next second: a candidate whose planned path turns this much starts a turn. */
export const FIGURE_TURN = 120.0;
/** Future keys (of KEY_STEP frames) within which a figure coming counts as running. */
export const FIGURE_AHEAD = 2;

/** The manifest's "onCount": samples each step, how far the footwork aimed at swings (0-1), what
 *  a candidate whose hips turn back adds to its miss (m/s; HIPS when absent), and the turn (degrees)
 *  the figure being led asks of a candidate (FIGURE_TURN; absent or 0: the figure is not read). */
export interface OnCountSettings {
  samples: number;
  strength: number;
  hips?: number;
  figureTurn?: number;
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
/** The joints whose steps the choice reads, the hips and both ankles, and where each role's input
 *  holds their positions (its own pose block, its root space now); the hips' velocity follows theirs. */
export const STEPPED: readonly number[] = [0, ...FEET];
export const POSITION_IN: Readonly<Record<Role, readonly number[]>> = {
  leader: STEPPED.map((j) => blockSlices(LEADER_INPUT_LAYOUT).self_pose.start + POSE_JOINT * j),
  follower: STEPPED.map((j) => blockSlices(FOLLOWER_INPUT_LAYOUT).self_pose.start + POSE_JOINT * j),
};
const ROOT_UPDATE_OUT = blockSlices(OUTPUT_LAYOUT).root_update.start;
const CONTACTS_OUT = blockSlices(OUTPUT_LAYOUT).contacts.start;
/** Where each role's input holds the figure block (features.ts figureBlock). */
export const FIGURE_IN: Readonly<Record<Role, number>> = {
  leader: blockSlices(LEADER_INPUT_LAYOUT).figure.start,
  follower: blockSlices(FOLLOWER_INPUT_LAYOUT).figure.start,
};
/** The figure kinds that are the dancer's own turn: hers for the follower, his own for the leader. */
export const OWN_TURN: Readonly<Record<Role, FigureName>> = { leader: 'his_turn', follower: 'her_turn' };
const NOW_FIGURE_KEY = FIGURE_OFFSETS.indexOf(0);

function speedAt(x: ArrayLike<number>, c: number): number {
  return Math.hypot(x[c], x[c + 1], x[c + 2]);
}

/** Which feet (left, right) output[at..] plants, into `feet`: its contact above the contact layer's
 *  CONTACT_THRESHOLD, where footik.ts FootLock locks the drawn foot. */
export function planted(output: ArrayLike<number>, at: number, feet: boolean[]): boolean[] {
  feet[0] = output[at + CONTACTS_OUT] > CONTACT_THRESHOLD;
  feet[1] = output[at + CONTACTS_OUT + 1] > CONTACT_THRESHOLD;
  return feet;
}

/** The dancer's footwork now (m/s: the summed speed of both ankles) from its input; a foot `still`
 *  says is planted counts 0. */
export function footworkNow(input: ArrayLike<number>, role: Role, still: ArrayLike<boolean> | null = null): number {
  const ankles = ANKLE_VELOCITY_IN[role];
  let sum = 0;
  for (let k = 0; k < ankles.length; k++) if (still === null || !still[k]) sum += speedAt(input, ankles[k]);
  return sum;
}

/**
 * How far the hips and each ankle move (m, in the dancer's root space now) from where the input has
 * them to where output[at..] draws them, into steps [3 · 3]: `body` [17 · 3] is the body it draws
 * (guard.ts uprightBody, in the next root's space), carried by the output's root update.
 */
export function drawnSteps(
  output: ArrayLike<number>, at: number, body: ArrayLike<number>, input: ArrayLike<number>, role: Role, steps: Float64Array,
): Float64Array {
  const dx = output[at + ROOT_UPDATE_OUT];
  const dz = output[at + ROOT_UPDATE_OUT + 1];
  const turn = output[at + ROOT_UPDATE_OUT + 2];
  const c = Math.cos(turn);
  const s = Math.sin(turn);
  for (let n = 0; n < STEPPED.length; n++) {
    const j = 3 * STEPPED[n];
    const now = POSITION_IN[role][n];
    // features.ts fromRootSpaceDirections by the turn: the next root's space seen from this one.
    steps[3 * n] = c * body[j] + s * body[j + 2] + dx - input[now];
    steps[3 * n + 1] = body[j + 1] - input[now + 1];
    steps[3 * n + 2] = -s * body[j] + c * body[j + 2] + dz - input[now + 2];
  }
  return steps;
}

/** The footwork (m/s) of the steps drawnSteps gives: the summed speed of both ankles, a foot `still`
 *  says is planted counting 0. */
export function drawnFootwork(steps: ArrayLike<number>, still: ArrayLike<boolean> | null = null): number {
  const left = still !== null && still[0] ? 0 : Math.hypot(steps[3], steps[4], steps[5]);
  const right = still !== null && still[1] ? 0 : Math.hypot(steps[6], steps[7], steps[8]);
  return (left + right) * FPS;
}

/** Whether the steps drawnSteps gives take the hips back the way they came: more than 90 degrees
 *  from their step into this frame (the input's own hip velocity), both longer than STILL. */
export function hipsTurnBack(steps: ArrayLike<number>, input: ArrayLike<number>, role: Role): boolean {
  const v = POSITION_IN[role][0] + 3;
  const bx = input[v] / FPS;
  const by = input[v + 1] / FPS;
  const bz = input[v + 2] / FPS;
  return steps[0] * bx + steps[1] * by + steps[2] * bz < 0 && Math.hypot(steps[0], steps[1], steps[2]) > STILL && Math.hypot(bx, by, bz) > STILL;
}

/** How fast and which way the dancer turns now (rad/s, signed as the output's root update turns): its
 *  facing KEY_STEP frames ago, seen from its root now, lies the other way. */
export function turnNow(input: ArrayLike<number>, role: Role): number {
  const c = LAST_FACING[role];
  return (-Math.atan2(input[c], input[c + 1]) * FPS) / KEY_STEP;
}

/** How fast the dancer turns now (rad/s, unsigned): turnNow's size. */
export function turnRate(input: ArrayLike<number>, role: Role): number {
  return Math.abs(turnNow(input, role));
}

const FUTURE_OUT = blockSlices(OUTPUT_LAYOUT).trajectory_future.start;

/** How far output[at..]'s planned path turns over the next second (degrees, signed as the root update
 *  turns): its facing at each future key (sin, cos), from 0 now, summed key to key so that a whole
 *  turn counts whole. */
export function plannedTurn(output: ArrayLike<number>, at: number): number {
  let before = 0;
  let sum = 0;
  for (let k = 0; k < KEYS; k++) {
    const c = at + FUTURE_OUT + 4 * k;
    const h = Math.atan2(output[c + 2], output[c + 3]);
    sum += Math.atan2(Math.sin(h - before), Math.cos(h - before));
    before = h;
  }
  return (sum * 180) / Math.PI;
}

/** Whether output[at..] starts a turn: its planned path turns `degrees` or more over the next second,
 *  either way. */
export function startsTurn(output: ArrayLike<number>, at: number, degrees: number): boolean {
  return Math.abs(plannedTurn(output, at)) >= degrees;
}

/** The dancer's own turn the input's figure block says runs now or begins within FIGURE_AHEAD keys:
 *  its way (+1, -1); 0 when another figure runs or comes (her turn, for him); null when none does. */
export function figureWay(input: ArrayLike<number>, role: Role): number | null {
  const kinds = FIGURE_KINDS.length;
  const last = Math.min(NOW_FIGURE_KEY + FIGURE_AHEAD, FIGURE_OFFSETS.length - 1);
  let any = false;
  for (let k = 0; k < kinds; k++) {
    let inside = false;
    for (let key = NOW_FIGURE_KEY; key <= last; key++) if (input[FIGURE_IN[role] + 2 * (key * kinds + k)] > 0) inside = true;
    if (!inside) continue;
    if (FIGURE_KINDS[k][0] === OWN_TURN[role]) return FIGURE_KINDS[k][1];
    any = true;
  }
  return any ? 0 : null;
}

/** The count at the next step (beats, its fraction only) from the music block ending the input. */
export function countNext(input: ArrayLike<number>): number {
  const music = input.length - MUSIC_SIZE;
  const now = Math.atan2(input[music + NOW_KEY], input[music + NOW_KEY + 1]) / (2 * Math.PI);
  return now + input[input.length - 1] / FPS;
}

/** One dancer's footwork mean, kept across steps, and the footwork its next step aims at.
 *  `figureTurn` (null: the figure not read): outside a turn, the candidates the figure being led
 *  asks for are preferred (prefers). */
export class OnCount {
  mean: number | null = null;
  /** The feet planted in the step last taken (took); null before the first. */
  feet: boolean[] | null = null;
  /** This step the dancer turns faster than its TURNING. */
  turning = false;

  constructor(
    readonly role: Role,
    readonly samples: number = SAMPLES,
    readonly strength: number = STRENGTH,
    readonly hips: number = HIPS,
    readonly figureTurn: number | null = null,
  ) {
    if (samples < 2) throw new Error('choosing on the count needs at least 2 samples');
    if (figureTurn !== null && !(figureTurn > 0)) throw new Error(`figureTurn must be more than 0 degrees, got ${figureTurn}`);
  }

  /** The footwork the next step aims at, for this step's input (it moves the mean on); null while
   *  the dancer turns faster than its TURNING (its footwork is left to the network). */
  target(input: ArrayLike<number>): number | null {
    const now = footworkNow(input, this.role, this.feet);
    this.mean = this.mean === null ? now : this.mean + (now - this.mean) / (MEAN_SECONDS * FPS);
    this.turning = turnRate(input, this.role) > TURNING[this.role];
    if (this.turning) return null;
    return this.mean * (1 - this.strength * Math.cos(2 * Math.PI * countNext(input)));
  }

  /** Forget the dancer's footwork and feet before a new duet (its first step starts the mean). */
  restart(): void {
    this.mean = null;
    this.feet = null;
  }

  /** The step the dancer took (output[at..]): the feet it plants count as still in the footwork now
   *  of the next step's target. */
  took(output: ArrayLike<number>, at = 0): void {
    this.feet = planted(output, at, this.feet ?? [false, false]);
  }

  /** Outside a turn, which of `count` candidates laid one after another in `output` are preferred,
   *  written into `prefers`: with figureTurn and the step's `input`, those that turn figureTurn
   *  degrees or more the way of the dancer's own turn the figure says runs or comes, or, no figure
   *  running or coming, those that start no turn (figureWay; another figure: none preferred).
   *  Returns false (no candidate preferred) otherwise. */
  prefers(output: ArrayLike<number>, count: number, size: number, prefers: boolean[], input: ArrayLike<number> | null = null): boolean {
    if (this.turning || this.figureTurn === null || input === null) return false;
    const way = figureWay(input, this.role);
    if (way === 0) return false;
    for (let i = 0; i < count; i++) {
      prefers[i] = way === null ? !startsTurn(output, i * size, this.figureTurn) : plannedTurn(output, i * size) * way >= this.figureTurn;
    }
    return true;
  }
}

/**
 * The index of the candidate (of `count`) whose drawn footwork (m/s) is nearest the target, `hips`
 * m/s added to the miss of each whose hips turn back (hipsTurnBack), among those standing (their
 * upright margins, guard.ts) at least `margin` inside the range; -1 when none does. With no target
 * (the dancer turns) the footwork is left alone: the first standing one whose hips go on. With
 * `prefers` (OnCount.prefers: the candidates the figure asks for), only the standing ones among them
 * are aimed when there are any; otherwise all the standing ones, as without it.
 */
export function nearestCount(
  footwork: ArrayLike<number>, turnBack: ArrayLike<boolean>, count: number, target: number | null, standing: ArrayLike<number>,
  margin: number, hips = HIPS, prefers: ArrayLike<boolean> | null = null,
): number {
  let preferred = false;
  if (prefers !== null) {
    for (let i = 0; i < count; i++) if (standing[i] >= margin && prefers[i]) preferred = true;
  }
  let best = -1;
  let bestMiss = Infinity;
  for (let i = 0; i < count; i++) {
    if (!(standing[i] >= margin) || (preferred && !prefers![i])) continue;
    const miss = (target === null ? 0 : Math.abs(footwork[i] - target)) + (turnBack[i] ? hips : 0);
    if (miss < bestMiss) {
      best = i;
      bestMiss = miss;
    }
  }
  return best;
}
