// web/mirror/guard.ts against training/mirror/guard.py: the upright margin of follower outputs judged
// on the body they draw (two plausible ones, one tipped over by its rotations while its positions
// stand, one sunk by its hip), and the choice of the most upright.

import { describe, expect, it } from 'vitest';
import { OUTPUT_SIZE } from '../../web/mirror/features';
import { mostUpright, uprightMargin } from '../../web/mirror/guard';
import { expectClose, fixture } from './fixture';

const data = fixture('rollout');
const { outputs, ranges, margins, best } = data.upright;
const offsets = Float64Array.from(data.offsets.follower);

describe('uprightMargin', () => {
  it('matches Python for each output, and finds the tipped and the sunk body', () => {
    const out = Float32Array.from(outputs);
    const got = margins.map((_: number, i: number) => uprightMargin(out, i * OUTPUT_SIZE, ranges, offsets));
    expectClose(got, margins, 'upright margins');
    expect(got[0]).toBeGreaterThan(0);
    expect(got[2]).toBeLessThan(-0.5); // lying on its side, though its decoded positions stand
    expect(got[3]).toBeLessThan(0);
  });

  it('picks the most upright sample', () => {
    expect(mostUpright(Float32Array.from(outputs), margins.length, OUTPUT_SIZE, ranges, offsets)).toBe(best);
    const tippedFirst = Float32Array.from([...outputs.slice(2 * OUTPUT_SIZE, 3 * OUTPUT_SIZE), ...outputs.slice(OUTPUT_SIZE, 2 * OUTPUT_SIZE)]);
    expect(mostUpright(tippedFirst, 2, OUTPUT_SIZE, ranges, offsets)).toBe(1);
  });
});
