// Mirror of training/mirror/features.py: feature vectors of the paper, in the root space of the
// character being predicted ("self"). Same names in camelCase, same order of numbers;
// tests/web/features.test.ts pins both to the fixtures that tests/python/fixtures_writer.py writes.
// Layout and conventions: docs/features.md.
//
// Python computes whole takes at once with batch dimensions; here every function computes ONE
// frame and writes into a caller-provided array `out` at index `at`, so the page's per-frame
// path allocates nothing. Module-level scratch arrays hold gathered inputs (JS is single-threaded
// and none of these functions re-enters another while its scratch is live).

import { FEET, FPS, HANDS, KEY_JOINTS, type Motion, N_JOINTS, type Out, POSITIONS_SIZE, ROTATIONS_SIZE, rootFromMotion } from './skeleton';
import { MUSIC_SIZE, musicAt } from './music';


export const KEYS = 6; // trajectory keys per second (the paper's k)
export const KEY_STEP = FPS / KEYS; // 5 frames between keys at 30 fps
export const PAST_OFFSETS: readonly number[] = Array.from({ length: KEYS }, (_, i) => (i - KEYS) * KEY_STEP); // t-30 ... t-5
export const FUTURE_OFFSETS: readonly number[] = Array.from({ length: KEYS }, (_, i) => (i + 1) * KEY_STEP); // t+5 ... t+30
export const HISTORY = KEYS * KEY_STEP; // 30 frames of past are needed
export { N_JOINTS };
export const N_KEY_JOINTS = KEY_JOINTS.length;

export const TRAJECTORY_SIZE = KEYS * 4; // 24
export const KEY_JOINTS_SIZE = KEYS * N_KEY_JOINTS * 3; // 90
export const POSE_SIZE = N_JOINTS * 12; // 204
export const ROOT_UPDATE_SIZE = 3;
export const CONTACTS_SIZE = 2;
// The figure being led (figureBlock), one of FIGURE_KINDS: her turn or his, to the dancer's left
// (way +1, counterclockwise seen from above) or right (-1), read at each key of the past second,
// now, and each key of the next second, as (inside, progress).
export type FigureName = 'her_turn' | 'his_turn';
export const FIGURE_KINDS: ReadonlyArray<readonly [FigureName, number]> = [
  ['her_turn', 1], ['her_turn', -1], ['his_turn', 1], ['his_turn', -1],
];
/** The index into FIGURE_KINDS of figure `name` of `way` (Python's FIGURE_KINDS.index((name, way))); allocates nothing. */
export function figureKind(name: FigureName, way: number): number {
  for (let k = 0; k < FIGURE_KINDS.length; k++) if (FIGURE_KINDS[k][0] === name && FIGURE_KINDS[k][1] === way) return k;
  throw new Error(`no figure kind (${name}, ${way})`);
}
export const FIGURE_OFFSETS: readonly number[] = Array.from({ length: 2 * KEYS + 1 }, (_, i) => (i - KEYS) * KEY_STEP); // t-30 ... t ... t+30
export const FIGURE_SIZE = FIGURE_OFFSETS.length * FIGURE_KINDS.length * 2; // 104
export const HANDS_PLAN_SIZE = 1 + KEYS * HANDS.length * 3; // 37: shown, then where each hand is to go at each key

export type Layout = ReadonlyArray<readonly [string, number]>;

