// Mirror of training/mirror/rollout.py: the duet at run time.
//
// Each dancer is a `Track` of 61 frames: 30 past, the current frame at index NOW = 30, and 30 slots
// of planned future of which only the key frames (NOW+5, ..., NOW+30) are filled. The features are
// the very functions training used, read at frame NOW, so training and run time cannot differ.
//
// One step: the leader's plan is its last predicted future bent toward the user's steering; both
// models read the current state (the follower sees that plan as the leader's future); both outputs
// move their dancer one frame on. Absurd output (non-finite, a joint > 3 m from the root, a root
// jump > 1 m) resets that dancer beside its partner and is counted, never drawn.
//
// Differences from Python, none of which changes a number: a duet has a list of followers (two in
// compare mode, each reacting to the same leader; the leader reacts to the first); outputs are
// read at an offset so batched (ghost) results need no copies; scratch arrays are preallocated.
// One that does: Figures.rng is the page's seeded uniform generator (web/engine/random.ts), not
// numpy's, so one seed draws other own figures here than in Python (the same draws, in the same
// order, from other numbers). The page's Simulation (policies in, views out) is simulation.ts; its
// step is Python's step: planFigures, steerPlan, leadPlan, stepInputs, the models, finishStep.

import {
  FIGURE_SIZE, type FigureName, FUTURE_OFFSETS, HISTORY, INTENTION_SIZE, KEYS, N_JOINTS, OUTPUT_LAYOUT, OUTPUT_SIZE, Track,
  blockSlices, figureBlock, figureKind, followerInput, fromRootSpaceDirections, fromRootSpacePoints, leaderInput, toRootSpacePoints, wrapAngle,
} from './features';
import { FEET, FPS, HANDS, KEY_JOINTS, type Out, PARENTS, POSITIONS_SIZE, ROTATIONS_SIZE, forwardKinematicsReduced } from './skeleton';
import { DEFAULT_TEMPO, MUSIC_SIZE, beatsPerStep, musicBlock } from './music';
import { createUniform } from '../engine/random';

export const NOW = HISTORY;
export const TRACK_FRAMES = 2 * HISTORY + 1;
const OUT = blockSlices(OUTPUT_LAYOUT);

// m/s of the steered path at full stick (the recorded leaders cover 0.49 m in a second at the
// median and 0.96 m at the 90th percentile).
export const MAX_SPEED = 0.8;
export const STEER_HALFLIFE = 0.25; // s for the steered velocity to get halfway to the stick's
export const MAX_JOINT_DISTANCE = 3.0; // m from the root: beyond this the output is absurd
export const MAX_ROOT_JUMP = 1.0; // m in one step
export const MIN_ANKLE_HEIGHT = 0.04; // m: the lowest ankle height in the recordings
export const ANCHOR_RATE = 0.3; // share of the leader's distance to its anchor closed every free frame
export const ANCHOR_FREE = 0.75; // m around the anchor where a leader nobody steers is not drawn at all
export const LEASH_DISTANCE = 2.0; // m: beyond this a follower is drawn toward its leader ...
export const LEASH_RATE = 0.1; // ... closing this share of the excess every frame
export const START_DISTANCE = 0.8; // m between the partners at the start and after a reset
// The figures both dancers read (features figureBlock, Figures): her turn, from his preparation to
// her finish, or his own turn, one way or the other, FIGURE_BEATS long. In the recording her turns
// last a median 3.3 beats (10-90 %: 2.0-8.2), 16.9 a minute, his 2.0 beats, 6.3 a minute, and both
// start anywhere in the two-beat group: a figure the visitor asks for (her turn) starts on the next
// whole beat (under 0.4 s of waiting at 170 beats a minute), or when the figure running ends.
// Nobody asking, the leader leads figures of his own (Figures.own): after each figure he waits
// OWN_GAP_BEATS (drawn uniformly) and leads the next, his own turn in HIS_SHARE of them, either way
// alike: a figure every 7.2 beats on average (the wait for a beat included), as the recorded 23 a
// minute at 170 (16.9 hers, 6.3 his; planFigures alone for an hour: 16.9 and 6.6).
export const FIGURE_BEATS: Readonly<Record<FigureName, number>> = { her_turn: 3.5, his_turn: 2.0 };
export const OWN_GAP_BEATS: readonly number[] = [0.5, 6.5];
export const HIS_SHARE = 0.27;
// A figure also becomes his hands plan (features handsPlanBlock): his lead hand (the left for
// her turn to the left, +1, the right for -1) rises above his head and comes down again, the other
// stays where it was. In the recording (training.evaluation.recorded_leads) his higher hand peaks
// above 1.6 m in 84 % of her turns (median 1.83 m; in 17 % of all frames), a third of a second
// before the turn completes: the left hand for 60 % of her turns to the left, at (0.02, 1.80, 0.28)
// m in his root space (x to his left, z ahead), the right hand mirrored for her turns to the right.
// RAISE: (up, down) in s: his hand goes up over the figure's first `up` seconds, is held until the
// figure ends and comes down over `down` after it. The plan asks 1.90 m, above the recorded 1.80:
// the network stops short of a planned hand (a median 1.76 m asked for 1.90). In the recording the
// hand also circles the way she turns; a planned circle (12 or 25 cm) left his hand's path as it
// was, so the plan holds none (docs/results.md, "The hands plan").
export const LEAD_HAND_RAISED: readonly number[] = [0.02, 1.9, 0.28]; // m, the left hand, root space
export const RAISE: readonly number[] = [0.4, 0.5]; // s
// Her turn also bends his planned path (leadPlan): it turns LEAD_TURN her way and moves LEAD_SIDE
// to his other side (his right for her turn to the left), eased as her planned turn (his own turn
// turns his plan a full turn his way). The recorded
// leader turns with her (over the 2.5 s from 1.7 s before her turn completes, his facing goes her
// way by a median 38 degrees, quartiles -103 and +205), and she reads the way from his body over
// the second before her turn. With his plan left as it was she turned the asked way after 32 % of
// requests; turned 90 degrees and moved 0.6 m aside, 48 % (the other amounts tried:
// training/mirror/rollout.py).
export const LEAD_TURN = 90; // degrees
export const LEAD_SIDE = 0.6; // m

