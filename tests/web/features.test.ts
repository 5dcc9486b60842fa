// web/mirror/features.ts against training/mirror/features.py: constants and layouts, root space, every block,
// the model inputs, outputs and intention targets of two procedural dancers circling each other.

import { describe, expect, it } from 'vitest';
import * as F from '../../web/mirror/features';
import { expectClose, fixture, trackOf } from './fixture';

const data = fixture('features');
const leader = trackOf(data, 'leader');
const follower = trackOf(data, 'follower');
const times: number[] = data.t;

describe('constants and layouts', () => {
  it('match Python', () => {
    const c = data.constants;
    expect(F.KEYS).toBe(c.KEYS);
    expect(F.KEY_STEP).toBe(c.KEY_STEP);
    expect([...F.PAST_OFFSETS]).toEqual(c.PAST_OFFSETS);
    expect([...F.FUTURE_OFFSETS]).toEqual(c.FUTURE_OFFSETS);
    expect(F.HISTORY).toBe(c.HISTORY);
    expect([F.INPUT_SIZE, F.OUTPUT_SIZE, F.INTENTION_SIZE]).toEqual([c.INPUT_SIZE, c.OUTPUT_SIZE, c.INTENTION_SIZE]);
    expect(F.FOLLOWER_INPUT_LAYOUT).toEqual(c.FOLLOWER_INPUT_LAYOUT);
    expect(F.LEADER_INPUT_LAYOUT).toEqual(c.LEADER_INPUT_LAYOUT);
    expect(F.OUTPUT_LAYOUT).toEqual(c.OUTPUT_LAYOUT);
    expect(F.INTENTION_LAYOUT).toEqual(c.INTENTION_LAYOUT);
    expect([F.CONTACT_HEIGHT, F.CONTACT_SPEED]).toEqual([c.CONTACT_HEIGHT, c.CONTACT_SPEED]);
    expect([F.LEADER_INPUT_SIZE, F.FIGURE_SIZE]).toEqual([c.LEADER_INPUT_SIZE, c.FIGURE_SIZE]);
    expect(F.FIGURE_KINDS.map((k) => [...k])).toEqual(c.FIGURE_KINDS);
    expect(F.FIGURE_KINDS.map(([n, w]) => F.figureKind(n, w))).toEqual([0, 1, 2, 3]);
    expect([F.INPUT_SIZE, F.LEADER_INPUT_SIZE, F.FIGURE_SIZE]).toEqual([817, 854, 104]);
    expect([...F.FIGURE_OFFSETS]).toEqual(c.FIGURE_OFFSETS);
  });

  it('blockSlices gives Python slices', () => {
    const slices = F.blockSlices(F.FOLLOWER_INPUT_LAYOUT);
    for (const [name, [start, end]] of Object.entries(data.constants.followerSlices as Record<string, [number, number]>)) {
      expect(slices[name], name).toEqual({ start, end });
    }
  });
});

describe('root space', () => {
  const r = data.rootSpace;
  const n = r.points.length / 3;
  const run = (f: (out: Float64Array) => void) => {
    const out = new Float64Array(n * 3);
    f(out);
    return out;
  };
  it('toRootSpacePoints', () => {
    expectClose(run((o) => F.toRootSpacePoints(r.points, 0, n, r.root[0], r.root[1], r.heading, o, 0)), r.toPoints, 'points');
  });
  it('toRootSpaceDirections', () => {
    expectClose(run((o) => F.toRootSpaceDirections(r.points, 0, n, r.heading, o, 0)), r.toDirections, 'directions');
  });
  it('fromRootSpacePoints', () => {
    expectClose(run((o) => F.fromRootSpacePoints(r.points, 0, n, r.root[0], r.root[1], r.heading, o, 0)), r.fromPoints, 'points');
  });
  it('fromRootSpaceDirections', () => {
    expectClose(run((o) => F.fromRootSpaceDirections(r.points, 0, n, r.heading, o, 0)), r.fromDirections, 'directions');
  });
  it('from undoes to', () => {
    const local = run((o) => F.toRootSpacePoints(r.points, 0, n, r.root[0], r.root[1], r.heading, o, 0));
    expectClose(run((o) => F.fromRootSpacePoints(local, 0, n, r.root[0], r.root[1], r.heading, o, 0)), r.points, 'round trip', 1e-12);
  });
});

