// BVH writing (web/ui/bvhwriter.ts) and recording (web/ui/record.ts): a file written from world rotations
// and a hip path, read back with the page's own reader (parseBvh + reduceBvh), gives the same
// skeleton -- FK positions within 1e-4 m, world rotations within 1e-4 -- including rotations at
// and near gimbal lock; the recorder keeps every frame up to its cap and says when it stops.

import { describe, expect, it } from 'vitest';
import { axisRotation, matmul3, parseBvh } from '../../web/mirror/bvh';
import {
  BVH_UNITS_PER_METRE, BvhWriteError, CHANNELS_PER_FRAME, eulerZXY, frameChannels, writeBvh, writeBvhFromWorld,
} from '../../web/ui/bvhwriter';
import { JOINT_NAMES, N_JOINTS, PARENTS, forwardKinematicsReduced, motionFromBvhText, reduceBvh } from '../../web/mirror/skeleton';
import { NOW, startDuet } from '../../web/mirror/rollout';
import { MAX_RECORD_FRAMES, Recorder, formatDuration, timestamp } from '../../web/ui/record';
import { leaderMotionFromText } from '../../web/ui/dropzone';
import { DuetError } from '../../web/ui/errors';
import { mulberry32 } from '../../web/engine/random';
import { fixture } from './fixture';

const data = fixture('rollout');
const OFFSETS = Float64Array.from(data.offsets.follower as number[]);
const chunk = (flat: number[]) => Array.from({ length: flat.length / 3 }, (_, i) => flat.slice(3 * i, 3 * i + 3));

function random(seed: number): () => number {
  const next = mulberry32(seed);
  return () => next() / 4294967296;
}

/** Rz(a) Rx(b) Ry(c), degrees, into out[at..]. */
function zxy(a: number, b: number, c: number, out: Float64Array, at = 0): void {
  const z = new Float64Array(9), x = new Float64Array(9), y = new Float64Array(9), zx = new Float64Array(9);
  axisRotation('Z', a, z);
  axisRotation('X', b, x);
  axisRotation('Y', c, y);
  matmul3(z, 0, x, 0, zx, 0);
  matmul3(zx, 0, y, 0, out, at);
}

/** A uniformly random rotation (unit quaternion) into out[at..]. */
function randomRotation(rand: () => number, out: Float64Array, at = 0): void {
  let w = 0, x = 0, y = 0, z = 0, n = 0;
  do {
    w = 2 * rand() - 1; x = 2 * rand() - 1; y = 2 * rand() - 1; z = 2 * rand() - 1;
    n = Math.hypot(w, x, y, z);
  } while (n < 1e-3 || n > 1);
  w /= n; x /= n; y /= n; z /= n;
  const m = [
    1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
  ];
  for (let k = 0; k < 9; k++) out[at + k] = m[k];
}

/** Locals that sit at or next to the ZXY gimbal lock (x = ±90°), in degrees. */
const NEAR_LOCK = [90, -90, 90 - 1e-7, -90 + 1e-7, 90 - 1e-4, 89.99, -89.999, 90 + 1e-6];

/**
 * A procedural take: random world rotations per joint (every 3rd frame: local rotations at or
 * next to gimbal lock instead), a hip path that wanders and bobs. Returns hips [F × 3] and world
 * rotations [F × 17 × 9].
 */
function proceduralTake(frames: number, seed: number) {
  const rand = random(seed);
  const hips = new Float64Array(frames * 3);
  const rotations = new Float64Array(frames * N_JOINTS * 9);
  const localRotation = new Float64Array(9);
  for (let f = 0; f < frames; f++) {
    hips[3 * f] = 0.8 * Math.sin(f / 9) + 0.1 * rand();
    hips[3 * f + 1] = 0.95 + 0.05 * Math.sin(f / 3);
    hips[3 * f + 2] = -0.03 * f + 0.1 * rand();
    const base = f * N_JOINTS * 9;
    for (let j = 0; j < N_JOINTS; j++) {
      if (f % 3 === 2) {
        const lock = NEAR_LOCK[(f + j) % NEAR_LOCK.length];
        zxy(360 * rand() - 180, lock, 360 * rand() - 180, localRotation);
        if (PARENTS[j] < 0) rotations.set(localRotation, base);
        else matmul3(rotations, base + 9 * PARENTS[j], localRotation, 0, rotations, base + 9 * j);
      } else {
        randomRotation(rand, rotations, base + 9 * j);
      }
    }
  }
  return { hips, rotations };
}

