// Mirror of training/mirror/skeleton.py (same names in camelCase, same numbers): the 17-joint duet
// skeleton, reduction from BVH, metres, resampling, root, mirroring.
//
// A `Motion` holds one dancer as world-space joint positions and rotations per frame, flat and
// frame-major: positions [F × 17 × 3], rotations [F × 17 × 9] (row-major 3x3).

import { BvhError, type Bvh, bvhFps, forwardKinematics, localTransforms, parseBvh } from './bvh';

// BVH units -> metres. The shared CMU files were rescaled so that a dancer's head joint sits at
// about 1.11 units; 1.5 puts it at about 1.66 m, a plausible adult head-joint height.
export const SCALE = 1.5;
export const FPS = 30;

export const JOINT_NAMES = [
  'hip', 'abdomen', 'chest', 'neck', 'head',
  'lShldr', 'lForeArm', 'lHand', 'rShldr', 'rForeArm', 'rHand',
  'lThigh', 'lShin', 'lFoot', 'rThigh', 'rShin', 'rFoot',
] as const;
export const PARENTS = [-1, 0, 1, 2, 3, 2, 5, 6, 2, 8, 9, 0, 11, 12, 0, 14, 15];
export const N_JOINTS = 17;
/** Numbers per frame: joint positions [17 × 3] and world rotations [17 × 9] of a Motion or Track. */
export const POSITIONS_SIZE = N_JOINTS * 3; // 51
export const ROTATIONS_SIZE = N_JOINTS * 9; // 153
// Head, both hands, both feet: the paper's five key joints for trajectories and intention.
export const KEY_JOINTS = [4, 7, 10, 13, 16];
export const FEET = [13, 16];
export const HEAD = JOINT_NAMES.indexOf('head'); // 4
export const HANDS = [JOINT_NAMES.indexOf('lHand'), JOINT_NAMES.indexOf('rHand')]; // 7, 10
/** The torso as a chain hip -> abdomen -> chest -> neck (the partners' bodies must not cross it). */
export const SPINE = (['hip', 'abdomen', 'chest', 'neck'] as const).map((n) => JOINT_NAMES.indexOf(n)); // 0, 1, 2, 3

const isUpper = (c: string) => c >= 'A' && c <= 'Z';
/** Index of each joint's left/right twin (itself for the spine). */
export const MIRROR: number[] = JOINT_NAMES.map((n) => {
  const twin = n[0] === 'l' && isUpper(n[1]) ? 'r' + n.slice(1) : n[0] === 'r' && isUpper(n[1]) ? 'l' + n.slice(1) : n;
  return (JOINT_NAMES as readonly string[]).indexOf(twin);
});

/** Any float array a feature can be written into (policy inputs are float32, tests use float64). */
export type Out = Float32Array | Float64Array;

export interface Motion {
  /** [F × 17 × 3] world, metres. */
  positions: Float64Array;
  /** [F × 17 × 9] world, row-major. */
  rotations: Float64Array;
  /** [17 × 3] metres, in the parent's frame. */
  offsets: Float64Array;
  fps: number;
  frames: number;
}

/** Python's "{:g}" for the error messages. */
const g = (x: number) => String(Number(x.toPrecision(6)));

/**
 * Full-skeleton FK, then keep the 17 moving joints.
 *
 * Dropped joints between two kept ones (collars, buttocks) must not rotate: their constant
 * rotation and offset are folded into the child's offset, so FK on the reduced skeleton
 * reproduces the full skeleton's positions exactly.
 */