// (name, size) in order; docs/features.md explains each block.
export const FOLLOWER_INPUT_LAYOUT: Layout = [
  ['partner_trajectory_past', TRAJECTORY_SIZE], ['partner_trajectory_future', TRAJECTORY_SIZE],
  ['partner_key_joints_past', KEY_JOINTS_SIZE], ['partner_pose', POSE_SIZE],
  ['self_trajectory_past', TRAJECTORY_SIZE], ['self_key_joints_past', KEY_JOINTS_SIZE],
  ['self_pose', POSE_SIZE], ['figure', FIGURE_SIZE], ['music', MUSIC_SIZE],
];
export const LEADER_INPUT_LAYOUT: Layout = [
  ['partner_trajectory_past', TRAJECTORY_SIZE], ['partner_key_joints_past', KEY_JOINTS_SIZE],
  ['partner_pose', POSE_SIZE],
  ['self_trajectory_past', TRAJECTORY_SIZE], ['self_key_joints_past', KEY_JOINTS_SIZE],
  ['self_pose', POSE_SIZE], ['control', TRAJECTORY_SIZE], ['figure', FIGURE_SIZE],
  ['hands_plan', HANDS_PLAN_SIZE], ['music', MUSIC_SIZE],
];
export const OUTPUT_LAYOUT: Layout = [
  ['root_update', ROOT_UPDATE_SIZE], ['trajectory_future', TRAJECTORY_SIZE],
  ['key_joints_future', KEY_JOINTS_SIZE], ['pose', POSE_SIZE], ['contacts', CONTACTS_SIZE],
];
export const INTENTION_LAYOUT: Layout = [['partner_key_joints_future', KEY_JOINTS_SIZE]];
const layoutSize = (layout: Layout) => layout.reduce((sum, [, size]) => sum + size, 0);
export const INPUT_SIZE = layoutSize(FOLLOWER_INPUT_LAYOUT); // 817: the follower's input
export const LEADER_INPUT_SIZE = layoutSize(LEADER_INPUT_LAYOUT); // 854: the same blocks, control, figure, hands plan, music
export const OUTPUT_SIZE = layoutSize(OUTPUT_LAYOUT); // 323
export const INTENTION_SIZE = KEY_JOINTS_SIZE; // 90
export const INPUT_SIZES: Readonly<Record<string, number>> = { follower: INPUT_SIZE, leader: LEADER_INPUT_SIZE };

// Foot contact: ankle joint near the floor and nearly still. The ankle of a flat foot sits
// 7-11 cm up in this data (heels included), so 15 cm leaves room; 0.5 m/s separates a planted
// foot from a stepping one at 30 fps.
export const CONTACT_HEIGHT = 0.15;
export const CONTACT_SPEED = 0.5;

// ---------------------------------------------------------------- root space

/**
 * `count` world points (x, y, z) read from points[from..] -> root space, written to out[at..]
 * with `stride` numbers between points (3 = packed; the pose block interleaves).
 */
export function toRootSpacePoints(
  points: ArrayLike<number>, from: number, count: number,
  rootX: number, rootZ: number, heading: number,
  out: Out, at: number, stride = 3,
): void {
  const c = Math.cos(heading);
  const s = Math.sin(heading);
  for (let i = 0; i < count; i++) {
    const p = from + 3 * i;
    const o = at + stride * i;
    const dx = points[p] - rootX;
    const dz = points[p + 2] - rootZ;
    // R_y(-heading): the heading direction (sin h, 0, cos h) maps to +Z.
    out[o] = c * dx - s * dz;
    out[o + 1] = points[p + 1];
    out[o + 2] = s * dx + c * dz;
  }
}

/** World directions -> root space (rotation only); arguments as toRootSpacePoints. */
export function toRootSpaceDirections(
  dirs: ArrayLike<number>, from: number, count: number, heading: number,
  out: Out, at: number, stride = 3,
): void {
  const c = Math.cos(heading);
  const s = Math.sin(heading);
  for (let i = 0; i < count; i++) {
    const p = from + 3 * i;
    const o = at + stride * i;
    const x = dirs[p];
    const z = dirs[p + 2];
    out[o] = c * x - s * z;
    out[o + 1] = dirs[p + 1];
    out[o + 2] = s * x + c * z;
  }
}

/** Inverse of toRootSpacePoints. */
export function fromRootSpacePoints(
  points: ArrayLike<number>, from: number, count: number,
  rootX: number, rootZ: number, heading: number,
  out: Out, at: number, stride = 3,
): void {
  const c = Math.cos(heading);
  const s = Math.sin(heading);
  for (let i = 0; i < count; i++) {
    const p = from + 3 * i;
    const o = at + stride * i;
    const x = points[p];
    const z = points[p + 2];
    out[o] = c * x + s * z + rootX;
    out[o + 1] = points[p + 1];
    out[o + 2] = -s * x + c * z + rootZ;
  }
}

