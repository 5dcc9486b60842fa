// BVH writing: the 17-joint duet skeleton and one dancer's frames as a BVH file that Blender (and
// this page, as a leader recording) imports.
//
// Units: the file is written in the page's BVH units, the units of the CMU source files the
// dancers were trained on: 1 BVH unit = SCALE (1.5) metres, so the head joint sits at ~1.11 units.
// motionFromBvhText (web/mirror/skeleton.ts) multiplies by SCALE again, so a recording read back into the
// page is in metres exactly. (In Blender's BVH import, a Scale of 1.5 gives real metres.)
//
// Hierarchy: joints in JOINT_NAMES order (which is depth-first order), each OFFSET = its reduced
// offset from the manifest; End Sites below head, hands and feet, with short offsets that only give
// those bones a visible tail. Channels: hip Xposition Yposition Zposition Zrotation Xrotation
// Yrotation, every other joint Zrotation Xrotation Yrotation (R = Rz · Rx · Ry, web/mirror/bvh.ts); the hip
// OFFSET is zero and its position channels hold the world hip position.
//
// A frame's 54 channel values come from world state: the hip position and each joint's world
// rotation; local = parent_worldᵀ · world, then ZXY Euler angles in degrees (robust at gimbal
// lock, unwrapped against the previous frame so animation curves do not jump by 360°).

import { FPS, JOINT_NAMES, N_JOINTS, PARENTS, ROTATIONS_SIZE, SCALE } from '../mirror/skeleton';

/** BVH units per metre (see the header comment). */
export const BVH_UNITS_PER_METRE = 1 / SCALE;
/** Numbers per frame: 6 for the hip, 3 for each of the other 16 joints. */
export const CHANNELS_PER_FRAME = 6 + 3 * (N_JOINTS - 1);

const DEG = 180 / Math.PI;

/** End Site offsets in metres, in the joint's own frame (rest pose: Y up, the dancer faces +Z). */
const END_SITES: Record<string, [number, number, number] | 'along'> = {
  head: [0, 0.16, 0],
  lHand: 'along', // continue the forearm
  rHand: 'along',
  lFoot: [0, -0.06, 0.14], // ankle -> toes
  rFoot: [0, -0.06, 0.14],
};
const HAND_LENGTH = 0.09;

/** The writer was handed something it cannot turn into a BVH file. */
export class BvhWriteError extends Error {
  constructor(message: string) {
    super(message);
    this.name = 'BvhWriteError';
  }
}

/**
 * ZXY Euler angles of a rotation: R = Rz(z) · Rx(x) · Ry(y), read at m[at..at+9) (row-major).
 * Writes [z, x, y] in degrees to out[outAt..]. x is in [-90, 90]. z and y are each the value
 * nearest to previous[prevAt..] (same layout) modulo 360, so a smooth motion gives smooth curves.
 *
 * Near gimbal lock (x = ±90°) only z ± y is determined: z keeps the previous value (0 without one)
 * and y is solved from z, so the matrix is reproduced to rounding error however close to the lock.
 */
export function eulerZXY(
  m: ArrayLike<number>, at: number, out: Float64Array, outAt = 0, previous: ArrayLike<number> | null = null, prevAt = 0,
): void {
  // Rz Rx Ry = [[cz cy − sz sx sy, −sz cx, cz sy + sz sx cy],
  //             [sz cy + cz sx sy,  cz cx, sz sy − cz sx cy],
  //             [−cx sy,            sx,    cx cy          ]]
  const r01 = m[at + 1], r11 = m[at + 4], r20 = m[at + 6], r21 = m[at + 7], r22 = m[at + 8];
  const cx = Math.hypot(r20, r22);
  const x = Math.atan2(r21, cx);
  let z: number;
  if (Math.hypot(r01, r11) > 1e-9) z = Math.atan2(-r01, r11);
  else z = previous ? previous[prevAt] / DEG : 0;
  // (Rz Rx)ᵀ R = Ry(y); its first row is (cz, sz, 0)ᵀ R = (cos y, 0, sin y). This absorbs any error
  // in z, which matters only where z is ill-defined (gimbal lock).
  const cz = Math.cos(z), sz = Math.sin(z);
  const y = Math.atan2(cz * m[at + 2] + sz * m[at + 5], cz * m[at] + sz * m[at + 3]);
  let zd = z * DEG;
  let yd = y * DEG;
  if (previous) {
    zd = nearestTurn(zd, previous[prevAt]);
    yd = nearestTurn(yd, previous[prevAt + 2]);
  }
  out[outAt] = zd;
  out[outAt + 1] = x * DEG;
  out[outAt + 2] = yd;
}

