// A leader file (a BVH chosen in the panel or dropped on the page) as the leader's motion, and the
// one check of what it holds against what a dancer can do. Everything a file puts on the leader
// passes through leaderMotionFromText: here in a worker (leaderfile.worker.ts, so a big file does
// not stop the dance) or on the page when no worker starts (web/ui/dropzone.ts).
//
// The reader (web/mirror/bvh.ts, the twin of the Python one) takes any number a BVH can hold. A
// file can be a BVH and still no dance: a hip 1e30 m away sends both dancers (the follower follows
// its leader) and the camera after them, and at that distance the camera's few metres of offset
// from what it looks at are lost to rounding, for good. So before a motion reaches the leader,
// checkLeaderBvh holds every number of the file against generous bounds -- what a recording of a
// person could hold, with wide margins -- and refuses the file with a message naming the quantity,
// the frame, the value and the bound. Frames are counted from 1, as animation tools show them.

import { type Bvh, BvhError, parseBvh } from '../mirror/bvh';
import { JOINT_NAMES, type Motion, SCALE, motionFromBvh } from '../mirror/skeleton';
import { DuetError } from './errors';

/**
 * The bounds, in metres (a BVH unit is SCALE = 1.5 m, web/mirror/skeleton.ts), seconds and degrees.
 * Each is far beyond any dancer, and far inside what breaks the page (float64 keeps a 3 m camera
 * offset to 1e-6 m up to ~1e9 m from the origin).
 */
export const LEADER_BOUNDS = {
  /**
   * Hip's distance from the middle of the floor along X and along Z, m. The page's own 10-minute
   * recording (its limit), steered straight ahead at full stick (0.8 m/s), ends 480 m out; the
   * recorded couples stay within a few metres.
   */
  hipReach: 1000,
  /**
   * Hip height above the floor, m. Lying on the floor puts it ~0.1 m up, a leap under 2 m; the
   * metre below zero allows for a floor that is not at zero.
   */
  hipHeight: [-1, 3] as const,
  /**
   * Hip speed from one frame to the next, m/s: sprinters peak at ~12 m/s; the recorded followers'
   * root speed is 3.0 m/s at the 99th percentile (docs/plausibility.md). A file that jumps further
   * has lost frames or holds a glitch.
   */
  hipSpeed: 15,
  /**
   * Length of any OFFSET (a bone, End Sites included) and any position channel of a joint below
   * the hip, m: the longest human bone, the thigh, is ~0.5 m.
   */
  bone: 1,
  /**
   * Rotation channels, degrees either way. The page's BVH writer unwraps angles from frame to frame
   * (so curves do not jump by 360°): a dancer who keeps turning one way adds 360° a turn. Three
   * turns a second for the whole 10-minute recording is 648 000°; 1e4°, 28 turns, would refuse a
   * long recording of a spinning follower. sin and cos of 1e6° in float64 are exact to ~1e-11.
   */
  rotation: 1e6,
  /** Foot to head along the bones, m: a dancer, in the units of the CMU dance files. */
  height: [0.5, 4] as const,
};

const NAME_LENGTH = 60;

/** A file name fit for a message: no control characters, not endless. */
export function displayName(name: string): string {
  const clean = name.replace(/[\u0000-\u001f\u007f]/g, '').trim() || 'the file';
  return clean.length > NAME_LENGTH ? `${clean.slice(0, NAME_LENGTH - 1)}…` : clean;
}

/** A number for a message: 3 significant digits, powers of ten written out when large. */
function num(x: number): string {
  if (Number.isNaN(x)) return 'NaN';
  if (!Number.isFinite(x)) return x > 0 ? 'Infinity' : '-Infinity';
  const a = Math.abs(x);
  if (a !== 0 && (a >= 1e4 || a < 1e-3)) return x.toExponential(2);
  return String(Number(x.toPrecision(3)));
}

/** `value` BVH units as "value units (metres m)". */
const units = (value: number) => `${num(value)} units (${num(value * SCALE)} m)`;

/**
 * Hold every number of a parsed leader BVH against LEADER_BOUNDS; the first one outside them
 * (offsets first, then frame by frame) is returned as a sentence for the user, null when all pass.
 * The hip must be the root (reduceBvh checks that before).
 */