/**
 * `count` forward (R ez) and up (R ey) vectors -> orthonormal row-major 3x3 matrices at out[at..]
 * (Gram-Schmidt on forward): columns x = up × z, y = z × x, z = forward.
 */
export function rotationsFromVectors(
  forward: ArrayLike<number>, up: ArrayLike<number>, count: number, out: Float64Array, at = 0,
): void {
  for (let i = 0; i < count; i++) {
    const f0 = forward[3 * i], f1 = forward[3 * i + 1], f2 = forward[3 * i + 2];
    const fn = Math.max(Math.sqrt(f0 * f0 + f1 * f1 + f2 * f2), 1e-9);
    const z0 = f0 / fn, z1 = f1 / fn, z2 = f2 / fn;
    const u0 = up[3 * i], u1 = up[3 * i + 1], u2 = up[3 * i + 2];
    let x0 = u1 * z2 - u2 * z1, x1 = u2 * z0 - u0 * z2, x2 = u0 * z1 - u1 * z0;
    const xn = Math.max(Math.sqrt(x0 * x0 + x1 * x1 + x2 * x2), 1e-9);
    x0 /= xn;
    x1 /= xn;
    x2 /= xn;
    const y0 = z1 * x2 - z2 * x1, y1 = z2 * x0 - z0 * x2, y2 = z0 * x1 - z1 * x0;
    const o = at + 9 * i;
    out[o] = x0; out[o + 1] = y0; out[o + 2] = z0;
    out[o + 3] = x1; out[o + 4] = y1; out[o + 5] = z1;
    out[o + 6] = x2; out[o + 7] = y2; out[o + 8] = z2;
  }
}

/** A neutral standing pose in the dancer's own root space (manifest.startPose[role]). */
export interface StartPose {
  hip: number[];
  /** 17 × (x, y, z) */
  forward: number[][];
  /** 17 × (x, y, z) */
  up: number[][];
}

export class Dancer {
  readonly track = Track.empty(TRACK_FRAMES);
  /** Left, right foot in 0..1, as the model last said. */
  readonly contacts = new Float64Array(2);
  /** [6 × 5 × 3] world: what this dancer expects of its partner (null until a model says). */
  intention: Float64Array | null = null;
  resets = 0;
  /** Frames the leash moved this dancer (see keepClose). */
  leashed = 0;

  constructor(readonly offsets: Float64Array) {}

  get rootX(): number {
    return this.track.root[2 * NOW];
  }

  get rootZ(): number {
    return this.track.root[2 * NOW + 1];
  }

  get heading(): number {
    return this.track.heading[NOW];
  }

  /** The current joint positions [17 × 3] (a view into the track). */
  get positions(): Float64Array {
    return this.track.positions.subarray(NOW * POSITIONS_SIZE, NOW * POSITIONS_SIZE + POSITIONS_SIZE);
  }

  /** Make this dancer an exact copy of `other` (same offsets assumed): for trying outputs out. */
  copyFrom(other: Dancer): void {
    this.track.positions.set(other.track.positions);
    this.track.rotations.set(other.track.rotations);
    this.track.root.set(other.track.root);
    this.track.heading.set(other.track.heading);
    this.contacts.set(other.contacts);
  }
}

/** Forward vectors [17 × 3], then up vectors from UP_AT on. */
const poseVectors = new Float64Array(N_JOINTS * 3 * 2);
const UP_AT = N_JOINTS * 3;
const poseRotations = new Float64Array(ROTATIONS_SIZE);
const turnedRotations = new Float64Array(ROTATIONS_SIZE);
const hipScratch = new Float64Array(3);
const hipWorld = new Float64Array(3);

