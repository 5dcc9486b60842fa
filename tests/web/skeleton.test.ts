// web/mirror/skeleton.ts against training/mirror/skeleton.py: constants, reduction of a generated BVH to the 17
// joints (folding the collars and buttocks away), resampling, smoothing, root, mirroring, FK.

import { describe, expect, it } from 'vitest';
import { BvhError, parseBvh } from '../../web/mirror/bvh';
import {
  FEET, JOINT_NAMES, KEY_JOINTS, MIRROR, PARENTS, SCALE, FPS, facingDirection, forwardKinematicsReduced,
  gaussianSmooth, mirrorMotion, motionFromBvhText, reduceBvh, resample, rootFromMotion,
} from '../../web/mirror/skeleton';
import { expectClose, fixture } from './fixture';

const data = fixture('bvh');
const full = data.full;
const motion = () => reduceBvh(parseBvh(full.text, 'full.bvh'), 'full.bvh');

describe('constants', () => {
  it('match Python', () => {
    expect([...JOINT_NAMES]).toEqual(data.constants.names);
    expect(PARENTS).toEqual(data.constants.parents);
    expect(MIRROR).toEqual(data.constants.mirror);
    expect(KEY_JOINTS).toEqual([4, 7, 10, 13, 16]);
    expect(FEET).toEqual([13, 16]);
    expect(SCALE).toBe(1.5);
    expect(FPS).toBe(30);
  });
});

describe('reduceBvh', () => {
  it('keeps the 17 joints in metres, with offsets folded so FK stays exact', () => {
    const m = motion();
    expect(m.frames).toBe(full.frames);
    expect(m.fps).toBeCloseTo(full.reduced.fps, 9);
    expectClose(m.positions, full.reduced.positions, 'positions');
    expectClose(m.rotations, full.reduced.rotations, 'rotations');
    expectClose(m.offsets, full.reduced.offsets, 'offsets');
  });

  it.each((data.reduceErrors as { text: string; phrase: string }[]).map((e): [string, string] => [e.phrase, e.text]))(
    'refuses a skeleton it cannot reduce: "%s"',
    (phrase, text) => {
      const bvh = parseBvh(text, 'bad.bvh');
      expect(() => reduceBvh(bvh, 'bad.bvh')).toThrow(BvhError);
      expect(() => reduceBvh(bvh, 'bad.bvh')).toThrow(phrase);
    },
  );
});

describe('resample', () => {
  it('keeps every 4th frame from the phase (120 -> 30 fps)', () => {
    const r = resample(motion(), 30, 1);
    expect(r.frames).toBe(full.resampledPhase1.frames);
    expect(r.fps).toBe(30);
    expectClose(r.positions, full.resampledPhase1.positions, 'positions');
  });

  it('refuses rates that are not whole multiples, and bad phases', () => {
    expect(() => resample(motion(), 50)).toThrow('not a whole multiple');
    expect(() => resample(motion(), 30, 4)).toThrow('out of range');
  });

  it('motionFromBvhText gives the 30 fps motion of phase 0', () => {
    const m = motionFromBvhText(full.text, 'full.bvh');
    expect(m.frames).toBe(Math.ceil(full.frames / 4));
    expectClose(m.positions.subarray(0, 51), full.reduced.positions.slice(0, 51), 'frame 0');
    expectClose(m.positions.subarray(51, 102), full.reduced.positions.slice(4 * 51, 5 * 51), 'frame 1 = frame 4 at 120 fps');
  });
});

describe('gaussianSmooth', () => {
  it.each([
    ['sigma2', 2.0],
    ['sigma0_7', 0.7],
    ['sigma0', 0],
  ])('matches Python (%s)', (key, sigma) => {
    expectClose(gaussianSmooth(data.smooth.input, data.smooth.width, sigma as number), data.smooth[key as string], key as string);
  });
});

describe('root and facing', () => {
  it('facingDirection matches Python', () => {
    expectClose(facingDirection(motion().positions), full.facing, 'facing');
  });

  it('rootFromMotion matches Python (smoothed hip on the floor, heading)', () => {
    const { root, heading } = rootFromMotion(motion());
    expectClose(root, full.root, 'root');
    expectClose(heading, full.heading, 'heading');
  });
});

describe('mirrorMotion', () => {
  it('reflects x and swaps left and right like Python', () => {
    const m = mirrorMotion(motion());
    expectClose(m.positions, full.mirrored.positions, 'positions');
    expectClose(m.rotations, full.mirrored.rotations, 'rotations');
    expectClose(m.offsets, full.mirrored.offsets, 'offsets');
  });
});

describe('forwardKinematicsReduced', () => {
  it('rebuilds every frame from hip, rotations and offsets', () => {
    const m = motion();
    const out = new Float64Array(m.frames * 51);
    for (let f = 0; f < m.frames; f++) forwardKinematicsReduced(m.offsets, m.positions, f * 51, m.rotations, f * 153, out, f * 51);
    expectClose(out, full.fkReduced, 'positions');
    expectClose(out, full.reduced.positions, 'same as the full skeleton');
  });
});