export function fromRootSpaceDirections(
  dirs: ArrayLike<number>, from: number, count: number, heading: number,
  out: Out, at: number, stride = 3,
): void {
  toRootSpaceDirections(dirs, from, count, -heading, out, at, stride);
}

// ---------------------------------------------------------------- blocks

const keyPoints = new Float64Array(KEYS * 3);
const keyLocal = new Float64Array(KEYS * 3);
const keyForward = new Float64Array(KEYS * 3);
const keyForwardLocal = new Float64Array(KEYS * 3);

/**
 * Root keys (x, z) [K × 2] and headings [K] -> K × (x, z, fwd x, fwd z) at out[at..].
 * K = keyHeadings.length (at most KEYS).
 */
export function trajectoryBlock(
  keyRoots: ArrayLike<number>, keyHeadings: ArrayLike<number>,
  rootX: number, rootZ: number, heading: number, out: Out, at: number,
): void {
  const K = keyHeadings.length;
  for (let k = 0; k < K; k++) {
    keyPoints[3 * k] = keyRoots[2 * k];
    keyPoints[3 * k + 1] = 0;
    keyPoints[3 * k + 2] = keyRoots[2 * k + 1];
    keyForward[3 * k] = Math.sin(keyHeadings[k]);
    keyForward[3 * k + 1] = 0;
    keyForward[3 * k + 2] = Math.cos(keyHeadings[k]);
  }
  toRootSpacePoints(keyPoints, 0, K, rootX, rootZ, heading, keyLocal, 0);
  toRootSpaceDirections(keyForward, 0, K, heading, keyForwardLocal, 0);
  for (let k = 0; k < K; k++) {
    out[at + 4 * k] = keyLocal[3 * k];
    out[at + 4 * k + 1] = keyLocal[3 * k + 2];
    out[at + 4 * k + 2] = keyForwardLocal[3 * k];
    out[at + 4 * k + 3] = keyForwardLocal[3 * k + 2];
  }
}

/** Key-joint positions [K × 5 × 3] -> [K·5·3] in root space at out[at..]. */
export function keyJointsBlock(
  keyPositions: ArrayLike<number>, rootX: number, rootZ: number, heading: number, out: Out, at: number,
): void {
  toRootSpacePoints(keyPositions, 0, keyPositions.length / 3, rootX, rootZ, heading, out, at);
}

const velocity = new Float64Array(N_JOINTS * 3);
const forwardAxis = new Float64Array(N_JOINTS * 3);
const upAxis = new Float64Array(N_JOINTS * 3);

/**
 * Joints [17 × 3], the frame before, world rotations [17 × 9] -> [17 × 12] at out[at..].
 *
 * Per joint: position, velocity (finite difference, m/s), forward (R ez, the matrix's third
 * column) and up (R ey, the second column) vectors.
 */
export function poseBlock(
  positions: ArrayLike<number>, previousPositions: ArrayLike<number>, rotations: ArrayLike<number>,
  rootX: number, rootZ: number, heading: number, out: Out, at: number, fps: number = FPS,
): void {
  for (let j = 0; j < N_JOINTS; j++) {
    for (let k = 0; k < 3; k++) {
      velocity[3 * j + k] = (positions[3 * j + k] - previousPositions[3 * j + k]) * fps;
      forwardAxis[3 * j + k] = rotations[9 * j + 3 * k + 2];
      upAxis[3 * j + k] = rotations[9 * j + 3 * k + 1];
    }
  }
  toRootSpacePoints(positions, 0, N_JOINTS, rootX, rootZ, heading, out, at, 12);
  toRootSpaceDirections(velocity, 0, N_JOINTS, heading, out, at + 3, 12);
  toRootSpaceDirections(forwardAxis, 0, N_JOINTS, heading, out, at + 6, 12);
  toRootSpaceDirections(upAxis, 0, N_JOINTS, heading, out, at + 9, 12);
}