/** angle + 360·k closest to `reference` (degrees). */
function nearestTurn(angle: number, reference: number): number {
  if (!Number.isFinite(reference)) return angle;
  return angle + 360 * Math.round((reference - angle) / 360);
}

const local = new Float64Array(9);

/**
 * One frame's 54 channel values (hip position in metres, angles in degrees) from world state: the
 * hip at hip[hipAt..+3] and 17 world rotations at rotations[rotAt..+153] (row-major). `previous`
 * (the last frame's channels, same layout) keeps the angles continuous.
 */
export function frameChannels(
  hip: ArrayLike<number>, hipAt: number, rotations: ArrayLike<number>, rotAt: number,
  out: Float64Array, at = 0, previous: ArrayLike<number> | null = null, prevAt = 0,
): void {
  out[at] = hip[hipAt];
  out[at + 1] = hip[hipAt + 1];
  out[at + 2] = hip[hipAt + 2];
  for (let j = 0; j < N_JOINTS; j++) {
    const p = PARENTS[j];
    const w = rotAt + 9 * j;
    if (p < 0) {
      for (let k = 0; k < 9; k++) local[k] = rotations[w + k];
    } else {
      // parent_worldᵀ · world
      const q = rotAt + 9 * p;
      for (let r = 0; r < 3; r++) {
        for (let c = 0; c < 3; c++) {
          local[3 * r + c] = rotations[q + r] * rotations[w + c] + rotations[q + 3 + r] * rotations[w + 3 + c] + rotations[q + 6 + r] * rotations[w + 6 + c];
        }
      }
    }
    const channel = j === 0 ? 3 : 3 + 3 * j;
    eulerZXY(local, 0, out, at + channel, previous, prevAt + channel);
  }
}

/** Shortest decimal text of x rounded to `digits` decimals ("-0" never appears). */
function num(x: number, digits: number): string {
  const text = x.toFixed(digits);
  if (text.indexOf('.') < 0) return text === '-0' ? '0' : text;
  let end = text.length;
  while (text.charCodeAt(end - 1) === 48 /* 0 */) end--;
  if (text.charCodeAt(end - 1) === 46 /* . */) end--;
  const trimmed = text.slice(0, end);
  return trimmed === '-0' ? '0' : trimmed;
}

const offsetText = (x: number, y: number, z: number) =>
  `OFFSET ${num(x * BVH_UNITS_PER_METRE, 6)} ${num(y * BVH_UNITS_PER_METRE, 6)} ${num(z * BVH_UNITS_PER_METRE, 6)}`;

/** The HIERARCHY section for a dancer with these reduced offsets ([17 × 3] metres, flat). */
export function bvhHierarchy(offsets: ArrayLike<number>): string {
  if (offsets.length !== N_JOINTS * 3) throw new BvhWriteError(`expected ${N_JOINTS * 3} offset numbers (17 joints × 3), got ${offsets.length}`);
  for (let i = 0; i < offsets.length; i++) {
    if (!Number.isFinite(offsets[i])) throw new BvhWriteError(`offset ${i} of joint '${JOINT_NAMES[Math.floor(i / 3)]}' is not a number`);
  }
  const lines: string[] = ['HIERARCHY'];
  const children = JOINT_NAMES.map((_, j) => PARENTS.flatMap((p, c) => (p === j ? [c] : [])));
  const joint = (j: number, depth: number) => {
    const pad = '\t'.repeat(depth);
    const name = JOINT_NAMES[j];
    lines.push(`${pad}${j === 0 ? 'ROOT' : 'JOINT'} ${name}`, `${pad}{`);
    if (j === 0) {
      lines.push(`${pad}\t${offsetText(0, 0, 0)}`, `${pad}\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation`);
    } else {
      lines.push(`${pad}\t${offsetText(offsets[3 * j], offsets[3 * j + 1], offsets[3 * j + 2])}`, `${pad}\tCHANNELS 3 Zrotation Xrotation Yrotation`);
    }
    for (const c of children[j]) joint(c, depth + 1);
    const end = END_SITES[name];
    if (end) {
      let [x, y, z] = end === 'along' ? [offsets[3 * j], offsets[3 * j + 1], offsets[3 * j + 2]] : end;
      if (end === 'along') {
        const length = Math.hypot(x, y, z) || 1;
        [x, y, z] = [(x / length) * HAND_LENGTH, (y / length) * HAND_LENGTH, (z / length) * HAND_LENGTH];
      }
      lines.push(`${pad}\tEnd Site`, `${pad}\t{`, `${pad}\t\t${offsetText(x, y, z)}`, `${pad}\t}`);
    }
    lines.push(`${pad}}`);
  };
  joint(0, 0);
  return lines.join('\n');
}

