// web/mirror/guard.ts against training/mirror/guard.py: the upright margin of follower outputs judged
// on the body they draw (two plausible ones, one tipped over by its rotations while its positions
// stand, one sunk by its hip), and the choice of the most upright; the leader's head margin.

import { describe, expect, it } from 'vitest';
import { FIGURE_KINDS, FIGURE_OFFSETS, INPUT_SIZE, LEADER_INPUT_LAYOUT, LEADER_INPUT_SIZE, OUTPUT_SIZE, blockSlices, figureKind } from '../../web/mirror/features';
import { PARTNER_HIPS, hipSlackFor, mostUpright, slackFor, uprightMargin } from '../../web/mirror/guard';
import { expectClose, fixture } from './fixture';

const data = fixture('rollout');
const { outputs, ranges, margins, best, tight, tightMargins, slackMargins, hipSlackMargins, hipSlackBest, partnerHips, hipSlackFor: hipCases } =
  data.upright;
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

describe('the follower guard\'s hip margin', () => {
  it('judges her hips alone from further up, as Python does', () => {
    const out = Float32Array.from(outputs);
    const got = margins.map((_: number, i: number) => uprightMargin(out, i * OUTPUT_SIZE, ranges, offsets, 0, -0.1));
    expectClose(got, hipSlackMargins, 'margins with her hips judged 0.1 m further from the edge');
    expect(got[3]).toBeCloseTo(margins[3] - 0.1, 5); // the sunk body: its hips were what bound
    expect(mostUpright(out, margins.length, OUTPUT_SIZE, ranges, offsets, 0, -0.1)).toBe(hipSlackBest);
  });
});

describe('the follower guard beside his lunge', () => {
  it('judges her hips from partnerLowHipMargin while her input shows his hips below partnerLow, as Python does', () => {
    expect(PARTNER_HIPS).toBe(partnerHips);
    for (const c of hipCases) {
      const input = new Float32Array(c.size);
      input[PARTNER_HIPS] = c.hips;
      const slack = hipSlackFor(input, c.margin, c.hipMargin ?? undefined, c.partnerLow ?? undefined, c.partnerLowHipMargin ?? undefined);
      expect(slack, JSON.stringify(c)).toBeCloseTo(c.slack, 6);
    }
    // his hips low in her input: judged from 0.2 m (slack -0.15); standing tall: from the hipMargin (-0.1)
    expect(hipCases[0].slack).toBeCloseTo(-0.15, 6);
    expect(hipCases[1].slack).toBeCloseTo(-0.1, 6);
    expect(hipCases[5].slack).toBe(0); // a leader's own input is never judged by her partner's hips
  });
});

describe('the leader guard\'s head margin', () => {
  it('lets off the head over the hips alone, as Python does', () => {
    const out = Float32Array.from(outputs);
    const judged = (slack: number) => margins.map((_: number, i: number) => uprightMargin(out, i * OUTPUT_SIZE, tight, offsets, slack));
    expectClose(judged(0), tightMargins, 'margins under a range whose head part binds');
    expectClose(judged(0.04), slackMargins, 'the same with 0.04 m of head slack');
    expect(slackMargins[0]).toBeCloseTo(tightMargins[0] + 0.04, 5); // the head part was binding
    expect(slackMargins[3]).toBeLessThan(0); // the sunk body stays low
  });

  it('is let off only with a headMargin, and not while a figure runs or comes', () => {
    expect(slackFor(new Float32Array(LEADER_INPUT_SIZE), 0.07, 0.03)).toBeCloseTo(0.04, 12);
    const leading = new Float32Array(LEADER_INPUT_SIZE);
    const figure = blockSlices(LEADER_INPUT_LAYOUT).figure.start;
    const now = FIGURE_OFFSETS.indexOf(0);
    leading[figure + 2 * (now * FIGURE_KINDS.length + figureKind('her_turn', 1))] = 1; // her turn, inside now
    expect(slackFor(leading, 0.07, 0.03)).toBe(0);
    expect(slackFor(new Float32Array(LEADER_INPUT_SIZE), 0.07)).toBe(0);
    expect(slackFor(new Float32Array(INPUT_SIZE).fill(1), 0.07, 0.03)).toBeCloseTo(0.04, 12); // a follower's input
  });
});
