// Mirror of training/mirror/bvh.py: BVH reading and forward kinematics (same names in camelCase).
//
// A BVH file is a joint hierarchy (offsets + channel orders) followed by one line of channel
// values per frame. Every joint is kept, End Sites included, because a dropped joint's offset
// still places its children. Rotations are 3x3 matrices stored row-major, 9 numbers per joint per
// frame; positions are in the file's own units. Storage is flat Float64Array (frame-major), so
// the numbers match numpy's float64 math to the last few bits.

/** The file is not a BVH we can read. The message is meant for a user, one line. */
export class BvhError extends Error {
  constructor(message: string) {
    super(message);
    this.name = 'BvhError';
  }
}

export interface Bvh {
  /** Joint names, End Sites named "<parent>_end". */
  names: string[];
  /** -1 for the root; parents precede their children. */
  parents: number[];
  /** [J × 3] in file units. */
  offsets: Float64Array;
  /** Per joint, e.g. ["Zrotation", "Xrotation", "Yrotation"]. */
  channels: string[][];
  /** Seconds per frame. */
  frameTime: number;
  frames: number;
  /** Sum of the channel counts: numbers per frame. */
  channelCount: number;
  /** [F × channelCount] raw values (degrees, file units). */
  motion: Float64Array;
}

export function bvhFps(bvh: Bvh): number {
  return 1 / bvh.frameTime;
}

/** Python's int(): digits only, so "3.0" or "3x" are malformed rather than silently truncated. */
function parseInt10(token: string): number {
  if (!/^[+-]?\d+$/.test(token)) throw new SyntaxError(`invalid literal for int(): '${token}'`);
  return Number(token);
}

/** Python's float(): Number() would also accept "" and "0x10", which a BVH never holds. */
function parseFloat64(token: string): number {
  const value = Number(token);
  if (Number.isNaN(value) && !/^[+-]?nan$/i.test(token)) throw new SyntaxError(`could not convert string to float: '${token}'`);
  if (/^[+-]?0[xob]/i.test(token)) throw new SyntaxError(`could not convert string to float: '${token}'`);
  return value;
}

export function parseBvh(text: string, source = '<string>'): Bvh {
  const tokens = text.split(/\s+/).filter((t) => t.length > 0);
  // Python gives one message for both; a user dropping an empty file deserves a precise one.
  if (tokens.length === 0) throw new BvhError(`${source}: the file is empty, not a BVH file`);
  if (tokens[0] !== 'HIERARCHY') throw new BvhError(`${source}: not a BVH file (it does not start with HIERARCHY)`);
  const names: string[] = [];
  const parents: number[] = [];
  const offsets: number[][] = [];
  const channels: string[][] = [];
  const stack: number[] = [];
  // Index errors of the Python version (tokens[i] past the end, stack[-1] of an empty stack).
  const at = (i: number): string => {
    if (i >= tokens.length) throw new RangeError('list index out of range');
    return tokens[i];
  };
  const top = (): number => {
    if (stack.length === 0) throw new RangeError('unbalanced braces');
    return stack[stack.length - 1];
  };
  let frames: number;
  let frameTime: number;
  let values: Float64Array;
  try {
    let i = 1;
    while (at(i) !== 'MOTION') {
      const tok = tokens[i];
      if (tok === 'ROOT' || tok === 'JOINT') {
        names.push(at(i + 1));
        parents.push(stack.length > 0 ? top() : -1);
        offsets.push([0, 0, 0]);
        channels.push([]);
        i += 2;
      } else if (tok === 'End') {
        // "End Site": named after its parent, no channels.
        const parent = top();
        names.push(names[parent] + '_end');
        parents.push(parent);
        offsets.push([0, 0, 0]);
        channels.push([]);
        i += 2;
      } else if (tok === '{') {
        stack.push(names.length - 1);
        i += 1;
      } else if (tok === '}') {
        top();
        stack.pop();
        i += 1;
      } else if (tok === 'OFFSET') {
        offsets[top()] = [parseFloat64(at(i + 1)), parseFloat64(at(i + 2)), parseFloat64(at(i + 3))];
        i += 4;
      } else if (tok === 'CHANNELS') {
        const n = parseInt10(at(i + 1));
        const joint = top();
        channels[joint] = [];
        for (let c = 0; c < n; c++) channels[joint].push(at(i + 2 + c));
        i += 2 + n;
      } else {
        throw new BvhError(`${source}: unexpected token '${tok}' in HIERARCHY`);
      }
    }
    if (at(i + 1) !== 'Frames:' || tokens[i + 3] !== 'Frame' || tokens[i + 4] !== 'Time:') {
      throw new BvhError(`${source}: MOTION section lacks 'Frames:' / 'Frame Time:'`);
    }
    frames = parseInt10(at(i + 2));
    frameTime = parseFloat64(at(i + 5));
    values = new Float64Array(Math.max(0, tokens.length - (i + 6)));
    for (let v = 0; v < values.length; v++) values[v] = parseFloat64(tokens[i + 6 + v]);
  } catch (error) {
    if (error instanceof BvhError) throw error;
    const e = error as Error;
    throw new BvhError(`${source}: malformed BVH (${e.name}: ${e.message})`);
  }
  if (names.length === 0) throw new BvhError(`${source}: BVH has no joints`);
  let channelCount = 0;
  for (const c of channels) channelCount += c.length;
  if (frames <= 0 || values.length !== frames * channelCount) {
    throw new BvhError(`${source}: BVH says ${frames} frames of ${channelCount} channels but holds ${values.length} numbers`);
  }
  if (!(frameTime > 0)) throw new BvhError(`${source}: Frame Time must be positive, got ${frameTime}`);
  return {
    names,
    parents,
    offsets: Float64Array.from(offsets.flat()),
    channels,
    frameTime,
    frames,
    channelCount,
    motion: values,
  };
}

