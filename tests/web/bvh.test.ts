// web/mirror/bvh.ts against training/mirror/bvh.py: parsing (channel orders, End Sites, errors), local
// transforms and forward kinematics of a hand-written BVH and of a generated 21-joint one.

import { describe, expect, it } from 'vitest';
import { BvhError, forwardKinematics, localTransforms, parseBvh } from '../../web/mirror/bvh';
import { expectClose, fixture } from './fixture';

const data = fixture('bvh');

describe('parseBvh', () => {
  it('reads the tiny BVH like Python (joints, End Sites, channel orders, motion)', () => {
    const bvh = parseBvh(data.tiny.text, 'tiny.bvh');
    expect(bvh.names).toEqual(data.tiny.names);
    expect(bvh.parents).toEqual(data.tiny.parents);
    expect(bvh.channels).toEqual(data.tiny.channels);
    expect(bvh.frames).toBe(data.tiny.frames);
    expect(bvh.frameTime).toBe(data.tiny.frameTime);
    expectClose(bvh.offsets, data.tiny.offsets, 'offsets', 0);
    expectClose(bvh.motion, data.tiny.motion, 'motion', 0);
  });

  it('reads the generated full BVH hierarchy', () => {
    const bvh = parseBvh(data.full.text, 'full.bvh');
    expect(bvh.names).toEqual(data.full.names);
    expect(bvh.parents).toEqual(data.full.parents);
    expect(bvh.frames).toBe(data.full.frames);
  });

  it.each((data.parseErrors as { text: string; phrase: string }[]).map((e): [string, string] => [e.phrase, e.text]))(
    'rejects a broken file with a BvhError saying "%s"',
    (phrase, text) => {
      expect(() => parseBvh(text, 'bad.bvh')).toThrow(BvhError);
      expect(() => parseBvh(text, 'bad.bvh')).toThrow(phrase);
      // One line, naming the file.
      try {
        parseBvh(text, 'bad.bvh');
      } catch (error) {
        expect((error as Error).message.startsWith('bad.bvh: ')).toBe(true);
        expect((error as Error).message).not.toContain('\n');
      }
    },
  );
});

describe('localTransforms and forwardKinematics', () => {
  it('match Python on the tiny BVH (channel order = rotation order)', () => {
    const bvh = parseBvh(data.tiny.text);
    const local = localTransforms(bvh);
    expectClose(local.rotations, data.tiny.localRotations, 'local rotations');
    expectClose(local.positions, data.tiny.localPositions, 'local positions');
    const world = forwardKinematics(bvh.parents, local);
    expectClose(world.rotations, data.tiny.worldRotations, 'world rotations');
    expectClose(world.positions, data.tiny.worldPositions, 'world positions');
  });

  it('match Python on the full BVH', () => {
    const bvh = parseBvh(data.full.text);
    const world = forwardKinematics(bvh.parents, localTransforms(bvh));
    expectClose(world.positions, data.full.fullWorldPositions, 'world positions');
  });
});
