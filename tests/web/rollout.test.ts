// web/mirror/rollout.ts against training/mirror/rollout.py: start pose, and four steps of the duet loop from the
// procedural dancers (his own figure planned, a visitor's ask, steering, both inputs, outputs applied,
// intention, and absurd outputs that reset a dancer: NaN, a root jump, a joint too far); the figures'
// schedule on the count over 420 steps (his own, her turns and his, drawn from a fixed list), their hands
// plan and bent path.

import { describe, expect, it } from 'vitest';
import { type FigureName, INPUT_SIZE, LEADER_INPUT_SIZE } from '../../web/mirror/features';
import * as R from '../../web/mirror/rollout';
import { beatsPerStep } from '../../web/mirror/music';
import { type Json, expectClose, fixture, trackOf } from './fixture';

const data = fixture('rollout');
const features = fixture('features');
const NOW = R.NOW;

/** Figures.rng giving these numbers in order (Python's fixture feeds the same list), counting its draws. */
function draws(numbers: number[]): { rng: () => number; used: () => number } {
  let used = 0;
  return { rng: () => numbers[used++], used: () => used };
}

/** Every figure as Python's fixture writes it: [name, way, start, end, asked]. */
const ledState = (figures: R.Figures) => figures.led.map((x) => [x.name, x.way, x.start, x.end, x.asked]);

/** A leader standing at frame 30 of the procedural track (his track: its frames 0..60). */
function standingLeader(): R.Dancer {
  const leader = new R.Dancer(Float64Array.from(data.offsets.leader));
  const source = trackOf(features, 'leader', R.TRACK_FRAMES);
  leader.track.positions.set(source.positions);
  leader.track.rotations.set(source.rotations);
  leader.track.root.set(source.root);
  leader.track.heading.set(source.heading);
  return leader;
}

/** A duet of that leader (his own partner: these functions read only him) at `frame`, with these figures. */
function duetAt(frame: number, led: R.Led[], leader = standingLeader()): R.Duet {
  const figures = new R.Figures(false, () => Number.NaN);
  figures.led = led;
  return { leader, followers: [leader], startPose: data.startPose, steering: new R.Steering(), frame, figures, tempo: 170, beat: 0, leadingTemperature: null };
}

