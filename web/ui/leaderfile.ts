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
// A broken file (cut short by a download, a brace or a number missing) is named as such in plain
// words too (bvhLayoutProblem, plainBvhError), never in the reader's own ("list index out of range").

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

/** A whole number with its thousands apart (narrow no-break spaces): 19 224. */
const count = (n: number) => Math.round(n).toString().replace(/\B(?=(\d{3})+(?!\d))/g, '\u202f');

const AGAIN = 'Download or record it again.';

/** The line (from 1) of the first whitespace-separated `token` in `text` at or after line `from`. */
function lineOf(text: string, token: string, from = 1): number | null {
  const lines = text.split('\n');
  for (let i = from - 1; i < lines.length; i++) if (lines[i].split(/\s+/).includes(token)) return i + 1;
  return null;
}

/**
 * What is wrong with the layout of a BVH text, as a sentence for a visitor, or null when its
 * sections, braces and numbers are all there (what they hold is for the reader and the check).
 * Run before the reader, whose messages are about its own workings ("list index out of range" for
 * a file that ends inside its skeleton): a file cut short by a failed download or copy is the
 * usual case, and gets "The file is cut short", with how far it goes.
 */
export function bvhLayoutProblem(text: string): string | null {
  const tokens = text.split(/\s+/).filter((t) => t.length > 0);
  const motion = tokens.indexOf('MOTION');
  const skeleton = motion < 0 ? tokens : tokens.slice(0, motion);
  let open = 0, close = 0, depth = 0, channels = 0;
  let badChannels: string | null = null;
  for (let i = 0; i < skeleton.length; i++) {
    if (skeleton[i] === '{') open++, depth++;
    else if (skeleton[i] === '}') close++, depth--;
    else if (skeleton[i] === 'CHANNELS' && i + 1 < skeleton.length) {
      if (/^\+?\d+$/.test(skeleton[i + 1])) channels += Number(skeleton[i + 1]);
      else badChannels ??= skeleton[i + 1];
    }
  }
  if (motion < 0) {
    return depth > 0 || open === 0
      ? `The file is cut short: it ends inside the skeleton (HIERARCHY), before the motion (MOTION) begins. ${AGAIN}`
      : 'The file has a skeleton (HIERARCHY) but no motion: its MOTION section is missing.';
  }
  if (badChannels !== null) {
    const line = lineOf(text, 'CHANNELS');
    return `A CHANNELS line of the skeleton${line ? ` (line ${lineOf(text, badChannels, line) ?? line})` : ''} gives "${badChannels.slice(0, 20)}" where the number of channels should be.`;
  }
  if (open !== close) {
    return `The skeleton (HIERARCHY) has ${open} opening braces { and ${close} closing braces }: ` +
      `${open > close ? 'a closing brace is missing' : 'there is a closing brace too many'}.`;
  }
  const rest = tokens.slice(motion + 1);
  if (rest.length < 5) {
    return `The file is cut short: it ends right after MOTION, before its "Frames:" and "Frame Time:" lines. ${AGAIN}`;
  }
  if (rest[0] !== 'Frames:' || rest[2] !== 'Frame' || rest[3] !== 'Time:') {
    return 'The MOTION section does not start with its "Frames:" and "Frame Time:" lines.';
  }
  if (!/^\+?\d+$/.test(rest[1])) return `Its "Frames:" line says ${rest[1].slice(0, 20)}; the number of frames is a whole number.`;
  const frames = Number(rest[1]);
  if (frames === 0) return 'Its "Frames:" line says 0: the file holds no motion.';
  const values = rest.length - 5;
  const expected = frames * channels;
  if (channels > 0 && values < expected) {
    const whole = Math.floor(values / channels);
    return `The file is cut short: it ends ${values % channels === 0 ? `after frame ${whole}` : `in frame ${whole + 1}`} ` +
      `of the ${count(frames)} it announces (it holds ${count(values)} of the ${count(expected)} numbers they need). ${AGAIN}`;
  }
  const last = tokens[tokens.length - 1];
  if (channels > 0 && values === expected && !/\s$/.test(text) && Number.isNaN(Number(last)) && !/^[+-]?nan$/i.test(last)) {
    return `The file is cut short: it ends in the middle of the last number of frame ${count(frames)} ("${last.slice(0, 20)}"). ${AGAIN}`;
  }
  if (channels > 0 && values > expected) {
    return `The file holds ${count(values)} numbers where its ${count(frames)} frames of ${channels} channels make ` +
      `${count(expected)}: its "Frames:" line is wrong, or a frame has numbers too many.`;
  }
  return null;
}