function maxDifference(a: ArrayLike<number>, b: ArrayLike<number>): number {
  expect(a.length).toBe(b.length);
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]));
  return worst;
}

describe('eulerZXY', () => {
  it('reproduces random rotations and rotations at gimbal lock to rounding error', () => {
    const rand = random(3);
    const m = new Float64Array(9);
    const angles = new Float64Array(3);
    const back = new Float64Array(9);
    const cases: number[][] = [];
    for (let i = 0; i < 200; i++) cases.push([360 * rand() - 180, 180 * rand() - 90, 360 * rand() - 180]);
    for (const lock of NEAR_LOCK) cases.push([37, lock, -121], [-170, lock, 175], [0, lock, 0]);
    for (const [a, b, c] of cases) {
      zxy(a, b, c, m);
      eulerZXY(m, 0, angles);
      expect(angles[1]).toBeGreaterThanOrEqual(-90);
      expect(angles[1]).toBeLessThanOrEqual(90);
      zxy(angles[0], angles[1], angles[2], back);
      expect(maxDifference(back, m), `angles ${a}, ${b}, ${c}`).toBeLessThan(1e-12);
    }
  });

  it('keeps curves continuous: a joint spinning twice about Y never jumps by 360°', () => {
    const m = new Float64Array(9);
    const angles = new Float64Array(3 * 145);
    for (let f = 0; f < 145; f++) {
      zxy(10, 20, f * 5, m); // 720° in 5° steps
      eulerZXY(m, 0, angles, 3 * f, f > 0 ? angles : null, 3 * (f - 1));
    }
    for (let f = 1; f < 145; f++) {
      expect(Math.abs(angles[3 * f + 2] - angles[3 * (f - 1) + 2])).toBeLessThan(6);
      expect(Math.abs(angles[3 * f] - angles[3 * (f - 1)])).toBeLessThan(1e-6);
    }
    expect(angles[3 * 144 + 2]).toBeCloseTo(720, 6);
  });
});