/** Fill the whole track with one still pose: the start pose at this root and heading. */
function standStill(d: Dancer, pose: StartPose, rootX: number, rootZ: number, heading: number): void {
  for (let j = 0; j < N_JOINTS; j++) {
    for (let k = 0; k < 3; k++) {
      poseVectors[3 * j + k] = pose.forward[j][k];
      poseVectors[UP_AT + 3 * j + k] = pose.up[j][k];
    }
  }
  rotationsFromVectors(poseVectors, poseVectors.subarray(UP_AT), N_JOINTS, poseRotations);
  // R_y(heading) · R, column by column (rotation_y in Python).
  const c = Math.cos(heading);
  const s = Math.sin(heading);
  for (let j = 0; j < N_JOINTS; j++) {
    for (let k = 0; k < 3; k++) {
      const x = poseRotations[9 * j + k], y = poseRotations[9 * j + 3 + k], z = poseRotations[9 * j + 6 + k];
      turnedRotations[9 * j + k] = c * x + s * z;
      turnedRotations[9 * j + 3 + k] = y;
      turnedRotations[9 * j + 6 + k] = -s * x + c * z;
    }
  }
  hipScratch[0] = pose.hip[0];
  hipScratch[1] = pose.hip[1];
  hipScratch[2] = pose.hip[2];
  fromRootSpacePoints(hipScratch, 0, 1, rootX, rootZ, heading, hipWorld, 0);
  const t = d.track;
  forwardKinematicsReduced(d.offsets, hipWorld, 0, turnedRotations, 0, t.positions, 0);
  for (let f = 1; f < TRACK_FRAMES; f++) t.positions.copyWithin(f * POSITIONS_SIZE, 0, POSITIONS_SIZE);
  for (let f = 0; f < TRACK_FRAMES; f++) {
    t.rotations.set(turnedRotations, f * ROTATIONS_SIZE);
    t.root[2 * f] = rootX;
    t.root[2 * f + 1] = rootZ;
    t.heading[f] = heading;
  }
}

/** A dancer standing still in the start pose, with a still history and a still plan. */
export function startDancer(offsets: ArrayLike<number>, startPose: StartPose, rootX: number, rootZ: number, heading: number): Dancer {
  const d = new Dancer(Float64Array.from(offsets));
  standStill(d, startPose, rootX, rootZ, heading);
  return d;
}

/** Output O (raw, 323, read at output[at..]) a dancer must not take: non-finite, a joint too far, a jump. */
export function outputIsAbsurd(output: ArrayLike<number>, at = 0): boolean {
  for (let i = 0; i < OUTPUT_SIZE; i++) if (!Number.isFinite(output[at + i])) return true;
  let farthest = 0;
  for (let j = 0; j < N_JOINTS; j++) {
    const p = at + OUT.pose.start + 12 * j;
    farthest = Math.max(farthest, Math.sqrt(output[p] ** 2 + output[p + 1] ** 2 + output[p + 2] ** 2));
  }
  const r = at + OUT.root_update.start;
  const jump = Math.sqrt(output[r] ** 2 + output[r + 1] ** 2);
  return farthest > MAX_JOINT_DISTANCE || jump > MAX_ROOT_JUMP;
}

const rootLocal = new Float64Array(3);
const rootWorld = new Float64Array(3);
const futureLocal = new Float64Array(KEYS * 3);
const futureWorld = new Float64Array(KEYS * 3);