/** Wrap an angle to (-π, π] the way numpy's angle(exp(iθ)) does. */
export function wrapAngle(theta: number): number {
  return Math.atan2(Math.sin(theta), Math.cos(theta));
}

const rootStep = new Float64Array(3);
const rootStepLocal = new Float64Array(3);

/** (dx, dz) of the next root in this root's space, and the wrapped heading change, at out[at..]. */
export function rootUpdate(
  rootX: number, rootZ: number, heading: number,
  nextX: number, nextZ: number, nextHeading: number, out: Out, at: number,
): void {
  rootStep[0] = nextX - rootX;
  rootStep[1] = 0;
  rootStep[2] = nextZ - rootZ;
  toRootSpaceDirections(rootStep, 0, 1, heading, rootStepLocal, 0);
  out[at] = rootStepLocal[0];
  out[at + 1] = rootStepLocal[2];
  out[at + 2] = wrapAngle(nextHeading - heading);
}

/** Joints [17 × 3] and the frame before -> 2 numbers in {0, 1} at out[at..]: ankle low and slow. */
export function footContacts(
  positions: ArrayLike<number>, previousPositions: ArrayLike<number>, out: Out, at: number, fps: number = FPS,
): void {
  for (let i = 0; i < FEET.length; i++) {
    const p = 3 * FEET[i];
    const dx = positions[p] - previousPositions[p];
    const dy = positions[p + 1] - previousPositions[p + 1];
    const dz = positions[p + 2] - previousPositions[p + 2];
    const speed = Math.sqrt(dx * dx + dy * dy + dz * dz) * fps;
    out[at + i] = positions[p + 1] < CONTACT_HEIGHT && speed < CONTACT_SPEED ? 1 : 0;
  }
}

// ---------------------------------------------------------------- one dancer over time

/**
 * A dancer as the features see it: motion plus the root per frame (30 fps), and the count of the
 * music it dances to when it is known (a recorded take's; the rollout passes its clock instead).
 */
export class Track {
  constructor(
    /** [F × 17 × 3] world. */
    readonly positions: Float64Array,
    /** [F × 17 × 9] world, row-major. */
    readonly rotations: Float64Array,
    /** [F × 2] floor (x, z). */
    readonly root: Float64Array,
    /** [F] radians, 0 = facing +Z. */
    readonly heading: Float64Array,
    /** [F] the count, beats since the music started; null: not known. */
    readonly beat: Float64Array | null = null,
  ) {}

  static fromMotion(motion: Motion): Track {
    const { root, heading } = rootFromMotion(motion);
    return new Track(motion.positions, motion.rotations, root, heading);
  }

  /** F frames of zeros (the rollout fills them). */
  static empty(frames: number): Track {
    return new Track(new Float64Array(frames * POSITIONS_SIZE), new Float64Array(frames * ROTATIONS_SIZE), new Float64Array(frames * 2), new Float64Array(frames));
  }

  get frames(): number {
    return this.heading.length;
  }

  /** Move frames 1..now one slot back (the rollout's step): frame `now` is then free for the new one. */
  shiftPast(now: number): void {
    this.positions.copyWithin(0, POSITIONS_SIZE, POSITIONS_SIZE * (now + 1));
    this.rotations.copyWithin(0, ROTATIONS_SIZE, ROTATIONS_SIZE * (now + 1));
    this.root.copyWithin(0, 2, 2 * (now + 1));
    this.heading.copyWithin(0, 1, now + 1);
  }
}

const gatherRoots = new Float64Array(KEYS * 2);
const gatherHeadings = new Float64Array(KEYS);
const gatherKeys = new Float64Array(KEYS * N_KEY_JOINTS * 3);
const gatherPositions = new Float64Array(N_JOINTS * 3);
const gatherPrevious = new Float64Array(N_JOINTS * 3);
const gatherRotations = new Float64Array(N_JOINTS * 9);

function copyFrame(from: Float64Array, size: number, frame: number, into: Float64Array): void {
  const base = frame * size;
  for (let i = 0; i < size; i++) into[i] = from[base + i];
}