export function checkLeaderBvh(bvh: Bvh): string | null {
  const { names, parents, offsets, channels, frames, channelCount, motion } = bvh;
  const B = LEADER_BOUNDS;
  const joint = (j: number) => displayName(names[j]);
  const J = names.length;

  // The skeleton: numbers, then its size as a whole (a file in centimetres is a giant, and that is
  // the clearer message), then each bone.
  for (let j = 0; j < J; j++) {
    for (let a = 0; a < 3; a++) {
      if (!Number.isFinite(offsets[3 * j + a])) return `The OFFSET of ${joint(j)} holds ${num(offsets[3 * j + a])}, not a length.`;
    }
  }
  const length = (j: number) => Math.hypot(offsets[3 * j], offsets[3 * j + 1], offsets[3 * j + 2]) * SCALE;
  const chain = (name: string) => {
    let sum = 0;
    for (let j = names.indexOf(name); j >= 0 && parents[j] >= 0; j = parents[j]) sum += length(j);
    return sum;
  };
  const height = chain('head') + chain('lFoot');
  if (!(height >= B.height[0] && height <= B.height[1])) {
    return `The skeleton is ${height.toPrecision(3)} m from foot to head; expected a dancer of ` +
      `${B.height[0]}–${B.height[1]} m (units as in the CMU dance BVH files).`;
  }
  for (let j = 0; j < J; j++) {
    if (parents[j] >= 0 && length(j) > B.bone) {
      return `The OFFSET of ${joint(j)} is ${num(length(j))} m long; a dancer's bone is at most ${B.bone} m.`;
    }
  }

  // Which channel is what: joint, axis and kind per column.
  const columnJoint: number[] = [];
  const columnName: string[] = [];
  for (let j = 0; j < J; j++) {
    for (const name of channels[j]) {
      columnJoint.push(j);
      columnName.push(name);
    }
  }
  const root = parents.indexOf(-1);
  const hipColumn = [-1, -1, -1];
  for (let c = 0; c < channelCount; c++) {
    if (columnJoint[c] === root && columnName[c].endsWith('position')) hipColumn['XYZ'.indexOf(columnName[c][0])] = c;
  }
  const where = (f: number) => `in frame ${f + 1} of ${frames}`;
  const what = (c: number, f: number) => `${joint(columnJoint[c])} ${columnName[c]} ${where(f)}`;
  const hipName = (axis: number) => (hipColumn[axis] >= 0 ? `${joint(root)} ${columnName[hipColumn[axis]]}` : `${joint(root)} OFFSET ${'XYZ'[axis]}`);

  const hip = [0, 0, 0];
  let px = 0, py = 0, pz = 0;
  for (let f = 0; f < frames; f++) {
    const row = f * channelCount;
    for (let c = 0; c < channelCount; c++) {
      const value = motion[row + c];
      const name = columnName[c];
      if (!Number.isFinite(value)) return `${what(c, f)} is ${num(value)}, not a number a motion can hold.`;
      if (!name.endsWith('position')) {
        if (Math.abs(value) > B.rotation) {
          return `${what(c, f)} is ${num(value)}°; a rotation channel stays within ±${B.rotation.toLocaleString('en-US')}° ` +
            `(${Math.floor(B.rotation / 360).toLocaleString('en-US')} turns).`;
        }
      } else if (columnJoint[c] !== root && Math.abs(value) * SCALE > B.bone) {
        return `${what(c, f)} is ${units(value)}; a joint sits at most ${B.bone} m from its parent.`;
      }
    }
    // The hip: a position channel replaces the OFFSET (web/mirror/bvh.ts localTransforms).
    for (let a = 0; a < 3; a++) hip[a] = hipColumn[a] >= 0 ? motion[row + hipColumn[a]] : offsets[3 * root + a];
    for (let a = 0; a < 3; a += 2) {
      if (Math.abs(hip[a]) * SCALE > B.hipReach) {
        return `${hipName(a)} ${where(f)} is ${units(hip[a])}; a dancer stays within ${B.hipReach} m of the middle of the floor.`;
      }
    }
    const y = hip[1] * SCALE;
    if (!(y >= B.hipHeight[0] && y <= B.hipHeight[1])) {
      return `The hip height (${hipName(1)}) ${where(f)} is ${units(hip[1])}; ` +
        `a dancer's hip is between ${B.hipHeight[0]} and ${B.hipHeight[1]} m above the floor.`;
    }
    if (f > 0) {
      const speed = (Math.hypot(hip[0] - px, hip[1] - py, hip[2] - pz) * SCALE) / bvh.frameTime;
      if (speed > B.hipSpeed) {
        return `The hip moves at ${num(speed)} m/s from frame ${f} to frame ${f + 1} of ${frames}; a dancer moves under ${B.hipSpeed} m/s.`;
      }
    }
    [px, py, pz] = hip;
  }
  return null;
}

/**
 * A BVH text as a leader motion (30 fps, metres), or a DuetError whose title and detail say what is
 * wrong with the file in words a dancer understands.
 */
export function leaderMotionFromText(text: string, fileName: string): Motion {
  const name = displayName(fileName);
  const title = `Cannot dance ${name}`;
  if (text.trim() === '') throw new DuetError(title, 'The file is empty. Choose a BVH motion capture file.');
  if (!text.trimStart().startsWith('HIERARCHY')) {
    throw new DuetError(title, 'This is not a BVH file (a BVH starts with HIERARCHY). Choose a .bvh motion capture file.');
  }
  let bvh: Bvh;
  let motion: Motion;
  try {
    bvh = parseBvh(text, name);
    motion = motionFromBvh(bvh, name);
  } catch (error) {
    const message = error instanceof Error ? error.message : String(error);
    if (error instanceof BvhError && /lacks joint/.test(message)) {
      throw new DuetError(title, `${message}. The leader needs the 17-joint dancer skeleton (${JOINT_NAMES.join(', ')}).`);
    }
    if (error instanceof BvhError && /resample/.test(message)) {
      throw new DuetError(title, `${message}. Use a BVH at 30, 60 or 120 frames per second.`);
    }
    throw new DuetError(title, message);
  }
  const problem = checkLeaderBvh(bvh);
  if (problem) throw new DuetError(title, `${problem} The file may be damaged, or not the motion of a dancer.`);
  if (motion.frames < 2) throw new DuetError(title, `The motion has ${motion.frames} frame at 30 fps; the leader needs at least 2.`);
  return motion;
}