/** Move the dancer one frame on with a model output O (raw, 323, read at output[at..]). */
export function applyOutput(d: Dancer, output: ArrayLike<number>, at = 0): void {
  const t = d.track;
  const r = at + OUT.root_update.start;
  rootLocal[0] = output[r];
  rootLocal[1] = 0;
  rootLocal[2] = output[r + 1];
  fromRootSpacePoints(rootLocal, 0, 1, t.root[2 * NOW], t.root[2 * NOW + 1], t.heading[NOW], rootWorld, 0);
  const rootX = rootWorld[0];
  const rootZ = rootWorld[2];
  const heading = wrapAngle(t.heading[NOW] + output[r + 2]);
  // Shift the past one frame back; the current slot gets the new frame.
  t.shiftPast(NOW);
  t.root[2 * NOW] = rootX;
  t.root[2 * NOW + 1] = rootZ;
  t.heading[NOW] = heading;
  const pose = at + OUT.pose.start;
  for (let j = 0; j < N_JOINTS; j++) {
    for (let k = 0; k < 3; k++) {
      poseVectors[3 * j + k] = output[pose + 12 * j + 6 + k];
      poseVectors[UP_AT + 3 * j + k] = output[pose + 12 * j + 9 + k];
    }
  }
  fromRootSpaceDirections(poseVectors, 0, 2 * N_JOINTS, heading, poseVectors, 0); // forward and up, in place
  rotationsFromVectors(poseVectors, poseVectors.subarray(UP_AT), N_JOINTS, t.rotations, NOW * ROTATIONS_SIZE);
  hipScratch[0] = output[pose];
  hipScratch[1] = output[pose + 1];
  hipScratch[2] = output[pose + 2];
  fromRootSpacePoints(hipScratch, 0, 1, rootX, rootZ, heading, hipWorld, 0);
  forwardKinematicsReduced(d.offsets, hipWorld, 0, t.rotations, NOW * ROTATIONS_SIZE, t.positions, NOW * POSITIONS_SIZE);
  // The predicted hip height can sag a few cm below what the legs need; lifting the whole body
  // keeps the ankles on or above the floor without bending a bone.
  const p = NOW * POSITIONS_SIZE;
  const lift = MIN_ANKLE_HEIGHT - Math.min(t.positions[p + 3 * FEET[0] + 1], t.positions[p + 3 * FEET[1] + 1]);
  if (lift > 0) for (let j = 0; j < N_JOINTS; j++) t.positions[p + 3 * j + 1] += lift;
  // The predicted future root path becomes the plan (the leader's is bent by steering later).
  const future = at + OUT.trajectory_future.start;
  for (let k = 0; k < KEYS; k++) {
    futureLocal[3 * k] = output[future + 4 * k];
    futureLocal[3 * k + 1] = 0;
    futureLocal[3 * k + 2] = output[future + 4 * k + 1];
  }
  fromRootSpacePoints(futureLocal, 0, KEYS, rootX, rootZ, heading, futureWorld, 0);
  for (let k = 0; k < KEYS; k++) {
    t.root[2 * (NOW + FUTURE_OFFSETS[k])] = futureWorld[3 * k];
    t.root[2 * (NOW + FUTURE_OFFSETS[k]) + 1] = futureWorld[3 * k + 2];
    futureLocal[3 * k] = output[future + 4 * k + 2];
    futureLocal[3 * k + 2] = output[future + 4 * k + 3];
  }
  fromRootSpaceDirections(futureLocal, 0, KEYS, heading, futureWorld, 0);
  for (let k = 0; k < KEYS; k++) t.heading[NOW + FUTURE_OFFSETS[k]] = Math.atan2(futureWorld[3 * k], futureWorld[3 * k + 2]);
  const c = at + OUT.contacts.start;
  d.contacts[0] = Math.min(1, Math.max(0, output[c]));
  d.contacts[1] = Math.min(1, Math.max(0, output[c + 1]));
}

/** Recover a dancer that produced absurd output: stand it in front of its partner, facing it. */
export function resetBeside(d: Dancer, partner: Dancer, startPose: StartPose): void {
  const h = partner.heading;
  const rootX = partner.rootX + START_DISTANCE * Math.sin(h);
  const rootZ = partner.rootZ + START_DISTANCE * Math.cos(h);
  standStill(d, startPose, rootX, rootZ, h + Math.PI);
  d.contacts.fill(0);
  d.resets += 1;
}

/**
 * The user's stick (world x, z; length <= 1) turned into a smooth velocity, and the anchor that
 * velocity carries: the spot the leader dances around. It moves only while steered.
 */
export class Steering {
  readonly velocity = new Float64Array(2);
  readonly anchor = new Float64Array(2);

  update(stickX: number, stickZ: number, dt = 1 / FPS): void {
    const decay = 0.5 ** (dt / STEER_HALFLIFE);
    const tx = stickX * MAX_SPEED;
    const tz = stickZ * MAX_SPEED;
    this.velocity[0] = tx + (this.velocity[0] - tx) * decay;
    this.velocity[1] = tz + (this.velocity[1] - tz) * decay;
    this.anchor[0] += this.velocity[0] * dt;
    this.anchor[1] += this.velocity[1] * dt;
  }
}

/**
 * Bend the leader's planned future root path toward the stick.
 *
 * With no stick, the plan is the leader's own last prediction (it dances on its own). With the
 * stick held, each key moves toward where the smoothed steering velocity carries the anchor,
 * in proportion to how far the stick is pushed.
 */
export function steerPlan(leader: Dancer, steering: Steering, stickX: number, stickZ: number): void {
  steering.update(stickX, stickZ);
  const weight = Math.min(1, Math.sqrt(stickX * stickX + stickZ * stickZ));
  if (weight <= 0) return;
  const root = leader.track.root;
  for (const off of FUTURE_OFFSETS) {
    const k = 2 * (NOW + off);
    const targetX = steering.anchor[0] + (steering.velocity[0] * off) / FPS;
    const targetZ = steering.anchor[1] + (steering.velocity[1] * off) / FPS;
    root[k] += weight * (targetX - root[k]);
    root[k + 1] += weight * (targetZ - root[k + 1]);
  }
}