describe('writeBvh', () => {
  it('round-trips through parseBvh + reduceBvh: FK positions within 1e-4 m, rotations within 1e-4', () => {
    const frames = 60;
    const { hips, rotations } = proceduralTake(frames, 11);
    const text = writeBvhFromWorld({ offsets: OFFSETS, frames, hips, rotations });

    const bvh = parseBvh(text, 'written.bvh');
    expect(bvh.frames).toBe(frames);
    expect(bvh.frameTime).toBeCloseTo(1 / 30, 6);
    expect(bvh.channelCount).toBe(CHANNELS_PER_FRAME);
    // 17 joints + End Sites below head, both hands and both feet.
    expect(bvh.names.filter((n) => !n.endsWith('_end'))).toEqual([...JOINT_NAMES]);
    expect(bvh.names.filter((n) => n.endsWith('_end')).sort()).toEqual(['head_end', 'lFoot_end', 'lHand_end', 'rFoot_end', 'rHand_end']);
    expect(bvh.channels[0]).toEqual(['Xposition', 'Yposition', 'Zposition', 'Zrotation', 'Xrotation', 'Yrotation']);
    expect(bvh.channels[1]).toEqual(['Zrotation', 'Xrotation', 'Yrotation']);

    const motion = reduceBvh(bvh, 'written.bvh');
    expect(maxDifference(motion.offsets, OFFSETS)).toBeLessThan(1e-5);
    expect(maxDifference(motion.rotations, rotations)).toBeLessThan(1e-4);
    const expected = new Float64Array(frames * 51);
    for (let f = 0; f < frames; f++) forwardKinematicsReduced(OFFSETS, hips, 3 * f, rotations, 153 * f, expected, 51 * f);
    expect(maxDifference(motion.positions, expected)).toBeLessThan(1e-4);

    // The page reads its own recordings back in metres at 30 fps (leader playback).
    const again = motionFromBvhText(text, 'written.bvh');
    expect(again.fps).toBe(30);
    expect(again.frames).toBe(frames);
    expect(maxDifference(again.positions, expected)).toBeLessThan(1e-4);
    expect(() => leaderMotionFromText(text, 'written.bvh')).not.toThrow();
  });

  it('writes offsets in BVH units of 1/SCALE metres with a zero hip OFFSET', () => {
    const { hips, rotations } = proceduralTake(2, 5);
    const bvh = parseBvh(writeBvhFromWorld({ offsets: OFFSETS, frames: 2, hips, rotations }));
    expect(Array.from(bvh.offsets.subarray(0, 3))).toEqual([0, 0, 0]);
    const shin = bvh.names.indexOf('lShin');
    for (let k = 0; k < 3; k++) expect(bvh.offsets[3 * shin + k]).toBeCloseTo(OFFSETS[3 * 12 + k] * BVH_UNITS_PER_METRE, 6);
    expect(bvh.motion[1]).toBeCloseTo(hips[1] * BVH_UNITS_PER_METRE, 6);
  });

  it('refuses 0 frames, missing values and non-finite numbers with a clear error', () => {
    expect(() => writeBvh({ offsets: OFFSETS, frames: 0, channels: new Float64Array(0) })).toThrow(BvhWriteError);
    expect(() => writeBvh({ offsets: OFFSETS, frames: 0, channels: new Float64Array(0) })).toThrow(/0 frames/);
    expect(() => writeBvhFromWorld({ offsets: OFFSETS, frames: 0, hips: [], rotations: [] })).toThrow(/0 frames/);
    expect(() => writeBvh({ offsets: OFFSETS, frames: 2, channels: new Float64Array(CHANNELS_PER_FRAME) })).toThrow(/need 108/);
    const channels = new Float64Array(CHANNELS_PER_FRAME);
    channels[7] = NaN;
    expect(() => writeBvh({ offsets: OFFSETS, frames: 1, channels })).toThrow(/not a number/);
    expect(() => writeBvh({ offsets: OFFSETS.subarray(3), frames: 1, channels: new Float64Array(CHANNELS_PER_FRAME) })).toThrow(/offset/);
  });
});