describe('blocks', () => {
  const b = data.blocks;
  const [x, z] = b.root;
  it('trajectoryBlock', () => {
    const out = new Float64Array(F.TRAJECTORY_SIZE);
    F.trajectoryBlock(b.keyRoots, b.keyHeadings, x, z, b.heading, out, 0);
    expectClose(out, b.trajectory, 'trajectory');
  });
  it('keyJointsBlock', () => {
    const out = new Float64Array(F.KEY_JOINTS_SIZE);
    F.keyJointsBlock(b.keyPositions, x, z, b.heading, out, 0);
    expectClose(out, b.keyJoints, 'key joints');
  });
  it('poseBlock', () => {
    const t = b.poseFrame;
    const out = new Float64Array(F.POSE_SIZE);
    F.poseBlock(
      leader.positions.subarray(t * 51, t * 51 + 51), leader.positions.subarray((t - 1) * 51, t * 51),
      leader.rotations.subarray(t * 153, t * 153 + 153), x, z, b.heading, out, 0,
    );
    expectClose(out, b.pose, 'pose');
  });
  it.each((b.rootUpdates as { args: number[]; expected: number[] }[]).map((u, i): [number, typeof u] => [i, u]))('rootUpdate case %i (incl. wrap across ±π)', (_, u) => {
    const out = new Float64Array(3);
    const [rx, rz, h, nx, nz, nh] = u.args;
    F.rootUpdate(rx, rz, h, nx, nz, nh, out, 0);
    expectClose(out, u.expected, 'root update');
  });
  it('footContacts on every frame of the leader', () => {
    const out = new Float64Array(2 * (data.frames - 1));
    for (let f = 1; f < data.frames; f++) {
      F.footContacts(leader.positions.subarray(f * 51, f * 51 + 51), leader.positions.subarray((f - 1) * 51, f * 51), out, 2 * (f - 1));
    }
    expectClose(out, b.footContacts, 'contacts', 0);
  });
  it('footContacts around the height and speed thresholds', () => {
    const out = new Float64Array(2);
    for (const c of b.footCases as { positions: number[]; previous: number[]; expected: number[] }[]) {
      F.footContacts(c.positions, c.previous, out, 0);
      expectClose(out, c.expected, 'contacts', 0);
    }
  });
});

describe('figureBlock', () => {
  it('reads each figure\'s kind, inside and progress at every key of the past and next second', () => {
    for (const [n, c] of (data.figureBlocks as { figures: number[][] | null; expected: number[] }[]).entries()) {
      const flat = c.figures === null ? null : c.figures.flat();
      const out = perFrame(F.FIGURE_SIZE, (t, o, at) => F.figureBlock(flat, t, o, at));
      expectClose(out, c.expected, `figure block, case ${n} ${JSON.stringify(c.figures)}`);
    }
  });
  it('a kind that is no index into FIGURE_KINDS is an error', () => {
    const out = new Float64Array(F.FIGURE_SIZE);
    for (const kind of [-1, 4, 0.5]) expect(() => F.figureBlock([kind, 30, 40], 30, out)).toThrow(/FIGURE_KINDS/);
    expect(() => F.figureKind('her_turn', 0)).toThrow();
  });
  it('overwrites what was there, and writes nothing beyond its 104 numbers', () => {
    const out = new Float64Array(F.FIGURE_SIZE + 4).fill(7);
    F.figureBlock(null, 30, out, 2);
    expect([...out.subarray(0, 2), ...out.subarray(F.FIGURE_SIZE + 2)]).toEqual([7, 7, 7, 7]);
    expect(out.subarray(2, F.FIGURE_SIZE + 2).every((v) => v === 0)).toBe(true);
  });
});

