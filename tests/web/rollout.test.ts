// web/mirror/rollout.ts against training/mirror/rollout.py: start pose, and four steps of the duet loop from the
// procedural dancers (steering, both inputs, outputs applied, intention, and absurd outputs that
// reset a dancer: NaN, a root jump, a joint too far).

import { describe, expect, it } from 'vitest';
import { INPUT_SIZE, LEADER_INPUT_SIZE } from '../../web/mirror/features';
import * as R from '../../web/mirror/rollout';
import { type Json, expectClose, fixture, trackOf } from './fixture';

const data = fixture('rollout');
const features = fixture('features');
const NOW = R.NOW;

function expectDancer(d: R.Dancer, expected: Json, label: string): void {
  const t = d.track;
  expectClose(t.positions.subarray(NOW * 51, NOW * 51 + 51), expected.positionsNow, `${label} positions at NOW`);
  expectClose(t.positions.subarray((NOW - 1) * 51, NOW * 51), expected.positionsBefore, `${label} positions at NOW-1`);
  expectClose(t.positions.subarray(0, 51), expected.positionsFirst, `${label} positions at 0`);
  expectClose(t.rotations.subarray(NOW * 153, NOW * 153 + 153), expected.rotationsNow, `${label} rotations at NOW`);
  expectClose(t.root, expected.root, `${label} root and plan`);
  expectClose(t.heading, expected.heading, `${label} heading and plan`);
  expectClose(d.contacts, expected.contacts, `${label} contacts`);
  expect(d.resets, `${label} resets`).toBe(expected.resets);
  if (expected.intention) expectClose(d.intention!, expected.intention, `${label} intention`);
}

describe('constants', () => {
  it('match Python', () => {
    expect(R.NOW).toBe(data.NOW);
    expect(R.TRACK_FRAMES).toBe(data.TRACK_FRAMES);
  });
});

describe('rotationsFromVectors', () => {
  it('orthonormalizes like Python (Gram-Schmidt on forward)', () => {
    const r = data.rotationsFromVectors;
    const out = new Float64Array(r.expected.length);
    R.rotationsFromVectors(r.forward, r.up, r.forward.length / 3, out);
    expectClose(out, r.expected, 'rotations');
  });
});

describe('startDuet', () => {
  it('stands both partners still in the start pose, 0.8 m apart, facing each other', () => {
    const duet = R.startDuet({
      skeleton: { offsets: { leader: chunk(data.offsets.leader), follower: chunk(data.offsets.follower) } },
      startPose: data.startPose,
    });
    expectDancer(duet.leader, data.startDuet.leader, 'leader');
    expectDancer(duet.followers[0], data.startDuet.follower, 'follower');
    expect([duet.tempo, duet.beat]).toEqual([data.startDuet.tempo, data.startDuet.beat]);
  });

  it('takes the tempo asked for, else the manifest\'s, and refuses one that is not a tempo', () => {
    const skeleton = { offsets: { leader: chunk(data.offsets.leader), follower: chunk(data.offsets.follower) } };
    expect(R.startDuet({ skeleton, startPose: data.startPose }, 1, 188).tempo).toBe(188);
    expect(R.startDuet({ skeleton, startPose: data.startPose, music: { tempo: 161 } }).tempo).toBe(161);
    for (const bad of [0, -170, Number.NaN, Number.POSITIVE_INFINITY]) {
      expect(() => R.startDuet({ skeleton, startPose: data.startPose }, 1, bad), String(bad)).toThrow(/tempo/);
    }
  });

  it('falls back to a rest pose when the manifest has none (placeholder models)', () => {
    const duet = R.startDuet({ skeleton: { offsets: { leader: chunk(data.offsets.leader), follower: chunk(data.offsets.follower) } }, startPose: {} }, 2);
    expect(duet.followers).toHaveLength(2);
    const p = duet.leader.positions;
    expect(Math.min(p[13 * 3 + 1], p[16 * 3 + 1])).toBeCloseTo(0.08, 6);
    expect([...p].every(Number.isFinite)).toBe(true);
  });
});