/**
 * While a figure is danced or about to be, bend the leader's planned path (after steerPlan): for
 * her turn it turns LEAD_TURN degrees her way and moves LEAD_SIDE metres to his other side, for his
 * own turn it turns a full turn his way, from now to each future key times the share of the turn
 * planned between them.
 */
export function leadPlan(duet: Duet): void {
  const t = duet.leader.track;
  const h = t.heading[NOW];
  const leftX = Math.cos(h); // his root space's +x on the floor
  const leftZ = -Math.sin(h);
  for (const led of duet.figures.led) {
    const her = led.name === 'her_turn';
    const turn = her ? (LEAD_TURN * Math.PI) / 180 : 2 * Math.PI;
    const side = her ? LEAD_SIDE : 0;
    for (const off of FUTURE_OFFSETS) {
      const share = figureShare(led, duet.frame + off) - figureShare(led, duet.frame);
      if (!share) continue;
      t.heading[NOW + off] += led.way * turn * share;
      t.root[2 * (NOW + off)] -= led.way * side * share * leftX;
      t.root[2 * (NOW + off) + 1] -= led.way * side * share * leftZ;
    }
  }
}

/** Slide a dancer on the floor: current root, current pose and planned path together. */
export function shiftDancer(d: Dancer, sx: number, sz: number): void {
  const t = d.track;
  t.root[2 * NOW] += sx;
  t.root[2 * NOW + 1] += sz;
  for (const off of FUTURE_OFFSETS) {
    t.root[2 * (NOW + off)] += sx;
    t.root[2 * (NOW + off) + 1] += sz;
  }
  for (let j = 0; j < N_JOINTS; j++) {
    t.positions[NOW * POSITIONS_SIZE + 3 * j] += sx;
    t.positions[NOW * POSITIONS_SIZE + 3 * j + 2] += sz;
  }
}

/**
 * Draw the leader a little toward its anchor in the frames where its feet are free.
 *
 * The leader model reads the steered plan as an intention, not an order: fed its own predicted
 * path it wanders (about 1.7 m in 3 s here), and steered it answers only in part. Pulling the
 * root toward the anchor lets it travel where the user steers and keeps it near the spot the
 * user left it at. The pull moves the whole body, so it acts only as far as no foot is planted
 * (1 - the larger contact): a planted foot is never slid by it. Nobody steering, the pull spares
 * a circle of ANCHOR_FREE around the anchor (shrinking to nothing as the steered speed grows, so
 * steering answers as before): pinned to one spot, the leader hardly travelled.
 */
export function followAnchor(leader: Dancer, steering: Steering): void {
  const free = 1 - Math.max(leader.contacts[0], leader.contacts[1]);
  const speed = Math.hypot(steering.velocity[0], steering.velocity[1]);
  const radius = ANCHOR_FREE * Math.max(0, 1 - speed / MAX_SPEED);
  const dx = steering.anchor[0] - leader.rootX;
  const dz = steering.anchor[1] - leader.rootZ;
  const dist = Math.hypot(dx, dz);
  if (dist <= radius) return;
  const rate = (1 - radius / dist) * ANCHOR_RATE * free;
  shiftDancer(leader, dx * rate, dz * rate);
}

/**
 * Draw a follower that fell behind toward its leader.
 *
 * A steered leader can travel faster and straighter than any recorded one; the follower model
 * then lags. The leash only acts beyond LEASH_DISTANCE, where the recordings hardly go (99 % of
 * recorded frames are within 2.74 m), and moves at most a tenth of the excess per frame.
 */
export function keepClose(follower: Dancer, leader: Dancer): boolean {
  const dx = leader.rootX - follower.rootX;
  const dz = leader.rootZ - follower.rootZ;
  const dist = Math.hypot(dx, dz);
  if (dist <= LEASH_DISTANCE) return false;
  shiftDancer(follower, (dx / dist) * (dist - LEASH_DISTANCE) * LEASH_RATE, (dz / dist) * (dist - LEASH_DISTANCE) * LEASH_RATE);
  return true;
}

/**
 * One figure the leader leads: `name` her_turn or his_turn, to the dancer's left (way +1,
 * counterclockwise seen from above) or right (-1), from duet frame `start` to `end` (both danced);
 * `asked` when the visitor asked for it; `hands`: his hands (left, right; [2 × 3]) in his root
 * space when his plan for it began.
 */
export interface Led {
  name: FigureName;
  way: number;
  start: number;
  end: number;
  asked: boolean;
  hands: Float64Array | null;
}

/**
 * The figures of a duet: those danced and planned, in time order, and whether the leader leads his
 * own (`own`; the page's ?figures=0 turns them off) with `rng` (uniform in [0, 1)) drawing when and
 * which.
 */
export class Figures {
  led: Led[] = [];
  /** spans()'s array, reused: the page's step allocates nothing. */
  private readonly spanned: number[] = [];

  constructor(public own: boolean, public rng: () => number) {}

  /** The figure danced at `frame`, or null. */
  at(frame: number): Led | null {
    return this.led.find((f) => f.start <= frame && frame <= f.end) ?? null;
  }