function trajectoryAt(track: Track, t: number, offsets: readonly number[], rootX: number, rootZ: number, heading: number, out: Out, at: number): void {
  for (let k = 0; k < offsets.length; k++) {
    const f = t + offsets[k];
    gatherRoots[2 * k] = track.root[2 * f];
    gatherRoots[2 * k + 1] = track.root[2 * f + 1];
    gatherHeadings[k] = track.heading[f];
  }
  trajectoryBlock(gatherRoots, gatherHeadings, rootX, rootZ, heading, out, at);
}

function keyJointsAt(track: Track, t: number, offsets: readonly number[], rootX: number, rootZ: number, heading: number, out: Out, at: number): void {
  for (let k = 0; k < offsets.length; k++) {
    const f = t + offsets[k];
    for (let n = 0; n < N_KEY_JOINTS; n++) {
      const src = (f * N_JOINTS + KEY_JOINTS[n]) * 3;
      const dst = (k * N_KEY_JOINTS + n) * 3;
      gatherKeys[dst] = track.positions[src];
      gatherKeys[dst + 1] = track.positions[src + 1];
      gatherKeys[dst + 2] = track.positions[src + 2];
    }
  }
  keyJointsBlock(gatherKeys, rootX, rootZ, heading, out, at);
}

function poseAt(track: Track, t: number, rootX: number, rootZ: number, heading: number, out: Out, at: number): void {
  copyFrame(track.positions, POSITIONS_SIZE, t, gatherPositions);
  copyFrame(track.positions, POSITIONS_SIZE, t - 1, gatherPrevious);
  copyFrame(track.rotations, ROTATIONS_SIZE, t, gatherRotations);
  poseBlock(gatherPositions, gatherPrevious, gatherRotations, rootX, rootZ, heading, out, at);
}

/** Writes one input block at out[at..]: read from `partner` or `me` at frame t, in the root space (x, z, h). */
type InputBlock = (partner: Track, me: Track, t: number, x: number, z: number, h: number, out: Out, at: number) => void;

// What each input block name means; the layout tables above give the order and the sizes.
const INPUT_BLOCKS: Record<string, InputBlock> = {
  partner_trajectory_past: (partner, _me, t, x, z, h, out, at) => trajectoryAt(partner, t, PAST_OFFSETS, x, z, h, out, at),
  partner_trajectory_future: (partner, _me, t, x, z, h, out, at) => trajectoryAt(partner, t, FUTURE_OFFSETS, x, z, h, out, at),
  partner_key_joints_past: (partner, _me, t, x, z, h, out, at) => keyJointsAt(partner, t, PAST_OFFSETS, x, z, h, out, at),
  partner_pose: (partner, _me, t, x, z, h, out, at) => poseAt(partner, t, x, z, h, out, at),
  self_trajectory_past: (_partner, me, t, x, z, h, out, at) => trajectoryAt(me, t, PAST_OFFSETS, x, z, h, out, at),
  self_key_joints_past: (_partner, me, t, x, z, h, out, at) => keyJointsAt(me, t, PAST_OFFSETS, x, z, h, out, at),
  self_pose: (_partner, me, t, x, z, h, out, at) => poseAt(me, t, x, z, h, out, at),
  // The leader's control is its own planned (steered) future trajectory.
  control: (_partner, me, t, x, z, h, out, at) => trajectoryAt(me, t, FUTURE_OFFSETS, x, z, h, out, at),
  // No figure here; followerInput / leaderInput write the one being led over it when there is one.
  figure: (_partner, _me, t, _x, _z, _h, out, at) => figureBlock(null, t, out, at),
  // Nor a lead; leaderInput writes the hands plan for a figure over it when there is one.
  hands_plan: (_partner, _me, _t, _x, _z, _h, out, at) => handsPlanBlock(null, out, at),
  // The count the tracks carry; followerInput / leaderInput write the rollout's clock instead.
  music: (partner, me, t, _x, _z, _h, out, at) => {
    const beat = me.beat ?? partner.beat;
    if (beat) musicAt(beat, t, out, at);
  },
};

