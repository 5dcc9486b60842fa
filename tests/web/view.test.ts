// web/mirror/view.ts against training/mirror/view.py: the follower's input with her leader's body
// lifted to the partner floor (one step's input as it is, and the same with him 0.3 m lower).

import { describe, expect, it } from 'vitest';
import { INPUT_SIZE } from '../../web/mirror/features';
import { PARTNER_KEY_JOINTS, PARTNER_POSE, liftPartner, partnerLift } from '../../web/mirror/view';
import { expectClose, fixture } from './fixture';

const { inputs, floor, lifts, lifted } = fixture('rollout').partnerView;

describe('the partner floor', () => {
  it('lifts his body by what his hips lack, as Python does', () => {
    const x = Float32Array.from(inputs);
    const got = [0, 1].map((i) => partnerLift(x, floor, i * INPUT_SIZE));
    expectClose(got, lifts, 'lifts');
    expect(got[0]).toBe(0); // standing: above the floor
    expect(got[1]).toBeCloseTo(0.2, 5); // 0.3 m lower, the floor 0.1 m under his hips
    const done = [0, 1].map((i) => liftPartner(x, floor, i * INPUT_SIZE));
    expectClose(done, lifts, 'lifts returned');
    expectClose(Array.from(x), lifted, 'lifted inputs');
  });

  it('moves only his heights, and leaves a body above the floor alone', () => {
    const x = Float32Array.from(inputs);
    liftPartner(x, floor, INPUT_SIZE);
    expect(Array.from(x.subarray(0, INPUT_SIZE))).toEqual(Array.from(Float32Array.from(inputs).subarray(0, INPUT_SIZE)));
    const before = Float32Array.from(inputs);
    let changed = 0;
    for (let i = INPUT_SIZE; i < 2 * INPUT_SIZE; i++) {
      if (x[i] === before[i]) continue;
      changed++;
      const j = i - INPUT_SIZE;
      const inPose = j >= PARTNER_POSE.start && j < PARTNER_POSE.end && (j - PARTNER_POSE.start) % 12 === 1;
      const inKeys = j >= PARTNER_KEY_JOINTS.start && j < PARTNER_KEY_JOINTS.end && (j - PARTNER_KEY_JOINTS.start) % 3 === 1;
      expect(inPose || inKeys).toBe(true);
    }
    expect(changed).toBe(17 + 30); // each joint's height, each key joint's height
  });
});