/** Run a per-frame feature function at every fixture frame t into one [N × size] array. */
function perFrame(size: number, f: (t: number, out: Float64Array, at: number) => void): Float64Array {
  const out = new Float64Array(times.length * size);
  times.forEach((t, i) => f(t, out, i * size));
  return out;
}

describe('model inputs, outputs and intention', () => {
  it('followerInput (partner = leader)', () => {
    expectClose(perFrame(F.INPUT_SIZE, (t, o, at) => F.followerInput(leader, follower, t, o, at)), data.followerInput, 'follower input');
  });
  it('leaderInput (partner = follower, control = own future)', () => {
    expectClose(perFrame(F.LEADER_INPUT_SIZE, (t, o, at) => F.leaderInput(follower, leader, t, o, at)), data.leaderInput, 'leader input');
  });
  it('both inputs with a figure being led, the leader\'s with a hands plan (his hands\' moves)', () => {
    const spans = data.ledSpans as number[];
    const moves = data.handsMoves as number[];
    const size = F.HANDS_PLAN_SIZE - 1;
    const figure = new Float64Array(F.FIGURE_SIZE);
    const led = perFrame(F.LEADER_INPUT_SIZE, (t, o, at) => {
      const i = at / F.LEADER_INPUT_SIZE;
      F.figureBlock(spans, t, figure);
      F.leaderInput(follower, leader, t, o, at, figure, moves.slice(i * size, (i + 1) * size));
    });
    expectClose(led, data.leaderInputLed, 'leader input, a figure led');
    const felt = perFrame(F.INPUT_SIZE, (t, o, at) => {
      F.figureBlock(spans, t, figure);
      F.followerInput(leader, follower, t, o, at, figure);
    });
    expectClose(felt, data.followerInputLed, 'follower input, a figure led');
  });
  it('outputFeatures of both dancers (incl. foot contacts)', () => {
    expectClose(perFrame(F.OUTPUT_SIZE, (t, o, at) => F.outputFeatures(follower, t, o, at)), data.followerOutput, 'follower output');
    expectClose(perFrame(F.OUTPUT_SIZE, (t, o, at) => F.outputFeatures(leader, t, o, at)), data.leaderOutput, 'leader output');
  });
  it('intentionTarget of both dancers', () => {
    expectClose(perFrame(F.INTENTION_SIZE, (t, o, at) => F.intentionTarget(leader, follower, t, o, at)), data.followerIntention, 'follower intention');
    expectClose(perFrame(F.INTENTION_SIZE, (t, o, at) => F.intentionTarget(follower, leader, t, o, at)), data.leaderIntention, 'leader intention');
  });
  it('writes float32 policy inputs at an offset and nothing else', () => {
    const out = new Float32Array(F.INPUT_SIZE + 10).fill(7);
    F.followerInput(leader, follower, times[0], out, 5);
    expect([...out.subarray(0, 5), ...out.subarray(F.INPUT_SIZE + 5)]).toEqual(Array(10).fill(7));
    expectClose(out.subarray(5, F.INPUT_SIZE + 5), data.followerInput.slice(0, F.INPUT_SIZE), 'float32 input');
  });
  it('every block of the follower input is checked on its own (a bad block is named)', () => {
    const out = perFrame(F.INPUT_SIZE, (t, o, at) => F.followerInput(leader, follower, t, o, at));
    for (const [name, { start, end }] of Object.entries(F.blockSlices(F.FOLLOWER_INPUT_LAYOUT))) {
      for (let i = 0; i < times.length; i++) {
        const base = i * F.INPUT_SIZE;
        expectClose(out.subarray(base + start, base + end), data.followerInput.slice(base + start, base + end), `${name} at t=${times[i]}`);
      }
    }
  });
});