describe('Recorder', () => {
  const manifest = {
    skeleton: { offsets: { leader: chunk(data.offsets.leader), follower: chunk(data.offsets.follower) } },
    startPose: data.startPose,
  };

  /** Move a dancer's current frame somewhere new (a stand-in for a simulation step). */
  function wiggle(duet: ReturnType<typeof startDuet>, f: number): void {
    for (const d of [duet.leader, duet.followers[0]]) {
      const t = d.track;
      t.positions[NOW * 51] += 0.02;
      const r = NOW * 153;
      zxy(3 * f, 40 * Math.sin(f / 4), -2 * f, t.rotations, r + 9 * 5); // a shoulder
      zxy(f, 0, 0, t.rotations, r + 9 * 6);
      forwardKinematicsReduced(d.offsets, t.positions, NOW * 51, t.rotations, NOW * 153, t.positions, NOW * 51);
    }
  }

  it('records every frame of both dancers; the files reproduce their skeletons', () => {
    const duet = startDuet(manifest);
    const recorder = new Recorder();
    const leaderFrames: Float64Array[] = [];
    recorder.start(duet);
    leaderFrames.push(duet.leader.positions.slice());
    // More frames than one storage chunk holds.
    for (let f = 1; f < 1000; f++) {
      wiggle(duet, f);
      recorder.capture(duet);
      if (f % 100 === 0) leaderFrames.push(duet.leader.positions.slice());
    }
    expect(recorder.frames).toBe(1000);
    expect(recorder.recording).toBe(true);
    const files = recorder.export()!;
    expect(files.frames).toBe(1000);
    const leader = reduceBvh(parseBvh(files.leader));
    const follower = reduceBvh(parseBvh(files.follower));
    expect(leader.frames).toBe(1000);
    expect(maxDifference(leader.offsets, duet.leader.offsets)).toBeLessThan(1e-5);
    expect(maxDifference(follower.offsets, duet.followers[0].offsets)).toBeLessThan(1e-5);
    leaderFrames.forEach((p, i) => expect(maxDifference(leader.positions.subarray(100 * i * 51, 100 * i * 51 + 51), p)).toBeLessThan(1e-4));
    expect(maxDifference(follower.positions.subarray(999 * 51), duet.followers[0].positions)).toBeLessThan(1e-4);
  });

  it('exports mid-take and after stop without losing frames; a stopped recorder ignores steps', () => {
    const duet = startDuet(manifest);
    const recorder = new Recorder();
    expect(recorder.export()).toBeNull();
    recorder.start(duet);
    for (let f = 1; f < 10; f++) recorder.capture(duet);
    expect(parseBvh(recorder.export()!.leader).frames).toBe(10);
    expect(recorder.saved).toBe(true);
    recorder.capture(duet);
    expect(recorder.saved).toBe(false);
    recorder.stop();
    recorder.capture(duet);
    expect(recorder.frames).toBe(11);
    expect(parseBvh(recorder.export()!.follower).frames).toBe(11);
  });

  it('stops at its cap and says so once; no frame beyond it and none dropped before it', () => {
    const duet = startDuet(manifest);
    let calls = 0;
    const recorder = new Recorder(5, () => calls++);
    recorder.start(duet);
    for (let f = 0; f < 20; f++) recorder.capture(duet);
    expect(recorder.frames).toBe(5);
    expect(recorder.recording).toBe(false);
    expect(recorder.full).toBe(true);
    expect(calls).toBe(1);
    expect(parseBvh(recorder.export()!.leader).frames).toBe(5);
    expect(MAX_RECORD_FRAMES).toBe(18000);
  });

  it('formats names and durations', () => {
    expect(timestamp(new Date(2025, 0, 31, 15, 4, 5))).toBe('20250131-150405');
    expect(formatDuration(62.5)).toBe('1:02.5');
    expect(formatDuration(600)).toBe('10:00.0');
  });
});

describe('leaderMotionFromText', () => {
  const valid = () => {
    const { hips, rotations } = proceduralTake(4, 9);
    return writeBvhFromWorld({ offsets: OFFSETS, frames: 4, hips, rotations });
  };
  const message = (text: string) => {
    try {
      leaderMotionFromText(text, 'take.bvh');
    } catch (error) {
      expect(error).toBeInstanceOf(DuetError);
      return `${(error as DuetError).title}: ${(error as DuetError).detail}`;
    }
    throw new Error('accepted');
  };

  it('says what is wrong with files it cannot dance', () => {
    expect(message('')).toMatch(/empty/);
    expect(message('hello, world')).toMatch(/not a BVH/);
    expect(message(valid().replace(/lShin/g, 'leftKnee'))).toMatch(/lacks joint.*lShin.*17-joint/);
    expect(message(valid().replace('Frame Time: 0.0333333', 'Frame Time: 0.04'))).toMatch(/25 fps.*30, 60 or 120/);
    expect(message(valid().replace('Frames: 4', 'Frames: 5'))).toMatch(/holds/);
    // One frame at 30 fps is not a dance.
    const lines = valid().split('\n');
    const motionAt = lines.indexOf('MOTION');
    const oneFrame = [...lines.slice(0, motionAt), 'MOTION', 'Frames: 1', lines[motionAt + 2], lines[motionAt + 3]].join('\n');
    expect(message(oneFrame)).toMatch(/at least 2/);
    // A skeleton in centimetres is a giant.
    const big = valid().replace(/OFFSET (\S+) (\S+) (\S+)/g, (_, x, y, z) => `OFFSET ${x * 100} ${y * 100} ${z * 100}`);
    expect(message(big)).toMatch(/from foot to head/);
  });

  it('frameChannels is a pure function of world state', () => {
    const { hips, rotations } = proceduralTake(1, 2);
    const a = new Float64Array(CHANNELS_PER_FRAME);
    const b = new Float64Array(CHANNELS_PER_FRAME);
    frameChannels(hips, 0, rotations, 0, a);
    frameChannels(hips, 0, rotations, 0, b);
    expect(Array.from(a)).toEqual(Array.from(b));
  });
});