/** A message of the BVH reader (web/mirror/bvh.ts, skeleton.ts) in words for a visitor. */
function plainBvhError(message: string, text: string, name: string): string {
  const said = message.startsWith(`${name}: `) ? message.slice(name.length + 2) : message;
  const motionLine = text.split('\n').findIndex((l) => l.trim() === 'MOTION') + 1;
  const where = (token: string, inMotion: boolean) => {
    const line = lineOf(text, token, inMotion && motionLine > 0 ? motionLine : 1);
    if (line === null) return '';
    if (inMotion && motionLine > 0 && line > motionLine + 2) return ` (line ${line}: frame ${line - motionLine - 2})`;
    return ` (line ${line})`;
  };
  let m: RegExpMatchArray | null;
  if ((m = /could not convert string to float: '(.*)'\)?$/.exec(said))) return `The file holds "${m[1].slice(0, 20)}" where a number should be${where(m[1], true)}.`;
  if ((m = /invalid literal for int\(\): '(.*)'\)?$/.exec(said))) return `The file holds "${m[1].slice(0, 20)}" where a whole number should be${where(m[1], false)}.`;
  if ((m = /^unexpected token '(.*)' in HIERARCHY$/.exec(said))) {
    return `The skeleton (HIERARCHY) holds "${m[1].slice(0, 20)}"${where(m[1], false)}, where a BVH has JOINT, End Site, OFFSET, CHANNELS, a brace or MOTION.`;
  }
  if (/list index out of range/.test(said)) return `The file is cut short: it ends inside the skeleton (HIERARCHY). ${AGAIN}`;
  if (/unbalanced braces/.test(said)) return 'The skeleton (HIERARCHY) has a closing brace } without its opening one.';
  if ((m = /^Frame Time must be positive, got (.*)$/.exec(said))) return `Its "Frame Time:" is ${m[1]} s; it must be above zero (0.0333333 for 30 frames a second).`;
  if (/^BVH has no joints$/.test(said)) return 'The skeleton (HIERARCHY) has no joints.';
  const skeleton = `The leader needs the 17-joint dancer skeleton (${JOINT_NAMES.join(', ')}).`;
  if (/^skeleton lacks joint/.test(said)) return `The ${said}. ${skeleton}`;
  if ((m = /^'(.*)' must be the root joint$/.exec(said))) return `This is another skeleton: "${m[1]}" is not its first (root) joint. ${skeleton}`;
  if ((m = /^'(.*)' is not below '(.*)'$/.exec(said))) return `This is another skeleton: "${m[1]}" does not hang below "${m[2]}". ${skeleton}`;
  if ((m = /^joint '(.*)' rotates; cannot reduce$/.exec(said))) {
    return `This is another skeleton: its joint "${m[1]}", which the dancers do not have, moves during the dance. ${skeleton}`;
  }
  if ((m = /^cannot resample (.*) fps to 30 fps/.exec(said))) return `The motion is at ${m[1]} fps (frames a second); the leader dances BVH files at 30, 60 or 120 fps.`;
  return said;
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
  const layout = bvhLayoutProblem(text);
  if (layout) throw new DuetError(title, layout);
  let bvh: Bvh;
  let motion: Motion;
  try {
    bvh = parseBvh(text, name);
    motion = motionFromBvh(bvh, name);
  } catch (error) {
    const message = error instanceof Error ? error.message : String(error);
    throw new DuetError(title, error instanceof BvhError ? plainBvhError(message, text, name) : message);
  }
  const problem = checkLeaderBvh(bvh);
  if (problem) throw new DuetError(title, `${problem} The file may be damaged, or not the motion of a dancer.`);
  if (motion.frames < 2) throw new DuetError(title, `The motion has ${motion.frames} frame at 30 fps; the leader needs at least 2.`);
  return motion;
}