describe('the duet loop, step by step', () => {
  // Dancers whose 61-frame tracks are frames 0..60 of the procedural tracks (NOW = their frame 30).
  const dancer = (role: 'leader' | 'follower') => {
    const d = new R.Dancer(Float64Array.from(data.offsets[role]));
    const source = trackOf(features, role, R.TRACK_FRAMES);
    d.track.positions.set(source.positions);
    d.track.rotations.set(source.rotations);
    d.track.root.set(source.root);
    d.track.heading.set(source.heading);
    return d;
  };
  const duet: R.Duet = {
    leader: dancer('leader'),
    followers: [dancer('follower')],
    startPose: data.startPose,
    steering: new R.Steering(),
    frame: 0,
    request: null,
    tempo: data.tempo,
    beat: data.beat,
  };
  const nan = (values: (number | null)[]) => Float32Array.from(values, (v) => (v === null ? NaN : v));

  (data.steps as Json[]).forEach((step, i) => {
    it(`step ${i}: steerPlan, leadPlan, stepInputs, outputIsAbsurd, finishStep (absurd: ${step.absurd})`, () => {
      if (step.ask !== null) R.askTurn(duet, step.ask);
      duet.steering.velocity.set(step.steeringBefore);
      R.steerPlan(duet.leader, duet.steering, step.stick[0], step.stick[1]);
      R.leadPlan(duet);
      expectClose(duet.steering.velocity, step.steeringAfter, 'steering velocity');
      expectClose(duet.leader.track.root, step.plannedLeaderRoot, 'steered plan');
      expectClose(duet.leader.track.heading, step.plannedLeaderHeading, 'steered plan, its facing');

      const leaderIn = new Float32Array(LEADER_INPUT_SIZE);
      const followerIn = new Float32Array(INPUT_SIZE);
      R.stepInputs(duet, leaderIn, [followerIn]);
      expectClose(leaderIn, step.leaderInput, 'leader input');
      expectClose(followerIn, step.followerInput, 'follower input');

      const leaderOut = nan(step.leaderOutput);
      const followerOut = nan(step.followerOutput);
      expect([R.outputIsAbsurd(leaderOut), R.outputIsAbsurd(followerOut)]).toEqual(step.absurd);
      R.finishStep(duet, leaderOut, [followerOut], [Float32Array.from(step.followerIntention)]);
      expectDancer(duet.leader, step.leader, 'leader');
      expectDancer(duet.followers[0], step.follower, 'follower');
      expect(duet.frame).toBe(i + 1);
    });
  });
  it('the count moved on one step of the tempo per step', () => {
    expect(duet.beat).toBeCloseTo(data.beatAfter, 12);
  });
});

describe('a turn asked for', () => {
  it('figureInput gives the planned partner turn over the request\'s life', () => {
    for (const c of data.figureInputs as { frame: number; direction: number; keys: number[] }[]) {
      expectClose(R.figureInput({ frame: c.frame, direction: c.direction, hands: new Float64Array(6) })!, c.keys, `figure keys at ${c.frame}`);
    }
    expect(R.figureInput(null)).toBeNull();
  });
  it('handsInput raises his lead hand and lowers it over the request\'s life', () => {
    const leader = new R.Dancer(Float64Array.from(data.offsets.leader));
    const source = trackOf(features, 'leader', R.TRACK_FRAMES);
    leader.track.positions.set(source.positions);
    leader.track.rotations.set(source.rotations);
    leader.track.root.set(source.root);
    leader.track.heading.set(source.heading);
    for (const c of data.handsInputs as { frame: number; direction: number; hands: number[][]; moves: number[] }[]) {
      const request = { frame: c.frame, direction: c.direction, hands: Float64Array.from(c.hands.flat()) };
      expectClose(R.handsInput(request, leader)!, c.moves, `hands plan at ${c.frame}`);
    }
    expect(R.handsInput(null, leader)).toBeNull();
  });
  it('a request ends after REQUEST_SECONDS', () => {
    const duet = R.startDuet({ skeleton: { offsets: data.offsets }, startPose: data.startPose });
    R.askTurn(duet, 1);
    const still = new Float32Array(data.steps[0].followerOutput.length);
    for (let i = 0; i < R.REQUEST_SECONDS * 30; i++) {
      expect(duet.request).not.toBeNull();
      R.finishStep(duet, null, [still]);
    }
    expect(duet.request).toBeNull();
  });
});

describe('partner guards', () => {
  it('followAnchor draws the leader toward its anchor and keepClose leashes a far follower', () => {
    const g = data.guards;
    const apart = R.startDuet({ skeleton: { offsets: data.offsets }, startPose: data.startPose });
    const f = apart.followers[0];
    for (let i = 0; i < R.TRACK_FRAMES; i++) {
      f.track.root[2 * i] += g.shift[0];
      f.track.root[2 * i + 1] += g.shift[1];
      for (let j = 0; j < 17; j++) {
        f.track.positions[51 * i + 3 * j] += g.shift[0];
        f.track.positions[51 * i + 3 * j + 2] += g.shift[1];
      }
    }
    apart.steering.anchor.set(g.anchor);
    apart.steering.velocity.set(g.velocity);
    R.followAnchor(apart.leader, apart.steering);
    expect(R.keepClose(f, apart.leader)).toBe(g.leashed);
    expectDancer(apart.leader, g.leader, 'leader');
    expectDancer(f, g.follower, 'follower');
  });
});

describe('applyOutput', () => {
  it('reads a batched output at an offset exactly like a single one', () => {
    const step = data.steps[0];
    const make = () => R.startDancer(data.offsets.follower, data.startPose.follower, 0.3, -0.2, 1.0);
    const single = make();
    const batched = make();
    R.applyOutput(single, Float32Array.from(step.followerOutput));
    const two = new Float32Array(2 * step.followerOutput.length);
    two.set(step.followerOutput, step.followerOutput.length);
    R.applyOutput(batched, two, step.followerOutput.length);
    expect(batched.track.positions).toEqual(single.track.positions);
    expect(batched.track.root).toEqual(single.track.root);
  });
});

function chunk(flat: number[]): number[][] {
  const rows: number[][] = [];
  for (let i = 0; i < flat.length; i += 3) rows.push(flat.slice(i, i + 3));
  return rows;
}