export function reduceBvh(bvh: Bvh, source = '<bvh>'): Motion {
  const missing = JOINT_NAMES.filter((n) => !bvh.names.includes(n));
  if (missing.length > 0) throw new BvhError(`${source}: skeleton lacks joint(s) ${missing.join(', ')}`);
  const local = localTransforms(bvh);
  const world = forwardKinematics(bvh.parents, local);
  const F = bvh.frames;
  const J = bvh.names.length;
  const index = JOINT_NAMES.map((n) => bvh.names.indexOf(n));
  for (let j = 0; j < N_JOINTS; j++) {
    const p = PARENTS[j];
    if (p < 0) {
      if (bvh.parents[index[j]] !== -1) throw new BvhError(`${source}: '${JOINT_NAMES[j]}' must be the root joint`);
      continue;
    }
    // Walk up the full hierarchy from the kept joint to its kept parent.
    let a = bvh.parents[index[j]];
    while (a !== index[p]) {
      if (a < 0) throw new BvhError(`${source}: '${JOINT_NAMES[j]}' is not below '${JOINT_NAMES[p]}'`);
      let change = 0;
      for (let f = 0; f < F; f++) {
        for (let k = 0; k < 9; k++) change = Math.max(change, Math.abs(local.rotations[(f * J + a) * 9 + k] - local.rotations[a * 9 + k]));
      }
      if (change > 1e-6) throw new BvhError(`${source}: joint '${bvh.names[a]}' rotates; cannot reduce`);
      a = bvh.parents[a];
    }
  }
  const positions = new Float64Array(F * N_JOINTS * 3);
  const rotations = new Float64Array(F * N_JOINTS * 9);
  for (let f = 0; f < F; f++) {
    for (let j = 0; j < N_JOINTS; j++) {
      const src = f * J + index[j];
      const dst = f * N_JOINTS + j;
      for (let k = 0; k < 3; k++) positions[dst * 3 + k] = world.positions[src * 3 + k] * SCALE;
      for (let k = 0; k < 9; k++) rotations[dst * 9 + k] = world.rotations[src * 9 + k];
    }
  }
  // Constant through time by the check above; take frame 0: offset = R_parentᵀ (p_j - p_parent).
  const offsets = new Float64Array(N_JOINTS * 3);
  for (let j = 0; j < N_JOINTS; j++) {
    const p = PARENTS[j];
    if (p < 0) continue;
    for (let r = 0; r < 3; r++) {
      let sum = 0;
      for (let c = 0; c < 3; c++) sum += rotations[p * 9 + 3 * c + r] * (positions[j * 3 + c] - positions[p * 3 + c]);
      offsets[j * 3 + r] = sum;
    }
  }
  return { positions, rotations, offsets, fps: bvhFps(bvh), frames: F };
}

/**
 * Keep every n-th frame starting at `phase` (120 fps -> 30 fps gives 4 phases per take).
 *
 * The source rate must be a whole multiple of the target rate: no interpolation is needed then,
 * and every phase is a real recorded frame.
 */
export function resample(motion: Motion, fps: number = FPS, phase = 0): Motion {
  const ratio = motion.fps / fps;
  if (Math.abs(ratio - Math.round(ratio)) > 1e-3 || Math.round(ratio) < 1) {
    throw new RangeError(`cannot resample ${g(motion.fps)} fps to ${g(fps)} fps (not a whole multiple)`);
  }
  const step = Math.round(ratio);
  if (!(phase >= 0 && phase < step)) throw new RangeError(`phase ${phase} out of range 0..${step - 1}`);
  const frames = Math.max(0, Math.ceil((motion.frames - phase) / step));
  const positions = new Float64Array(frames * N_JOINTS * 3);
  const rotations = new Float64Array(frames * N_JOINTS * 9);
  for (let f = 0; f < frames; f++) {
    const src = phase + f * step;
    positions.set(motion.positions.subarray(src * POSITIONS_SIZE, src * POSITIONS_SIZE + POSITIONS_SIZE), f * POSITIONS_SIZE);
    rotations.set(motion.rotations.subarray(src * ROTATIONS_SIZE, src * ROTATIONS_SIZE + ROTATIONS_SIZE), f * ROTATIONS_SIZE);
  }
  return { positions, rotations, offsets: motion.offsets, fps, frames };
}

/** Smooth [F × width] along the frames with edge padding (no shift, no shrinking at the ends). */
export function gaussianSmooth(x: ArrayLike<number>, width: number, sigma: number): Float64Array {
  const F = x.length / width;
  if (sigma <= 0) return Float64Array.from(x);
  const r = Math.ceil(3 * sigma);
  const kernel = new Float64Array(2 * r + 1);
  let total = 0;
  for (let i = -r; i <= r; i++) total += kernel[i + r] = Math.exp(-0.5 * (i / sigma) ** 2);
  for (let i = 0; i < kernel.length; i++) kernel[i] /= total;
  const out = new Float64Array(F * width);
  // Same order of additions as numpy (one kernel tap at a time over all frames).
  for (let i = 0; i < kernel.length; i++) {
    const w = kernel[i];
    for (let f = 0; f < F; f++) {
      const src = Math.min(F - 1, Math.max(0, f + i - r)); // edge padding
      for (let c = 0; c < width; c++) out[f * width + c] += w * x[src * width + c];
    }
  }
  return out;
}

// Root smoothing in frames at 30 fps: removes the hip's side-to-side sway from the root without
// lagging turns (a 0.07 s standard deviation).
export const ROOT_SMOOTHING = 2.0;

const L_THIGH = 11;
const R_THIGH = 14;
const L_SHLDR = 5;
const R_SHLDR = 8;