export interface BvhTake {
  /** [17 × 3] reduced offsets, metres (manifest.skeleton.offsets[role], flattened). */
  offsets: ArrayLike<number>;
  frames: number;
  /** [frames × 54] channel values as frameChannels writes them (hip metres, angles degrees). */
  channels: ArrayLike<number>;
  /** Frames per second; the page runs at 30. */
  fps?: number;
}

/** A whole BVH file. Refuses 0 frames and non-finite numbers (Blender would choke on them). */
export function writeBvh(take: BvhTake): string {
  const { frames, channels } = take;
  const fps = take.fps ?? FPS;
  if (!Number.isInteger(frames) || frames <= 0) {
    throw new BvhWriteError(`cannot write a BVH with ${frames} frames: nothing was recorded`);
  }
  if (!(fps > 0)) throw new BvhWriteError(`frame rate must be positive, got ${fps}`);
  if (channels.length < frames * CHANNELS_PER_FRAME) {
    throw new BvhWriteError(`${frames} frames need ${frames * CHANNELS_PER_FRAME} channel values, got ${channels.length}`);
  }
  const header = bvhHierarchy(take.offsets);
  const lines: string[] = [header, 'MOTION', `Frames: ${frames}`, `Frame Time: ${num(1 / fps, 7)}`];
  const row: string[] = new Array(CHANNELS_PER_FRAME);
  for (let f = 0; f < frames; f++) {
    const base = f * CHANNELS_PER_FRAME;
    for (let c = 0; c < CHANNELS_PER_FRAME; c++) {
      const value = channels[base + c];
      if (!Number.isFinite(value)) throw new BvhWriteError(`frame ${f} holds a value that is not a number (channel ${c})`);
      // Positions: 1e-6 units (1.5 µm); angles: 1e-5 degrees.
      row[c] = c < 3 ? num(value * BVH_UNITS_PER_METRE, 6) : num(value, 5);
    }
    lines.push(row.join(' '));
  }
  lines.push('');
  return lines.join('\n');
}

/**
 * A BVH file straight from world state: hips [frames × 3] metres and world rotations
 * [frames × 17 × 9] row-major (a Motion's rotations; its positions[f·51..] are the hips).
 */
export function writeBvhFromWorld(take: {
  offsets: ArrayLike<number>; frames: number; hips: ArrayLike<number>; hipStride?: number; rotations: ArrayLike<number>; fps?: number;
}): string {
  const { frames } = take;
  if (!Number.isInteger(frames) || frames <= 0) {
    throw new BvhWriteError(`cannot write a BVH with ${frames} frames: nothing was recorded`);
  }
  const stride = take.hipStride ?? 3;
  const channels = new Float64Array(frames * CHANNELS_PER_FRAME);
  for (let f = 0; f < frames; f++) {
    frameChannels(take.hips, f * stride, take.rotations, f * ROTATIONS_SIZE, channels, f * CHANNELS_PER_FRAME,
      f > 0 ? channels : null, (f - 1) * CHANNELS_PER_FRAME);
  }
  return writeBvh({ offsets: take.offsets, frames, channels, fps: take.fps });
}