/**
 * The figure being led [104] at out[at..], which both dancers read: at each of FIGURE_OFFSETS
 * from frame t (the past second, now, the next second), for each of FIGURE_KINDS, `inside` (1
 * while a figure of that kind runs) and `progress` (0 at its start to 1 at its end; 0 outside).
 *
 * `figures` holds (kind, start, end) per figure, flat, kind an index into FIGURE_KINDS, start and
 * end in the frames of t (both danced); null or empty: no figure. At run time they are the
 * visitor's and the leader's own (rollout.ts Figures). A salsa lead reaches the follower through
 * the joined hands, which a capture of positions does not hold: this block stands for what her
 * hand feels and his hand does. It asks nothing of her body or timing.
 */
export function figureBlock(figures: ArrayLike<number> | null, t: number, out: Out, at = 0): void {
  const kinds = FIGURE_KINDS.length;
  for (let i = 0; i < FIGURE_SIZE; i++) out[at + i] = 0;
  const n = figures ? figures.length / 3 : 0;
  for (let m = 0; m < n; m++) {
    const w = figures![3 * m], start = figures![3 * m + 1], end = figures![3 * m + 2];
    if (!(Number.isInteger(w) && w >= 0 && w < kinds)) throw new Error(`figure kind ${w} is not an index into FIGURE_KINDS`);
    for (let k = 0; k < FIGURE_OFFSETS.length; k++) {
      const f = t + FIGURE_OFFSETS[k];
      if (f < start || f > end) continue;
      const o = at + 2 * (k * kinds + w);
      out[o] = 1;
      out[o + 1] = (f - start) / Math.max(end - start, 1);
    }
  }
}

/**
 * The leader's hands plan [37] at out[at..]: `shown` (1 when a plan is given), then how far each
 * hand (left, right) is to move from where it is now to where it is at each future key, in his
 * root space now ([KEYS][2][3], key by key). null: no plan (zeros), and his hands go where he
 * likes, as he learnt from the samples whose plan was hidden. A raised hand is how a salsa leader
 * leads her turn; this block is how a visitor raises it.
 */
export function handsPlanBlock(moves: ArrayLike<number> | null, out: Out, at = 0): void {
  out[at] = moves ? 1 : 0;
  for (let i = 1; i < HANDS_PLAN_SIZE; i++) out[at + i] = moves ? moves[i - 1] : 0;
}

/** A layout table as (writer, start) pairs in its order (Python concatenates; here every block writes at its offset). */
function inputPlan(layout: Layout): { write: InputBlock; start: number }[] {
  const slices = blockSlices(layout);
  return layout.map(([name]) => {
    const write = INPUT_BLOCKS[name];
    if (!write) throw new Error(`no features for input block "${name}"`);
    return { write, start: slices[name].start };
  });
}

const FOLLOWER_PLAN = inputPlan(FOLLOWER_INPUT_LAYOUT);
const LEADER_PLAN = inputPlan(LEADER_INPUT_LAYOUT);
const OUTPUT_BLOCKS = blockSlices(OUTPUT_LAYOUT);

function writeInput(plan: { write: InputBlock; start: number }[], partner: Track, me: Track, t: number, out: Out, at: number): void {
  const x = me.root[2 * t];
  const z = me.root[2 * t + 1];
  const h = me.heading[t];
  for (const block of plan) block.write(partner, me, t, x, z, h, out, at + block.start);
}

const FOLLOWER_MUSIC_AT = blockSlices(FOLLOWER_INPUT_LAYOUT).music.start;
const LEADER_MUSIC_AT = blockSlices(LEADER_INPUT_LAYOUT).music.start;

/** The music block: the caller's (the rollout's clock) over what the tracks carry; neither is an error. */
function copyMusic(music: ArrayLike<number> | null, partner: Track, me: Track, out: Out, at: number): void {
  if (music) for (let i = 0; i < MUSIC_SIZE; i++) out[at + i] = music[i];
  else if (!me.beat && !partner.beat) {
    throw new Error('no count: the tracks carry no beat and no music block was given');
  }
}

