// web/mirror/on_count.ts against training/mirror/on_count.py: each dancer's footwork and count read
// from its input, the footwork its next step aims at over three steps (the mean carried between
// them), and the choice among samples where all, some and none of them stand.

import { describe, expect, it } from 'vitest';
import { OUTPUT_SIZE } from '../../web/mirror/features';
import { OnCount, TURNING, countNext, footworkNext, footworkNow, nearestCount, turnRate } from '../../web/mirror/on_count';
import { expectClose, fixture } from './fixture';

const data = fixture('rollout').onCount;

describe('the footwork each dancer aims at on the count', () => {
  for (const role of ['leader', 'follower'] as const) {
    it(`reads the ${role}'s footwork and count, and aims as Python does`, () => {
      const chooser = new OnCount(role, 4, 0.8);
      for (const step of data.roles[role]) {
        const x = Float32Array.from(step.input);
        expectClose([footworkNow(x, role)], step.footwork, `${role} footwork now`);
        expectClose([countNext(x)], step.count, `${role} count at the next step`);
        expectClose([turnRate(x, role)], step.turnRate, `${role} turn rate`);
        const target = chooser.target(x);
        if (step.target === null) expect(target, `${role} turning: no target`).toBeNull();
        else expectClose([target as number], step.target, `${role} target`);
        expectClose([chooser.mean as number], step.mean, `${role} footwork mean`);
      }
    });
  }

  it('leaves a turn to the network: the last step of each role turns faster than TURNING', () => {
    for (const role of ['leader', 'follower'] as const) {
      const turning = data.roles[role].map((s: { turnRate: number[]; target: number[] | null }) => [s.turnRate[0] > TURNING, s.target === null]);
      expect(turning).toEqual([[false, false], [false, false], [true, true]]);
    }
  });

  it('refuses a chooser with fewer than two samples', () => {
    expect(() => new OnCount('leader', 1)).toThrow(/at least 2 samples/);
  });
});

describe('nearestCount', () => {
  const outputs = Float32Array.from(data.outputs);
  const k = data.standing.length;

  it('reads each sample\'s next footwork as Python does', () => {
    expectClose(Array.from({ length: k }, (_, i) => footworkNext(outputs, i * OUTPUT_SIZE)), data.footworkNext, 'footwork next');
  });

  it('takes the standing sample nearest the target, and none when none stands', () => {
    for (const [margin, best] of Object.entries(data.best)) {
      expect(nearestCount(outputs, k, OUTPUT_SIZE, data.target[0], data.standing, Number(margin)), `margin ${margin}`).toBe(best);
    }
    // the case where the choice matters: all stand, the second is nearest; at 0.05 only the first stands
    expect(new Set(Object.values(data.best))).toEqual(new Set([1, 0, -1]));
  });
});