  /** (kind, start, end) of every figure (features figureBlock), flat, in the frames of a track
   *  whose NOW is `frame` (a shared array, overwritten by the next call). */
  spans(frame: number): number[] {
    const out = this.spanned;
    out.length = 0;
    for (const f of this.led) out.push(figureKind(f.name, f.way), f.start - frame + NOW, f.end - frame + NOW);
    return out;
  }
}

/** Frames from `atFrame` until the count reaches `beat` (the count runs on one step a frame). */
export function framesToBeat(duet: Duet, atFrame: number, beat: number): number {
  const now = duet.beat + (atFrame - duet.frame) * beatsPerStep(duet.tempo);
  return atFrame + Math.max(0, Math.ceil((beat - now) / beatsPerStep(duet.tempo) - 1e-9));
}

/** Python's round(): to the nearest whole number, halves to the even one (Math.round takes them up). */
function roundHalfEven(x: number): number {
  const r = Math.round(x);
  return r - x === 0.5 && r % 2 !== 0 ? r - 1 : r;
}

/** A figure `name` of `way` starting at the first whole beat of the count at or after `frame`. */
export function figureFrom(duet: Duet, frame: number, name: FigureName, way: number, asked: boolean): Led {
  const per = beatsPerStep(duet.tempo);
  const beat = duet.beat + (frame - duet.frame) * per;
  const start = framesToBeat(duet, frame, Math.ceil(beat - 1e-9));
  return { name, way: way >= 0 ? 1 : -1, start, end: start + roundHalfEven(FIGURE_BEATS[name] / per), asked, hands: null };
}

/**
 * The visitor asks the leader to lead her turn (+1 to her left, -1 to her right): it starts on the
 * next beat, or after the figure running ends; it takes the place of a figure not begun.
 */
export function askTurn(duet: Duet, direction: number): void {
  const f = duet.figures;
  f.led = f.led.filter((x) => x.start <= duet.frame);
  const after = Math.max(duet.frame, ...f.led.map((x) => x.end + 1));
  f.led.push(figureFrom(duet, after, 'her_turn', direction, true));
}

/**
 * Each step: forget figures out of the past second, and with `own`, plan his next figure
 * OWN_GAP_BEATS after the last (or after the start) once none is running or planned.
 */
export function planFigures(duet: Duet): void {
  const f = duet.figures;
  if (f.led.some((x) => x.end < duet.frame - HISTORY)) f.led = f.led.filter((x) => x.end >= duet.frame - HISTORY);
  if (!f.own || f.led.some((x) => x.end >= duet.frame)) return;
  const last = f.led.length ? Math.max(...f.led.map((x) => x.end + 1)) : duet.frame;
  // Three uniform draws, in this order (as Python's): the wait, whose turn, and its way.
  const gap = OWN_GAP_BEATS[0] + (OWN_GAP_BEATS[1] - OWN_GAP_BEATS[0]) * f.rng();
  const name: FigureName = f.rng() < HIS_SHARE ? 'his_turn' : 'her_turn';
  const way = f.rng() < 0.5 ? 1 : -1;
  const start = framesToBeat(duet, last, duet.beat + (last - duet.frame) * beatsPerStep(duet.tempo) + gap);
  f.led.push(figureFrom(duet, Math.max(start, duet.frame + 1), name, way, false));
}

/** A figure is led from LEAD_IN frames before it starts (the figure block shows it a second ahead:
 *  his preparation) to its end. */
export const LEAD_IN = FPS;

/**
 * Whether the leader leads a figure the visitor asked for this step: one runs, or starts within
 * LEAD_IN frames. His own figures do not count: drawn more freely through them too, she turned
 * more (0.90x the recording's turns a minute against 0.80x) but her steered steps landed on the
 * beat at +0.34 against +0.40 (docs/results.md, "Leading a turn").
 */
export function leading(duet: Duet): boolean {
  return duet.figures.led.some((f) => f.asked && f.start - LEAD_IN <= duet.frame && duet.frame <= f.end);
}

/**
 * The leader's variety this step: the manifest's leadingTemperature while he leads a figure the
 * visitor asked for (`leading`), else `temperature` (his own). Drawn at his everyday variety, his
 * samples seldom raised the lead hand for the hands plan; drawn more freely, his guard's choice near
 * the plan has more to choose from.
 */
export function leaderVariety(duet: Duet, temperature: number): number {
  return duet.leadingTemperature !== null && leading(duet) ? duet.leadingTemperature : temperature;
}

/** How much of the figure's turn is planned done at `frame`, 0 to 1 (smoothstep over it). */
export function figureShare(led: Led, frame: number): number {
  const u = Math.min(1, Math.max(0, (frame - led.start) / Math.max(led.end - led.start, 1)));
  return u * u * (3 - 2 * u);
}