const led = (name: FigureName, way: number, start: number, end: number, hands: number[] | null = null): R.Led =>
  ({ name, way, start, end, asked: false, hands: hands === null ? null : Float64Array.from(hands) });

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
  const stepDraws = draws(data.stepDraws);
  const duet: R.Duet = {
    leader: dancer('leader'),
    followers: [dancer('follower')],
    startPose: data.startPose,
    steering: new R.Steering(),
    frame: 0,
    figures: new R.Figures(true, stepDraws.rng),
    tempo: data.tempo,
    beat: data.beat,
    leadingTemperature: null,
  };
  const nan = (values: (number | null)[]) => Float32Array.from(values, (v) => (v === null ? NaN : v));

  (data.steps as Json[]).forEach((step, i) => {
    it(`step ${i}: askTurn, planFigures, steerPlan, leadPlan, stepInputs, outputIsAbsurd, finishStep (absurd: ${step.absurd})`, () => {
      if (step.ask !== null) R.askTurn(duet, step.ask);
      duet.steering.velocity.set(step.steeringBefore);
      R.planFigures(duet);
      expect(ledState(duet.figures), 'the figures').toEqual(step.led);
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
  it('the count moved on one step of the tempo per step, and his own figure drew as Python\'s', () => {
    expect(duet.beat).toBeCloseTo(data.beatAfter, 12);
    expect(stepDraws.used()).toBe(data.stepDrawn);
  });
});

describe('the figures', () => {
  const f = data.figures;

  it('constants match Python', () => {
    expect([R.FIGURE_BEATS, [...R.OWN_GAP_BEATS], R.HIS_SHARE, [...R.RAISE]]).toEqual([f.FIGURE_BEATS, f.OWN_GAP_BEATS, f.HIS_SHARE, f.RAISE]);
  });

  it('framesToBeat and figureFrom keep to the count', () => {
    const c = f.clock;
    const clock = duetAt(c.frame, []);
    clock.tempo = c.tempo;
    clock.beat = c.beat;
    for (const t of c.framesToBeat) expect(R.framesToBeat(clock, t.frame, t.beat), `to beat ${t.beat} from ${t.frame}`).toBe(t.expected);
    for (const t of c.figureFrom) {
      const x = R.figureFrom(clock, t.frame, t.name, t.way, t.asked);
      expect([x.name, x.way, x.start, x.end, x.asked], `${t.name} from ${t.frame}, way ${t.way}`).toEqual(t.expected);
    }
  });

  it('figureShare and raised over a figure', () => {
    const [name, way, start, end] = f.led;
    for (const c of f.share) {
      expect(R.figureShare(led(name, way, start, end), c.frame), `share at ${c.frame}`).toBeCloseTo(c.share, 12);
      expect(R.raised(led(name, way, start, end), c.frame), `raised at ${c.frame}`).toBeCloseTo(c.raised, 12);
    }
  });

  it('leading from LEAD_IN before an asked figure to its end (not his own), and the leader\'s variety then', () => {
    expect(R.LEAD_IN).toBe(f.LEAD_IN);
    const figures = (f.leading.led as [FigureName, number, number, number, boolean][]).map(([name, way, start, end, asked]) => ({ ...led(name, way, start, end), asked }));
    for (const c of f.leading.frames) {
      const duet = duetAt(c.frame, figures);
      expect(R.leading(duet), `leading at ${c.frame}`).toBe(c.leading);
      expect(R.leaderVariety(duet, 0.6), 'no leadingTemperature: his own').toBe(0.6);
      duet.leadingTemperature = 0.9;
      expect(R.leaderVariety(duet, 0.6), `variety at ${c.frame}`).toBe(c.variety);
    }
    expect(f.leading.frames.map((c: Json) => c.leading)).toEqual([false, false, true, true, true, false, false, false]);
  });

  it(`askTurn and planFigures: the same schedule as Python's over ${f.steps.length} steps`, () => {
    const d = draws(f.draws);
    const duet = R.startDuet({ skeleton: { offsets: { leader: chunk(data.offsets.leader), follower: chunk(data.offsets.follower) } }, startPose: data.startPose }, 1, f.tempo, true, d.rng);
    duet.beat = f.beat;
    const asks = new Map<number, number>(f.asks);
    (f.steps as { led: unknown[]; at: number | null; spans: number[] }[]).forEach((expected, frame) => {
      expect(duet.frame).toBe(frame);
      duet.figures.own = !(f.ownOff[0] <= frame && frame < f.ownOff[1]);
      if (asks.has(frame)) R.askTurn(duet, asks.get(frame)!);
      R.planFigures(duet);
      expect(ledState(duet.figures), `the figures at frame ${frame}`).toEqual(expected.led);
      const at = duet.figures.at(frame);
      expect(at === null ? null : duet.figures.led.indexOf(at), `the figure danced at ${frame}`).toBe(expected.at);
      expect(duet.figures.spans(frame), `spans at ${frame}`).toEqual(expected.spans);
      duet.frame += 1; // the clock alone, as Python's fixture runs it (no models)
      duet.beat += beatsPerStep(duet.tempo);
    });
    expect(d.used()).toBe(f.drawn);
    // Every kind was led: her turn and his, each way.
    const kinds = new Set((f.steps as { led: [string, number][] }[]).flatMap((s) => s.led.map(([n, w]) => `${n} ${w}`)));
    expect([...kinds].sort()).toEqual(['her_turn -1', 'her_turn 1', 'his_turn -1', 'his_turn 1']);
  });

  it('handsInput raises his lead hand for a figure near, and lowers it after', () => {
    for (const c of data.handsInputs as Json[]) {
      const figures = c.two
        ? (c.two as [FigureName, number, number, number][]).map(([n, w, a, b], i) => led(n, w, a, b, c.hands[i]))
        : [led(c.name, c.way, 40, 76, c.hands)];
      const duet = duetAt(c.frame, figures);
      const moves = R.handsInput(duet);
      const label = `hands plan, ${c.two ? JSON.stringify(c.two) : `${c.name} way ${c.way}`} at ${c.frame}`;
      if (c.moves === null) expect(moves, label).toBeNull();
      else expectClose(moves!, c.moves, label);
      if (!c.two) {
        if (c.handsAfter === null) expect(figures[0].hands, `${label}: hands kept`).toBeNull();
        else expectClose(figures[0].hands!, c.handsAfter, `${label}: hands kept`);
      }
    }
  });

  it('leadPlan bends his planned path for every figure near', () => {
    for (const c of data.leadPlans as Json[]) {
      const duet = duetAt(c.frame, (c.figures as [FigureName, number, number, number][]).map(([n, w, a, b]) => led(n, w, a, b)));
      R.leadPlan(duet);
      const label = `bent path, ${JSON.stringify(c.figures)} at ${c.frame}`;
      expectClose(duet.leader.track.root, c.root, label);
      expectClose(duet.leader.track.heading, c.heading, `${label}, its facing`);
    }
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