/** [F × 17 × 3] -> [F × 2] unit floor vector (x, z) the body faces (hips and shoulders). */
export function facingDirection(positions: ArrayLike<number>): Float64Array {
  const F = positions.length / POSITIONS_SIZE;
  const out = new Float64Array(F * 2);
  for (let f = 0; f < F; f++) {
    const b = f * POSITIONS_SIZE;
    const ax = positions[b + 3 * L_THIGH] - positions[b + 3 * R_THIGH] + (positions[b + 3 * L_SHLDR] - positions[b + 3 * R_SHLDR]);
    const az = positions[b + 3 * L_THIGH + 2] - positions[b + 3 * R_THIGH + 2] + (positions[b + 3 * L_SHLDR + 2] - positions[b + 3 * R_SHLDR + 2]);
    // forward = across × up, with up = +Y: (ax, ay, az) × (0, 1, 0) = (-az, 0, ax)
    const fx = -az;
    const fz = ax;
    const norm = Math.max(Math.sqrt(fx * fx + fz * fz), 1e-9);
    out[2 * f] = fx / norm;
    out[2 * f + 1] = fz / norm;
  }
  return out;
}

/** Root per frame: floor position [F × 2] (x, z) and heading [F] (radians, 0 = facing +Z). */
export function rootFromMotion(motion: Motion, smoothing = ROOT_SMOOTHING): { root: Float64Array; heading: Float64Array } {
  const F = motion.frames;
  const hip = new Float64Array(F * 2);
  for (let f = 0; f < F; f++) {
    hip[2 * f] = motion.positions[f * POSITIONS_SIZE];
    hip[2 * f + 1] = motion.positions[f * POSITIONS_SIZE + 2];
  }
  const root = gaussianSmooth(hip, 2, smoothing);
  const fwd = gaussianSmooth(facingDirection(motion.positions), 2, smoothing);
  const heading = new Float64Array(F);
  for (let f = 0; f < F; f++) heading[f] = Math.atan2(fwd[2 * f], fwd[2 * f + 1]);
  return { root, heading };
}

/**
 * Reflect through the YZ plane (x -> -x) and swap left and right joints.
 *
 * A reflected rotation is M R M with M = diag(-1, 1, 1), which keeps it a proper rotation: the
 * entries with exactly one index 0 change sign.
 */
export function mirrorMotion(motion: Motion): Motion {
  const F = motion.frames;
  const positions = new Float64Array(motion.positions.length);
  const rotations = new Float64Array(motion.rotations.length);
  const offsets = new Float64Array(N_JOINTS * 3);
  const flip = [1, -1, -1, -1, 1, 1, -1, 1, 1];
  for (let j = 0; j < N_JOINTS; j++) {
    const m = MIRROR[j];
    offsets[3 * j] = -motion.offsets[3 * m];
    offsets[3 * j + 1] = motion.offsets[3 * m + 1];
    offsets[3 * j + 2] = motion.offsets[3 * m + 2];
    for (let f = 0; f < F; f++) {
      const dst = f * N_JOINTS + j;
      const src = f * N_JOINTS + m;
      positions[3 * dst] = -motion.positions[3 * src];
      positions[3 * dst + 1] = motion.positions[3 * src + 1];
      positions[3 * dst + 2] = motion.positions[3 * src + 2];
      for (let k = 0; k < 9; k++) rotations[9 * dst + k] = flip[k] * motion.rotations[9 * src + k];
    }
  }
  return { positions, rotations, offsets, fps: motion.fps, frames: F };
}

/**
 * World positions of 17 joints from world rotations and the hip position: bone lengths exact.
 * hip at hip[hipAt..+3], rotations at rotations[rotAt..+153], result into out[at..+51].
 */
export function forwardKinematicsReduced(
  offsets: ArrayLike<number>,
  hip: ArrayLike<number>,
  hipAt: number,
  rotations: ArrayLike<number>,
  rotAt: number,
  out: Float64Array | Float32Array,
  at = 0,
): void {
  out[at] = hip[hipAt];
  out[at + 1] = hip[hipAt + 1];
  out[at + 2] = hip[hipAt + 2];
  for (let j = 1; j < N_JOINTS; j++) {
    const p = PARENTS[j];
    const r = rotAt + 9 * p;
    const x = offsets[3 * j];
    const y = offsets[3 * j + 1];
    const z = offsets[3 * j + 2];
    for (let k = 0; k < 3; k++) {
      out[at + 3 * j + k] = out[at + 3 * p + k] + (rotations[r + 3 * k] * x + rotations[r + 3 * k + 1] * y + rotations[r + 3 * k + 2] * z);
    }
  }
}

/** A BVH file as the page uses it: parsed, reduced to 17 joints, at 30 fps (first phase). */
export function motionFromBvhText(text: string, source = '<bvh>'): Motion {
  return motionFromBvh(parseBvh(text, source), source);
}

/** A parsed BVH reduced to 17 joints, at 30 fps (first phase). */
export function motionFromBvh(bvh: Bvh, source = '<bvh>'): Motion {
  const motion = reduceBvh(bvh, source);
  try {
    return resample(motion, FPS, 0);
  } catch (error) {
    throw new BvhError(`${source}: ${(error as Error).message}`);
  }
}