/** How far his lead hand is raised for `led` at `frame`, 0 to 1 (smoothsteps up and down). */
export function raised(led: Led, frame: number): number {
  const up = Math.min(1, Math.max(0, (frame - led.start) / (RAISE[0] * FPS)));
  const down = Math.min(1, Math.max(0, (frame - led.end) / (RAISE[1] * FPS)));
  return up * up * (3 - 2 * up) * (1 - down * down * (3 - 2 * down));
}

/**
 * The figure his hands plan is for (her turns only): the one danced now or beginning within the
 * next second, else one whose raise is coming down. A figure that follows another at once takes the
 * plan over as soon as the one before ends.
 */
export function planning(duet: Duet): Led | null {
  // A loop, not filter/find: this runs every step and allocates nothing.
  const lowering = Math.trunc(RAISE[1] * FPS);
  let lowered: Led | null = null;
  for (const x of duet.figures.led) {
    if (x.name !== 'her_turn' || x.start - HISTORY > duet.frame || duet.frame > x.end + lowering) continue;
    if (x.end >= duet.frame) return x;
    lowered ??= x;
  }
  return lowered;
}

const HANDS_MOVES = KEYS * HANDS.length * 3;
const handsMoves = new Float64Array(HANDS_MOVES);
const handsNow = new Float64Array(HANDS.length * 3);
const handsWorld = new Float64Array(HANDS.length * 3);

/** His hands (left, right) in his root space now, into out [2 × 3]. */
function handsInRootSpace(leader: Dancer, out: Float64Array): void {
  const p = leader.positions;
  for (let i = 0; i < HANDS.length; i++) {
    for (let c = 0; c < 3; c++) handsWorld[3 * i + c] = p[3 * HANDS[i] + c];
  }
  toRootSpacePoints(handsWorld, 0, HANDS.length, leader.rootX, leader.rootZ, leader.heading, out, 0);
}

/**
 * The leader's hands plan [KEYS × 2 × 3] for the figure he plans (null: none): from where his hands
 * are now to where the raise puts them at each future key, in his root space. A shared scratch array.
 */
export function handsInput(duet: Duet): Float64Array | null {
  const led = planning(duet);
  if (!led) return null;
  handsInRootSpace(duet.leader, handsNow);
  led.hands ??= Float64Array.from(handsNow);
  const lead = led.way > 0 ? 0 : 1;
  for (let k = 0; k < KEYS; k++) {
    const u = raised(led, duet.frame + FUTURE_OFFSETS[k]);
    for (let h = 0; h < HANDS.length; h++) {
      for (let c = 0; c < 3; c++) {
        const from = led.hands[3 * h + c];
        let to = from;
        if (h === lead) {
          const top = c === 0 ? (lead === 0 ? 1 : -1) * LEAD_HAND_RAISED[0] : LEAD_HAND_RAISED[c];
          to = from + u * (top - from);
        }
        handsMoves[(k * HANDS.length + h) * 3 + c] = to - handsNow[3 * h + c];
      }
    }
  }
  return handsMoves;
}

export interface Duet {
  leader: Dancer;
  /** One, or two in compare mode; the leader reacts to the first. */
  followers: Dancer[];
  startPose: { leader: StartPose; follower: StartPose };
  steering: Steering;
  frame: number;
  /** The figures led: the visitor's and his own (Figures). */
  figures: Figures;
  /**
   * The music both dancers hear (web/mirror/music.ts): its tempo (beats a minute) and the count now
   * (beats since it started). finishStep moves the count on by one step of the tempo; the page sets
   * it from the audio clock before a step while the music plays (what the listener hears now).
   */
  tempo: number;
  beat: number;
  /** The leader's variety while he leads a figure the visitor asked for (the manifest's
   *  leadingTemperature; null: his own throughout). leaderVariety reads it. */
  leadingTemperature: number | null;
}

/** The parts of manifest.json a duet starts from. */
export interface DuetManifest {
  skeleton: { offsets: { leader: number[][]; follower: number[][] } };
  startPose: unknown;
  music?: { tempo?: number };
  leadingTemperature?: number;
}

/** The music's tempo a duet dances to when none is asked for: the manifest's, else DEFAULT_TEMPO. */
export function manifestTempo(manifest: DuetManifest): number {
  return manifest.music?.tempo ?? DEFAULT_TEMPO;
}

/** Still T-ish rest pose (all rotations identity), ankles 8 cm up: for manifests without a start pose. */
export function restStartPose(offsets: number[][]): StartPose {
  const y = new Float64Array(N_JOINTS);
  let lowest = 0;
  for (let j = 1; j < N_JOINTS; j++) {
    y[j] = y[PARENTS[j]] + offsets[j][1];
    lowest = Math.min(lowest, y[j]);
  }
  return {
    hip: [0, 0.08 - lowest, 0],
    forward: Array.from({ length: N_JOINTS }, () => [0, 0, 1]),
    up: Array.from({ length: N_JOINTS }, () => [0, 1, 0]),
  };
}