/** Right-handed rotation about X, Y or Z by `degrees`, written row-major into out[at..at+9). */
export function axisRotation(axis: string, degrees: number, out: Float64Array, at = 0): void {
  const a = (degrees * Math.PI) / 180;
  const c = Math.cos(a);
  const s = Math.sin(a);
  let m: number[];
  if (axis === 'X') m = [1, 0, 0, 0, c, -s, 0, s, c];
  else if (axis === 'Y') m = [c, 0, s, 0, 1, 0, -s, 0, c];
  else m = [c, -s, 0, s, c, 0, 0, 0, 1];
  for (let k = 0; k < 9; k++) out[at + k] = m[k];
}

/** a[ai..] @ b[bi..] (3x3 row-major) into out[oi..]; out may alias neither a nor b. */
export function matmul3(a: ArrayLike<number>, ai: number, b: ArrayLike<number>, bi: number, out: Float64Array, oi: number): void {
  for (let r = 0; r < 3; r++) {
    for (let c = 0; c < 3; c++) {
      out[oi + 3 * r + c] = a[ai + 3 * r] * b[bi + c] + a[ai + 3 * r + 1] * b[bi + 3 + c] + a[ai + 3 * r + 2] * b[bi + 6 + c];
    }
  }
}

export interface Transforms {
  /** [F × J × 9] row-major 3x3. */
  rotations: Float64Array;
  /** [F × J × 3]. */
  positions: Float64Array;
}

/**
 * Per frame and joint: local rotation and local translation.
 *
 * Channels apply in the order written (the first channel is the outermost rotation), which is
 * the BVH convention: "Zrotation Xrotation Yrotation" means R = Rz · Rx · Ry.
 */
export function localTransforms(bvh: Bvh): Transforms {
  const F = bvh.frames;
  const J = bvh.names.length;
  const rotations = new Float64Array(F * J * 9);
  const positions = new Float64Array(F * J * 3);
  const axis = new Float64Array(9);
  const product = new Float64Array(9);
  for (let f = 0; f < F; f++) {
    let col = f * bvh.channelCount;
    for (let j = 0; j < J; j++) {
      const r = (f * J + j) * 9;
      const p = (f * J + j) * 3;
      rotations[r] = rotations[r + 4] = rotations[r + 8] = 1;
      for (let a = 0; a < 3; a++) positions[p + a] = bvh.offsets[3 * j + a];
      for (const name of bvh.channels[j]) {
        const value = bvh.motion[col++];
        if (name.endsWith('position')) {
          positions[p + 'XYZ'.indexOf(name[0])] = value;
        } else {
          axisRotation(name[0], value, axis);
          matmul3(rotations, r, axis, 0, product, 0);
          rotations.set(product, r);
        }
      }
    }
  }
  return { rotations, positions };
}

/** World rotations and positions from local ones ([F × J × 9], [F × J × 3]); parents precede children. */
export function forwardKinematics(parents: number[], local: Transforms): Transforms {
  const J = parents.length;
  const F = local.positions.length / (J * 3);
  const rotations = new Float64Array(local.rotations.length);
  const positions = new Float64Array(local.positions.length);
  for (let f = 0; f < F; f++) {
    for (let j = 0; j < J; j++) {
      const p = parents[j];
      const r = (f * J + j) * 9;
      const t = (f * J + j) * 3;
      if (p < 0) {
        for (let k = 0; k < 9; k++) rotations[r + k] = local.rotations[r + k];
        for (let k = 0; k < 3; k++) positions[t + k] = local.positions[t + k];
      } else {
        const pr = (f * J + p) * 9;
        const pt = (f * J + p) * 3;
        matmul3(rotations, pr, local.rotations, r, rotations, r);
        const x = local.positions[t];
        const y = local.positions[t + 1];
        const z = local.positions[t + 2];
        for (let k = 0; k < 3; k++) {
          positions[t + k] = positions[pt + k] + rotations[pr + 3 * k] * x + rotations[pr + 3 * k + 1] * y + rotations[pr + 3 * k + 2] * z;
        }
      }
    }
  }
  return { rotations, positions };
}
