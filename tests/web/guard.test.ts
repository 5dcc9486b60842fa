// web/mirror/guard.ts against training/mirror/guard.py: the upright margin of follower outputs judged
// on the body they draw (two plausible ones, one tipped over by its rotations while its positions
// stand, one sunk by its hip), and the choice of the most upright; the leader's head margin.

import { describe, expect, it } from 'vitest';
import { INPUT_SIZE, LEADER_INPUT_SIZE, OUTPUT_SIZE } from '../../web/mirror/features';
import { HAND_HEIGHTS, HAND_PLAN_FIRST, HANDS_PLAN_SHOWN, hipSlackFor, leadHandMiss, mostUpright, nearPlan, nearestPlan, showsPlan, slackFor, uprightMargin } from '../../web/mirror/guard';
import { expectClose, fixture } from './fixture';

const data = fixture('rollout');
const { outputs, ranges, margins, best, tight, tightMargins, slackMargins, hipSlackMargins, hipSlackBest, handsPlanShown, hipSlack: hipCases } =
  data.upright;
const { handHeights, handPlanFirst, planInput, planMiss, planBest, planBestStanding, nearPlan: nearPlanCases } = data.upright;
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

describe('the hips judged from their own margin', () => {
  it('lets off the hips by margin - hipMargin (none without one), as Python does', () => {
    for (const c of hipCases) expect(hipSlackFor(c.margin, c.hipMargin ?? undefined), JSON.stringify(c)).toBeCloseTo(c.slack, 12);
    expect(hipCases[0].slack).toBeCloseTo(-0.15, 12); // hers, shipped: from 0.20 m, 0.15 m more than the margin
    expect(hipCases[3].slack).toBe(0);
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

  it('is let off unless his input shows a hands plan (he leads a turn), and only with a headMargin', () => {
    expect(HANDS_PLAN_SHOWN).toBe(handsPlanShown);
    const input = new Float32Array(LEADER_INPUT_SIZE);
    expect(slackFor(input, 0.07, 0.03)).toBeCloseTo(0.04, 12);
    input[HANDS_PLAN_SHOWN] = 1;
    expect(slackFor(input, 0.07, 0.03)).toBe(0);
    expect(slackFor(new Float32Array(LEADER_INPUT_SIZE), 0.07)).toBe(0);
    expect(slackFor(new Float32Array(INPUT_SIZE).fill(1), 0.07, 0.03)).toBeCloseTo(0.04, 12); // not a leader's input
  });
});

describe('the leader guard keeps his lead hand to a request\'s plan', () => {
  it('reads his hands and their plan where Python does, and measures the lead hand\'s miss as Python does', () => {
    expect(HAND_HEIGHTS).toEqual(handHeights);
    expect(HAND_PLAN_FIRST).toEqual(handPlanFirst);
    const input = Float32Array.from(planInput);
    expect(showsPlan(input)).toBe(true);
    expect(showsPlan(new Float32Array(LEADER_INPUT_SIZE))).toBe(false);
    const out = Float32Array.from(outputs);
    const got = planMiss.map((_: number, i: number) => leadHandMiss(out, i * OUTPUT_SIZE, input, offsets));
    expectClose(got, planMiss, 'lead hand misses');
  });

  it('takes the standing sample nearest the plan, as Python does', () => {
    const input = Float32Array.from(planInput);
    const out = Float32Array.from(outputs);
    expect(nearestPlan(out, planMiss.length, OUTPUT_SIZE, input, ranges, offsets, 0)).toBe(planBest);
    // At 0.05 m the nearer body is within the margin: the standing one is taken instead.
    expect(planBestStanding).not.toBe(planBest);
    expect(nearestPlan(out, planMiss.length, OUTPUT_SIZE, input, ranges, offsets, 0.05)).toBe(planBestStanding);
    // None standing: the most upright.
    expect(nearestPlan(out, planMiss.length, OUTPUT_SIZE, input, ranges, offsets, 5)).toBe(best);
  });

  it('marks the n standing samples nearest the plan, as Python does', () => {
    const input = Float32Array.from(planInput);
    const out = Float32Array.from(outputs);
    const near: boolean[] = [];
    for (const [margin, expected] of Object.entries(nearPlanCases as Record<string, boolean[][]>)) {
      expected.forEach((marks, i) => {
        nearPlan(out, planMiss.length, OUTPUT_SIZE, input, ranges, offsets, Number(margin), i + 1, near);
        expect(near.slice(0, planMiss.length), `margin ${margin}, n ${i + 1}`).toEqual(marks);
      });
    }
    // The cases hold a choice: one body, then two, at margin 0; at 0.05 the nearer does not stand.
    const trues = (marks: boolean[]) => marks.filter(Boolean).length;
    expect((nearPlanCases as Record<string, boolean[][]>)['0.0'].map(trues).slice(0, 2)).toEqual([1, 2]);
    expect((nearPlanCases as Record<string, boolean[][]>)['0.05'][0]).not.toEqual((nearPlanCases as Record<string, boolean[][]>)['0.0'][0]);
  });
});