function isStartPose(value: unknown): value is StartPose {
  const p = value as StartPose | undefined;
  const rows = (a: unknown) => Array.isArray(a) && a.length === N_JOINTS && a.every((r) => Array.isArray(r) && r.length === 3);
  return !!p && Array.isArray(p.hip) && p.hip.length === 3 && rows(p.forward) && rows(p.up);
}

/**
 * Both partners standing still, 0.8 m apart and facing each other (leader at the origin facing +Z),
 * the music at `tempo` beats a minute (null: the manifest's) and its count at 0; with `figures` the
 * leader leads figures of his own, drawn by `random` (uniform in [0, 1): the page's seeded one).
 */
export function startDuet(
  manifest: DuetManifest, followerCount = 1, tempo: number | null = null, figures = true, random: () => number = createUniform(0),
): Duet {
  const bpm = tempo ?? manifestTempo(manifest);
  if (!Number.isFinite(bpm) || bpm <= 0) throw new Error(`tempo must be a positive number of beats a minute, got ${tempo}`);
  const offsets = manifest.skeleton.offsets;
  const poses = (manifest.startPose ?? {}) as Record<string, unknown>;
  const startPose = {
    leader: isStartPose(poses.leader) ? poses.leader : restStartPose(offsets.leader),
    follower: isStartPose(poses.follower) ? poses.follower : restStartPose(offsets.follower),
  };
  const leader = startDancer(offsets.leader.flat(), startPose.leader, 0, 0, 0);
  const followers = Array.from({ length: followerCount }, () =>
    startDancer(offsets.follower.flat(), startPose.follower, 0, START_DISTANCE, Math.PI));
  const duet: Duet = {
    leader, followers, startPose, steering: new Steering(), frame: 0, figures: new Figures(figures, random), tempo: bpm, beat: 0,
    leadingTemperature: manifest.leadingTemperature ?? null,
  };
  setAnchor(duet);
  return duet;
}

const figureNow = new Float64Array(FIGURE_SIZE);

/**
 * Both models' inputs at NOW: the leader's (partner = first follower) and each follower's. All read
 * the figure being led (what her hand feels); only his hands plan says where his hands go.
 */
export function stepInputs(duet: Duet, leaderOut: Out | null, followerOuts: Out[]): void {
  figureBlock(duet.figures.spans(duet.frame), NOW, figureNow, 0);
  const heard = musicInput(duet);
  if (leaderOut) {
    leaderInput(duet.followers[0].track, duet.leader.track, NOW, leaderOut, 0, figureNow, handsInput(duet), heard);
  }
  duet.followers.forEach((f, i) => followerInput(duet.leader.track, f.track, NOW, followerOuts[i], 0, figureNow, heard));
}

const heardNow = new Float64Array(MUSIC_SIZE);

/** The music block [53] both dancers hear this step: the count now and the tempo (shared scratch). */
export function musicInput(duet: Duet): Float64Array {
  musicBlock(duet.beat, duet.tempo / 60, heardNow, 0);
  return heardNow;
}

const intentionLocal = new Float64Array(INTENTION_SIZE);

/** Put the anchor under the leader (start, reset, recorded leader). */
export function setAnchor(duet: Duet): void {
  duet.steering.anchor[0] = duet.leader.rootX;
  duet.steering.anchor[1] = duet.leader.rootZ;
}

/**
 * Move everyone one frame on. A null leader output means the leader was moved already (playback).
 * Each absurd output resets its dancer beside its partner instead.
 */
export function finishStep(
  duet: Duet, leaderOutput: ArrayLike<number> | null, followerOutputs: ArrayLike<number>[],
  followerIntentions: (ArrayLike<number> | null)[] = [],
): void {
  if (leaderOutput) {
    if (outputIsAbsurd(leaderOutput)) {
      resetBeside(duet.leader, duet.followers[0], duet.startPose.leader);
      setAnchor(duet);
    } else {
      applyOutput(duet.leader, leaderOutput);
      followAnchor(duet.leader, duet.steering);
    }
  } else {
    setAnchor(duet); // a recording leads: the anchor waits where the model will take over
  }
  duet.followers.forEach((f, i) => {
    if (outputIsAbsurd(followerOutputs[i])) resetBeside(f, duet.leader, duet.startPose.follower);
    else applyOutput(f, followerOutputs[i]);
    if (keepClose(f, duet.leader)) f.leashed += 1;
    const intention = followerIntentions[i];
    if (intention) {
      for (let k = 0; k < INTENTION_SIZE; k++) intentionLocal[k] = intention[k];
      f.intention ??= new Float64Array(INTENTION_SIZE);
      fromRootSpacePoints(intentionLocal, 0, KEYS * KEY_JOINTS.length, f.rootX, f.rootZ, f.heading, f.intention, 0);
    }
  });
  duet.frame += 1;
  duet.beat += beatsPerStep(duet.tempo);
}