/** The figure block given (figureBlock's [104]) over the zeros the layout wrote; null: none. */
function copyFigure(figure: ArrayLike<number> | null, out: Out, at: number): void {
  if (figure) for (let i = 0; i < FIGURE_SIZE; i++) out[at + i] = figure[i];
}

const FOLLOWER_FIGURE_AT = blockSlices(FOLLOWER_INPUT_LAYOUT).figure.start;

/**
 * Input I [817] for the follower at frame t (partner = leader, whose future is steered), then the
 * figure being led (figureBlock's [104]; null: none) and the music last (musicBlock's [53]; null:
 * the count the tracks carry).
 */
export function followerInput(
  partner: Track, me: Track, t: number, out: Out, at = 0,
  figure: ArrayLike<number> | null = null, music: ArrayLike<number> | null = null,
): void {
  writeInput(FOLLOWER_PLAN, partner, me, t, out, at);
  copyFigure(figure, out, at + FOLLOWER_FIGURE_AT);
  copyMusic(music, partner, me, out, at + FOLLOWER_MUSIC_AT);
}

const LEADER_FIGURE_AT = blockSlices(LEADER_INPUT_LAYOUT).figure.start;
const HANDS_PLAN_AT = blockSlices(LEADER_INPUT_LAYOUT).hands_plan.start;

/**
 * Input I [854] for the leader (partner = follower, control = own future trajectory, then the
 * figure being led: figureBlock's [104], and the hands plan: handsPlanBlock of `handsPlan`, none
 * when null; the music last, as the follower's).
 */
export function leaderInput(
  partner: Track, me: Track, t: number, out: Out, at = 0,
  figure: ArrayLike<number> | null = null, handsPlan: ArrayLike<number> | null = null,
  music: ArrayLike<number> | null = null,
): void {
  writeInput(LEADER_PLAN, partner, me, t, out, at);
  copyFigure(figure, out, at + LEADER_FIGURE_AT);
  if (handsPlan) handsPlanBlock(handsPlan, out, at + HANDS_PLAN_AT);
  copyMusic(music, partner, me, out, at + LEADER_MUSIC_AT);
}

/** Output O [323]: the self at t+1, in the root space of t+1 (root update in t's). */
export function outputFeatures(me: Track, t: number, out: Out, at = 0): void {
  const n = t + 1;
  const x = me.root[2 * n];
  const z = me.root[2 * n + 1];
  const h = me.heading[n];
  const b = OUTPUT_BLOCKS;
  rootUpdate(me.root[2 * t], me.root[2 * t + 1], me.heading[t], x, z, h, out, at + b.root_update.start);
  trajectoryAt(me, n, FUTURE_OFFSETS, x, z, h, out, at + b.trajectory_future.start);
  keyJointsAt(me, n, FUTURE_OFFSETS, x, z, h, out, at + b.key_joints_future.start);
  poseAt(me, n, x, z, h, out, at + b.pose.start);
  copyFrame(me.positions, POSITIONS_SIZE, n, gatherPositions);
  copyFrame(me.positions, POSITIONS_SIZE, t, gatherPrevious);
  footContacts(gatherPositions, gatherPrevious, out, at + b.contacts.start);
}

/** The partner's key joints 1 s ahead [90], in the self root space at t. */
export function intentionTarget(partner: Track, me: Track, t: number, out: Out, at = 0): void {
  keyJointsAt(partner, t, FUTURE_OFFSETS, me.root[2 * t], me.root[2 * t + 1], me.heading[t], out, at);
}

export interface Slice {
  start: number;
  end: number;
}

/** {name: {start, end}} for a layout list (Python's slice(start, end)). */
export function blockSlices(layout: Layout): Record<string, Slice> {
  const out: Record<string, Slice> = {};
  let start = 0;
  for (const [name, size] of layout) {
    out[name] = { start, end: start + size };
    start += size;
  }
  return out;
}
