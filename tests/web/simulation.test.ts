// The page's Simulation (createSimulation in web/engine/simulation.ts) on fake policies: views in world
// space, compare mode, ghosts that leave the real state alone, resets on absurd output, leader
// playback from a recording, foot locking on the drawn pose only, step timing.

import { describe, expect, it, vi } from 'vitest';
import { FIGURE_KINDS, FOLLOWER_INPUT_LAYOUT, INPUT_SIZE, LEADER_INPUT_LAYOUT, LEADER_INPUT_SIZE, OUTPUT_LAYOUT, OUTPUT_SIZE, Track, blockSlices, figureKind } from '../../web/mirror/features';
import { ANCHOR_FREE, ANCHOR_RATE, NOW, figureFrom } from '../../web/mirror/rollout';
import { type DuetSimulation, createSimulation } from '../../web/engine/simulation';
import type { Motion } from '../../web/mirror/skeleton';
import type { Manifest, StepPolicy } from '../../web/engine/types';
import { ANKLE_FLOOR } from '../../web/mirror/footik';
import { OnCount } from '../../web/mirror/on_count';
import { fixture, trackOf } from './fixture';

const data = fixture('rollout');
const OUT = blockSlices(OUTPUT_LAYOUT);
const chunk = (flat: number[]) => Array.from({ length: flat.length / 3 }, (_, i) => flat.slice(3 * i, 3 * i + 3));

const manifest = {
  version: 1,
  fps: 30,
  skeleton: { names: [], parents: [], offsets: { leader: chunk(data.offsets.leader), follower: chunk(data.offsets.follower) } },
  keyJoints: [4, 7, 10, 13, 16],
  layout: { input: 660, output: 323, intention: 90 },
  startPose: data.startPose,
  models: {},
  defaultTemperature: 0.5,
  credit: '',
} as unknown as Manifest;

interface FakeOptions {
  role: 'leader' | 'follower';
  /** Forward speed of the fake dancer, m per step. */
  step?: number;
  contacts?: [number, number];
  intention?: boolean;
  /** Per batch sample i: extra sideways step (ghosts differ). */
  spread?: number;
  broken?: boolean;
  /** Samples (0: run(); i: the i-th of a batch) whose body is tipped over: every joint's rotation
   *  turned 90 degrees about x, its decoded positions standing. */
  tipped?: number[];
  /** Milliseconds each run or batch counts as the network's (networkMs: set, not timed). */
  cost?: number;
}

/** A stand-in for Policy: "keep the current pose, move `step` forward", built from its own input. */
class FakePolicy implements StepPolicy {
  readonly input: Float32Array;
  readonly result = { output: new Float32Array(OUTPUT_SIZE), intention: null as Float32Array | null };
  readonly entry = { intention: false };
  runs = 0;
  /** What the page's Policy keeps: ms in the network's runs (here options.cost per run). */
  networkMs = 0;
  private readonly size: number;
  /** The batch sizes asked for, in order. */
  readonly batchSizes: number[] = [];
  /** The temperature of every run and batch, in order. */
  readonly temperatures: number[] = [];
  private readonly batches = new Map<number, { input: Float32Array; output: Float32Array }>();

  constructor(readonly options: FakeOptions) {
    this.size = options.role === 'leader' ? LEADER_INPUT_SIZE : INPUT_SIZE;
    this.input = new Float32Array(this.size);
    this.entry.intention = !!options.intention;
    if (options.intention) this.result.intention = new Float32Array(90);
  }

  get hasIntention() {
    return this.entry.intention;
  }

  async run(temperature: number) {
    this.runs++;
    this.networkMs += this.options.cost ?? 0;
    this.temperatures.push(temperature);
    this.fill(this.input, 0, this.result.output, 0, 0);
    return this.result;
  }

  batchInput(k: number) {
    if (!this.batches.has(k)) this.batches.set(k, { input: new Float32Array(k * this.size), output: new Float32Array(k * OUTPUT_SIZE) });
    return this.batches.get(k)!.input;
  }

  async runBatch(k: number, temperature: number) {
    this.networkMs += this.options.cost ?? 0;
    this.temperatures.push(temperature);
    this.batchSizes.push(k);
    const b = this.batches.get(k)!;
    for (let i = 0; i < k; i++) this.fill(b.input, i * this.size, b.output, i * OUTPUT_SIZE, i);
    return { output: b.output, intention: null };
  }

  /** k samples of `input` (the page's guards and its choice on the count): as k rows of it. */
  async runDraws(k: number, temperature: number) {
    const rows = this.batchInput(k);
    for (let i = 0; i < k; i++) rows.set(this.input, i * this.size);
    const { output } = await this.runBatch(k, temperature);
    return { output, intention: this.result.intention };
  }

  private fill(input: Float32Array, at: number, out: Float32Array, to: number, sample: number) {
    const o = this.options;
    const self = blockSlices(o.role === 'leader' ? LEADER_INPUT_LAYOUT : FOLLOWER_INPUT_LAYOUT).self_pose.start;
    const dz = o.step ?? 0;
    const dx = (o.spread ?? 0) * sample;
    out.fill(0, to, to + OUTPUT_SIZE);
    out[to] = dx;
    out[to + 1] = dz;
    for (let k = 0; k < 6; k++) {
      out[to + OUT.trajectory_future.start + 4 * k + 1] = dz * 5 * (k + 1);
      out[to + OUT.trajectory_future.start + 4 * k + 3] = 1;
    }
    // The pose in the next root space: the same as now, since the root moved with the body.
    for (let i = 0; i < 204; i++) out[to + OUT.pose.start + i] = input[at + self + i];
    if (o.tipped?.includes(sample)) {
      for (let j = 0; j < 17; j++) {
        for (const v of [6, 9]) {
          const q = to + OUT.pose.start + 12 * j + v;
          const [y, z] = [out[q + 1], out[q + 2]];
          out[q + 1] = -z;
          out[q + 2] = y;
        }
      }
    }
    const [l, r] = o.contacts ?? [1, 1];
    out[to + OUT.contacts.start] = l;
    out[to + OUT.contacts.start + 1] = r;
    if (o.broken) out[to + 5] = NaN;
  }
}

const policy = (o: FakeOptions) => new FakePolicy(o);
const steer = { x: 0, z: 0, active: false };

function simulation(
  followers: FakeOptions[] = [{ role: 'follower', intention: true }], leader: FakeOptions = { role: 'leader' }, extra: Partial<Manifest> = {},
  figures = true,
) {
  const lead = new FakePolicy(leader);
  const follow = followers.map((o) => new FakePolicy(o));
  const sim = createSimulation({ manifest: { ...manifest, ...extra }, leader: lead, followers: follow, seed: 1, figures });
  return { sim, lead, follow };
}

const finite = (a: ArrayLike<number>) => Array.from(a).every(Number.isFinite);

describe('createSimulation', () => {
  it('runs the leader at its own variety, and the upright guard picks a standing sample of a tipping follower', async () => {
    const guarded = {
      leaderTemperature: 0.5,
      guard: { samples: 4, margin: 0.05 },
      plausibility: { hip_low: 0.7, head_above_hip_low: 0.4, feet_wide: 1.07, angle_high: [2.5, 0.59] },
    };
    const { sim, lead, follow } = simulation([{ role: 'follower', tipped: [0, 1] }], { role: 'leader' }, guarded);
    await sim.step(steer, 1);
    expect(lead.temperatures).toEqual([0.5]);
    expect(follow[0].temperatures).toEqual([1, 1]); // its own run, then the guard's batch of 4
    expect(sim.guards().upright).toBe(1);
    const p = sim.followers[0].positions;
    expect(p[4 * 3 + 1] - p[1]).toBeGreaterThan(0.4); // the head stays above the hips
    // Without a guard in the manifest, the same follower is drawn tipped over.
    const bare = simulation([{ role: 'follower', tipped: [0, 1] }]);
    await bare.sim.step(steer, 1);
    expect(bare.sim.guards().upright).toBe(0);
    const q = bare.sim.followers[0].positions;
    expect(q[4 * 3 + 1] - q[1]).toBeLessThan(0.2);
  });

  it('the leader guard (leaderGuard) picks a standing sample of a tipping leader, at his own variety', async () => {
    const ranges = { hip_low: 0.7, head_above_hip_low: 0.4, feet_wide: 1.07, angle_high: [2.5, 0.59] };
    const guarded = { leaderTemperature: 0.5, leaderGuard: { samples: 4, margin: 0.1 }, plausibility: ranges };
    const { sim, lead } = simulation([{ role: 'follower' }], { role: 'leader', tipped: [0, 1] }, guarded);
    await sim.step(steer, 1);
    expect(lead.temperatures).toEqual([0.5, 0.5]); // his own run, then the guard's batch of 4
    expect(sim.guards().upright).toBe(1);
    const p = sim.leader.positions;
    expect(p[4 * 3 + 1] - p[1]).toBeGreaterThan(0.4);
    // The followers' guard alone leaves him tipped over.
    const only = simulation([{ role: 'follower' }], { role: 'leader', tipped: [0, 1] },
      { leaderTemperature: 0.5, guard: { samples: 4, margin: 0.05 }, plausibility: ranges });
    await only.sim.step(steer, 1);
    const q = only.sim.leader.positions;
    expect(q[4 * 3 + 1] - q[1]).toBeLessThan(0.2);
  });

  it('the leader guard judges his hips from its hipMargin', async () => {
    const ranges = { hip_low: 0.7, head_above_hip_low: 0.4, feet_wide: 1.07, angle_high: [2.5, 0.59] };
    // A standing leader is within 5 m of the hips' edge: judged from there, every step is guarded.
    const wide = { leaderTemperature: 0.5, leaderGuard: { samples: 4, margin: 0.05, hipMargin: 5 }, plausibility: ranges };
    const hips = simulation([{ role: 'follower' }], { role: 'leader' }, wide);
    await hips.sim.step(steer, 1);
    expect(hips.lead.temperatures).toEqual([0.5, 0.5]); // his own run, then the guard's batch
    expect(hips.sim.guards().upright).toBe(1);
    // Judged from the margin alone, the same standing leader is left as he is.
    const plain = simulation([{ role: 'follower' }], { role: 'leader' }, { ...wide, leaderGuard: { samples: 4, margin: 0.05 } });
    await plain.sim.step(steer, 1);
    expect(plain.lead.temperatures).toEqual([0.5]);
    expect(plain.sim.guards().upright).toBe(0);
  });

  it('onCount: every step each dancer draws its samples at once and keeps a standing one; the guard takes over when none stands', async () => {
    const ranges = { hip_low: 0.7, head_above_hip_low: 0.4, feet_wide: 1.07, angle_high: [2.5, 0.59] };
    const counted = {
      leaderTemperature: 0.5, guard: { samples: 4, margin: 0.05 }, leaderGuard: { samples: 4, margin: 0.05 },
      onCount: { samples: 3, strength: 1 }, plausibility: ranges,
    };
    const { sim, lead, follow } = simulation([{ role: 'follower', tipped: [0, 1] }], { role: 'leader', tipped: [0] }, counted);
    await sim.step(steer, 1);
    expect(lead.runs).toBe(0); // no single run: the batch of 3 alone, at his variety
    expect(lead.batchSizes).toEqual([3]);
    expect(lead.temperatures).toEqual([0.5]);
    expect(follow[0].runs).toBe(0);
    expect(follow[0].batchSizes).toEqual([3]);
    expect(sim.guards().upright).toBe(0); // a standing sample was kept (her third, his second or third)
    const p = sim.followers[0].positions;
    expect(p[4 * 3 + 1] - p[1]).toBeGreaterThan(0.4);
    // None of her 3 stands: her guard draws its 4 and takes the most upright (the fourth stands).
    const fallen = simulation([{ role: 'follower', tipped: [0, 1, 2] }], { role: 'leader' }, counted);
    await fallen.sim.step(steer, 1);
    expect(fallen.follow[0].batchSizes).toEqual([3, 4]);
    expect(fallen.sim.guards().upright).toBe(1);
    const q = fallen.sim.followers[0].positions;
    expect(q[4 * 3 + 1] - q[1]).toBeGreaterThan(0.4);
    // Without onCount each takes its one sample, as before.
    const plain = simulation([{ role: 'follower' }], { role: 'leader' }, { ...counted, onCount: undefined });
    await plain.sim.step(steer, 1);
    expect(plain.lead.batchSizes).toEqual([]);
    expect(plain.follow[0].batchSizes).toEqual([]);
  });

  it('onCount.figureTurn: every dancer\'s chooser reads the figure in its own input; absent or 0, none does', async () => {
    const ranges = { hip_low: 0.7, head_above_hip_low: 0.4, feet_wide: 1.07, angle_high: [2.5, 0.59] };
    const counted = {
      leaderTemperature: 0.5, guard: { samples: 4, margin: 0.05 }, leaderGuard: { samples: 4, margin: 0.05 },
      onCount: { samples: 3, strength: 1, figureTurn: 180 }, plausibility: ranges,
    };
    const calls: { role: string; figureTurn: number | null; input: ArrayLike<number> | null | undefined }[] = [];
    const spy = vi.spyOn(OnCount.prototype, 'prefers').mockImplementation(function (this: OnCount, ...args) {
      calls.push({ role: this.role, figureTurn: this.figureTurn, input: args[4] });
      return false;
    });
    try {
      // a compare-mode duet: the leader and two followers, each with its chooser
      const { sim, lead, follow } = simulation([{ role: 'follower' }, { role: 'follower' }], { role: 'leader' }, counted);
      await sim.step(steer, 1);
      expect(calls.map((c) => [c.role, c.figureTurn])).toEqual([['leader', 180], ['follower', 180], ['follower', 180]]);
      expect(calls[0].input).toBe(lead.input);
      expect(calls[1].input).toBe(follow[0].input);
      expect(calls[2].input).toBe(follow[1].input);
      for (const figureTurn of [undefined, 0]) {
        calls.length = 0;
        const older = simulation([{ role: 'follower' }], { role: 'leader' }, { ...counted, onCount: { samples: 3, strength: 1, figureTurn } });
        await older.sim.step(steer, 1);
        expect(calls.map((c) => c.figureTurn), `figureTurn ${figureTurn}`).toEqual([null, null]);
      }
    } finally {
      spy.mockRestore();
    }
  });

  it('with keepPlan, a request draws his samples at once and keeps the standing one whose lead hand is nearest the plan, or the one on the count among the keepPlan nearest', async () => {
    const ranges = { hip_low: 0.7, head_above_hip_low: 0.4, feet_wide: 1.07, angle_high: [2.5, 0.59] };
    const keep = { leaderTemperature: 0.5, leaderGuard: { samples: 4, margin: 0.05, keepPlan: true }, plausibility: ranges };
    // Sample i stands 2 cm x i further to his side (the fake's spread): the samples differ, all stand.
    // His own figures are off: only the visitor's leads (a hands plan only for it).
    const { sim, lead } = simulation([{ role: 'follower' }], { role: 'leader', spread: 0.02 }, keep, false);
    await sim.step(steer, 1);
    expect(lead.temperatures).toEqual([0.5]); // nobody asks: his one run, standing, as before
    expect(sim.askTurn(-1)).toBe(true);
    await sim.step(steer, 1);
    expect(lead.runs).toBe(1); // asked: no single run ...
    expect(lead.batchSizes).toEqual([4]); // ... the batch alone, at his variety
    expect(lead.temperatures).toEqual([0.5, 0.5]);
    expect(sim.guards().upright).toBe(0); // a standing sample was kept: not a guarded step
    // Without keepPlan the same request takes his one sample, as before.
    const plain = simulation([{ role: 'follower' }], { role: 'leader', spread: 0.02 }, { ...keep, leaderGuard: { samples: 4, margin: 0.05 } }, false);
    await plain.sim.step(steer, 1);
    plain.sim.askTurn(-1);
    await plain.sim.step(steer, 1);
    expect(plain.lead.runs).toBe(2);
    expect(plain.lead.batchSizes).toEqual([]);
    // keepPlan 2 beside his chooser on the count: the same one batch a step, and while the request
    // runs the count still chooses (among the two nearest the plan) where keepPlan 1 leaves it out.
    const counted = async (keepPlan: number) => {
      const both = simulation([{ role: 'follower' }], { role: 'leader', spread: 0.02 },
        { ...keep, leaderGuard: { samples: 4, margin: 0.05, keepPlan }, onCount: { samples: 4, strength: 1, hips: 1 } }, false);
      await both.sim.step(steer, 1);
      const before = both.sim.guards().counted;
      both.sim.askTurn(-1);
      await both.sim.step(steer, 1);
      expect(both.lead.batchSizes).toEqual([4, 4]);
      return both.sim.guards().counted - before;
    };
    expect(await counted(1)).toBe(0);
    expect(await counted(2)).toBe(1);
  });

  it('starts both dancers in world space: leader at the origin, follower 0.8 m ahead facing it', () => {
    const sim = createSimulation({ manifest, leader: policy({ role: 'leader' }), followers: [policy({ role: 'follower' })], seed: 1 });
    expect(sim.leader.root).toEqual([0, 0]);
    expect(sim.followers[0].root[1]).toBeCloseTo(0.8, 12);
    expect(sim.followers[0].heading).toBeCloseTo(Math.PI, 12);
    expect(sim.leader.positions).toHaveLength(51);
    expect(sim.leader.future).toHaveLength(12);
    expect(finite(sim.leader.positions) && finite(sim.followers[0].positions)).toBe(true);
    expect(sim.followers[0].intention).toBeUndefined();
    const withIntention = createSimulation({ manifest, leader: policy({ role: 'leader' }), followers: [policy({ role: 'follower', intention: true })], seed: 1 });
    // Before any prediction the intention shows the leader's head where it is (not the origin).
    expect(withIntention.followers[0].intention![1]).toBeCloseTo(withIntention.leader.positions[4 * 3 + 1], 5);
  });

  it('steps: still models keep still dancers still, the intention is drawn in world space, timing is kept', async () => {
    const { sim, lead, follow } = simulation();
    const before = Float32Array.from(sim.followers[0].positions);
    for (let i = 0; i < 5; i++) await sim.step(steer, 0.5);
    expect(lead.runs).toBe(5);
    expect(follow[0].runs).toBe(5);
    for (let i = 0; i < 51; i++) expect(sim.followers[0].positions[i]).toBeCloseTo(before[i], 5);
    expect(sim.followers[0].intention).toHaveLength(90);
    // A zero intention in root space is the follower's own root on the floor.
    expect(sim.followers[0].intention![2]).toBeCloseTo(0.8, 5);
    const ms = sim.stepMs();
    expect(ms.median).toBeGreaterThanOrEqual(0);
    expect(ms.p95).toBeGreaterThanOrEqual(ms.median);
  });

  it("parts each step's time out to the networks: every run of the step, not the ghosts' between steps", async () => {
    const guarded = {
      guard: { samples: 4, margin: 0.05 },
      plausibility: { hip_low: 0.7, head_above_hip_low: 0.4, feet_wide: 1.07, angle_high: [2.5, 0.59] },
    };
    const { sim } = simulation([{ role: 'follower', cost: 0.5 }], { role: 'leader', cost: 0.25 });
    expect(sim.networkMs().median).toBe(0);
    for (let i = 0; i < 5; i++) {
      await sim.step(steer, 0.5);
      await sim.ghosts(2); // a batch of her network outside the step
    }
    expect(sim.networkMs()).toEqual({ median: 0.75, p95: 0.75 }); // his run and hers
    // A tipping follower under the guard: her run, then the guard's batch, in the same step.
    const tipping = simulation([{ role: 'follower', cost: 0.5, tipped: [0, 1] }], { role: 'leader', cost: 0.25 }, guarded);
    await tipping.sim.step(steer, 1);
    expect(tipping.sim.networkMs().median).toBe(1.25);
  });

  it('moves the drawn future and root with the model output', async () => {
    const { sim } = simulation([{ role: 'follower', step: 0.02 }], { role: 'leader', step: 0.02, contacts: [0.4, 0.2] });
    for (let i = 0; i < 60; i++) await sim.step(steer, 0.5);
    // The leader faces +Z and steps 2 cm a frame, while its anchor (nobody steers) stays at the
    // origin: free within ANCHOR_FREE of it, beyond that drawn back by ANCHOR_RATE of the excess
    // each frame, times the share of the frame its feet are free (1 - the larger contact, 0.4).
    let lead = 0;
    for (let i = 0; i < 60; i++) {
      lead += 0.02;
      if (lead > ANCHOR_FREE) lead -= (lead - ANCHOR_FREE) * ANCHOR_RATE * 0.6;
    }
    expect(lead).toBeGreaterThan(ANCHOR_FREE + 0.01);
    expect(sim.leader.root[1]).toBeCloseTo(lead, 6);
    expect(sim.followers[0].root[1]).toBeCloseTo(0.8 - 60 * 0.02, 6); // follower faces -Z
    expect(sim.leader.future[11]).toBeCloseTo(lead + 0.02 * 30, 5);
  });

  it('steering bends the leader plan toward the stick', async () => {
    const { sim, lead } = simulation();
    for (let i = 0; i < 3; i++) await sim.step({ x: 1, z: 0, active: true }, 0.5);
    // The control block (the leader's future in its own root space; it faces +Z, so x is world x)
    // bends toward the stick; the fake model itself just walks straight on.
    const control = blockSlices(LEADER_INPUT_LAYOUT).control.start;
    expect(lead.input[control + 4 * 5]).toBeGreaterThan(0.1);
    expect(lead.input[control + 4 * 5 + 1]).toBeCloseTo(0, 6);
  });

  it('compare mode: two followers, each its own dancer and model; the leader reacts to the first', async () => {
    const { sim, lead: leaderPolicy, follow } = simulation([{ role: 'follower', step: 0.01 }, { role: 'follower', step: -0.01 }]);
    for (let i = 0; i < 4; i++) await sim.step(steer, 0.5);
    expect(sim.followers).toHaveLength(2);
    expect(follow[0].runs).toBe(4);
    expect(follow[1].runs).toBe(4);
    expect(sim.followers[0].root[1]).toBeCloseTo(0.8 - 0.04, 6);
    expect(sim.followers[1].root[1]).toBeCloseTo(0.8 + 0.04, 6);
    // The leader's last input saw followers[0] as its partner (the leader stands at the origin
    // facing +Z, so root space is world space): the partner hip is followers[0]'s previous hip.
    const s = sim as DuetSimulation;
    expect(s.duet.leader.rootX).toBe(0);
    const hipZ = s.duet.followers.map((f) => f.track.positions[(NOW - 1) * 51 + 2]);
    const partnerPose = blockSlices(LEADER_INPUT_LAYOUT).partner_pose.start;
    expect(leaderPolicy.input[partnerPose + 2]).toBeCloseTo(hipZ[0], 5);
    expect(Math.abs(leaderPolicy.input[partnerPose + 2] - hipZ[1])).toBeGreaterThan(0.05);
  });

  it('resets a dancer whose model output is absurd, and never draws the absurd pose', async () => {
    const { sim } = simulation([{ role: 'follower', broken: true }]);
    await sim.step(steer, 0.5);
    const s = sim as DuetSimulation;
    expect(s.duet.followers[0].resets).toBe(1);
    expect(finite(sim.followers[0].positions)).toBe(true);
    expect(sim.followers[0].root[1]).toBeCloseTo(0.8, 6);
  });

  it('ghosts: k sampled next poses of the first follower, the real state untouched', async () => {
    const { sim } = simulation([{ role: 'follower', spread: 0.05 }]);
    await sim.step(steer, 0.5);
    const s = sim as DuetSimulation;
    const track = Float64Array.from(s.duet.followers[0].track.positions);
    const drawn = Float32Array.from(sim.followers[0].positions);
    const ghosts = await sim.ghosts(3);
    expect(ghosts).toHaveLength(3);
    for (const g of ghosts) expect(g.length === 51 && finite(g)).toBe(true);
    // Sample i stepped 0.05·i sideways (in the follower's frame, which faces -Z: world -X).
    expect(ghosts[1][0] - ghosts[0][0]).toBeCloseTo(-0.05, 5);
    expect(ghosts[2][0] - ghosts[0][0]).toBeCloseTo(-0.1, 5);
    expect(s.duet.followers[0].track.positions).toEqual(track);
    expect(sim.followers[0].positions).toEqual(drawn);
    expect(await sim.ghosts(0)).toEqual([]);
  });

  it('ghosts dance on by themselves and branch from the partner again, each at its own moment', async () => {
    const { sim } = simulation([{ role: 'follower', spread: 0.05 }]);
    await sim.step(steer, 0.5);
    let ghosts: Float32Array[] = [];
    for (let call = 0; call < 15; call++) ghosts = await sim.ghosts(3);
    // Sample i steps 0.05·i sideways (world -X) per call. Of 30 calls, ghost 1 branches at call
    // 20 and ghost 2 at call 10: after 15 calls ghost 1 has danced 15 steps, ghost 2 only 5.
    expect(ghosts[1][0] - ghosts[0][0]).toBeCloseTo(-0.05 * 15, 4);
    expect(ghosts[2][0] - ghosts[0][0]).toBeCloseTo(-0.1 * 5, 4);
    // reset(): all branch again from the new start.
    sim.reset();
    ghosts = await sim.ghosts(3);
    expect(ghosts[2][0] - ghosts[0][0]).toBeCloseTo(-0.1, 5);
  });

  it('reset() goes back to the start pose', async () => {
    const { sim } = simulation([{ role: 'follower', step: 0.02 }], { role: 'leader', step: 0.02 });
    for (let i = 0; i < 5; i++) await sim.step(steer, 0.5);
    sim.reset();
    expect(sim.leader.root).toEqual([0, 0]);
    expect(sim.followers[0].root[1]).toBeCloseTo(0.8, 12);
  });
});

describe('figures', () => {
  const LEADER_FIGURE = blockSlices(LEADER_INPUT_LAYOUT).figure;
  const FOLLOWER_FIGURE = blockSlices(FOLLOWER_INPUT_LAYOUT).figure;
  const leaderFigure = (p: FakePolicy) => Array.from(p.input.subarray(LEADER_FIGURE.start, LEADER_FIGURE.end));
  const followerFigure = (input: Float32Array, at = 0) => Array.from(input.subarray(at + FOLLOWER_FIGURE.start, at + FOLLOWER_FIGURE.end));
  const none = (block: number[]) => block.every((v) => v === 0);

  it('he leads his own, drawn from the seed; the leader, the followers and the possible reactions all read the same block', async () => {
    const { sim, lead, follow } = simulation([{ role: 'follower' }, { role: 'follower' }]);
    const s = sim as DuetSimulation;
    let felt = 0;
    let danced = 0;
    const kinds = new Set<string>();
    for (let i = 0; i < 300; i++) {
      await sim.step(steer, 0.5);
      const block = leaderFigure(lead);
      expect(followerFigure(follow[0].input), `step ${i}: her block is his`).toEqual(block);
      expect(followerFigure(follow[1].input), `step ${i}: the compare follower's too`).toEqual(block);
      if (!none(block)) felt++;
      const figure = sim.figure;
      if (figure && !figure.coming) {
        danced++;
        kinds.add(`${figure.name} ${figure.way}`);
        expect(figure.asked).toBe(false);
        // Both read it, as its kind, inside now (key 6).
        expect(block[2 * (6 * FIGURE_KINDS.length + figureKind(figure.name, figure.way))], `step ${i}: ${figure.name} read`).toBe(1);
        expect(sim.turnAsked).toBe(0);
      }
      if (i === 150) {
        // The possible reactions read the figure block of the step they take: all alike.
        await sim.ghosts(2);
        const rows = follow[0].batchInput(2);
        expect(followerFigure(rows, INPUT_SIZE)).toEqual(followerFigure(rows, 0));
      }
    }
    expect(felt).toBeGreaterThan(60); // 10 s: a figure every 7 beats or so, each felt from a second before
    expect(danced).toBeGreaterThan(30);
    expect(kinds.size).toBeGreaterThan(1);
    expect(s.duet.figures.led.every((x) => !x.asked)).toBe(true);
    // The same seed draws the same figures; reset() draws them anew from it.
    const again = simulation([{ role: 'follower' }]);
    for (let i = 0; i < 120; i++) await again.sim.step(steer, 0.5);
    const first = (again.sim as DuetSimulation).duet.figures.led.map((x) => [x.name, x.way, x.start, x.end]);
    again.sim.reset();
    for (let i = 0; i < 120; i++) await again.sim.step(steer, 0.5);
    expect((again.sim as DuetSimulation).duet.figures.led.map((x) => [x.name, x.way, x.start, x.end])).toEqual(first);
  });

  it('?figures=0: only the turns asked for; switched off, his own not begun yet go at once, switched on they come again', async () => {
    const { sim, lead } = simulation([{ role: 'follower' }], { role: 'leader' }, {}, false);
    expect(sim.ownFigures).toBe(false);
    for (let i = 0; i < 200; i++) {
      await sim.step(steer, 0.5);
      expect(none(leaderFigure(lead)), `step ${i}: a figure nobody asked for`).toBe(true);
    }
    expect(sim.figure).toBeNull();
    sim.ownFigures = true;
    await sim.step(steer, 0.5);
    const s = sim as DuetSimulation;
    expect(s.duet.figures.led).toHaveLength(1); // planned on the step after the switch
    expect(sim.figure?.coming).toBe(true);
    sim.ownFigures = false;
    expect(s.duet.figures.led).toEqual([]); // not begun: gone with the switch
    expect(sim.figure).toBeNull();
  });

  it('his own turn: read as its kind, no hands plan for it, no turn asked; switched off before it begins, it goes', async () => {
    const { sim, lead } = simulation([{ role: 'follower' }], { role: 'leader' }, {}, false);
    const s = sim as DuetSimulation;
    for (let i = 0; i < 10; i++) await sim.step(steer, 0.5);
    s.duet.figures.led.push(figureFrom(s.duet, s.duet.frame, 'his_turn', 1, false));
    expect(sim.figure).toMatchObject({ name: 'his_turn', way: 1, asked: false, coming: true });
    expect(sim.turnAsked).toBe(0);
    let dancing = 0;
    for (let i = 0; i < 60; i++) {
      await sim.step(steer, 0.5);
      if (sim.figure && !sim.figure.coming) {
        dancing++;
        expect(sim.figure).toMatchObject({ name: 'his_turn', way: 1, asked: false });
        expect(lead.input[blockSlices(LEADER_INPUT_LAYOUT).hands_plan.start]).toBe(0);
        expect(leaderFigure(lead)[2 * (6 * FIGURE_KINDS.length + figureKind('his_turn', 1))]).toBe(1);
        expect(sim.turnAsked).toBe(0);
      }
    }
    // FIGURE_BEATS.his_turn at the manifest's tempo (170): 20 steps danced.
    expect(dancing).toBe(Math.round(2 / (170 / 60 / 30)) + 1);
    s.duet.figures.led.push(figureFrom(s.duet, s.duet.frame + 5, 'his_turn', -1, false));
    sim.ownFigures = false;
    expect(s.duet.figures.led.filter((x) => x.name === 'his_turn' && x.end >= s.duet.frame)).toEqual([]);
  });

  it('askTurn: on the next beat, turnAsked from the ask until the figure ends, danced as asked', async () => {
    const { sim, lead } = simulation([{ role: 'follower' }], { role: 'leader' }, {}, false);
    for (let i = 0; i < 10; i++) await sim.step(steer, 0.5);
    expect(sim.turnAsked).toBe(0);
    expect(sim.askTurn(-1)).toBe(true);
    expect(sim.turnAsked).toBe(-1);
    expect(sim.figure).toMatchObject({ name: 'her_turn', way: -1, asked: true, coming: true });
    let steps = 0;
    let dancing = 0;
    while (sim.turnAsked !== 0) {
      await sim.step(steer, 0.5);
      steps++;
      if (sim.figure && !sim.figure.coming) {
        dancing++;
        expect(sim.figure).toMatchObject({ name: 'her_turn', way: -1, asked: true });
        // A hands plan is shown, and both read her turn to her right inside now (key 6).
        expect(lead.input[blockSlices(LEADER_INPUT_LAYOUT).hands_plan.start]).toBe(1);
        expect(leaderFigure(lead)[2 * (6 * FIGURE_KINDS.length + figureKind('her_turn', -1))]).toBe(1);
      }
      expect(steps).toBeLessThan(100);
    }
    // FIGURE_BEATS at the manifest's tempo (170): 37 steps danced, after at most a beat's wait.
    expect(dancing).toBe(Math.round(3.5 / (170 / 60 / 30)) + 1);
    expect(steps - dancing).toBeLessThanOrEqual(Math.ceil(30 * 60 / 170));
    expect(sim.figure).toBeNull();
  });
});

describe('leader playback', () => {
  const features = fixture('features');
  const track = trackOf(features, 'leader');
  const recording: Motion = { positions: track.positions, rotations: track.rotations, offsets: Float64Array.from(data.offsets.leader), fps: 30, frames: track.frames };

  it('drives the leader from the recording (moved rigidly onto the leader), not from the leader model', async () => {
    const { sim, lead } = simulation();
    const s = sim as DuetSimulation;
    s.setLeaderPlayback(recording);
    for (let i = 0; i < 3; i++) await sim.step(steer, 0.5);
    expect(lead.runs).toBe(0);
    expect(s.leaderPlayback).toEqual({ frame: 3, frames: track.frames });
    // Heights are the recording's; horizontal distances between joints too.
    const p = s.duet.leader.track.positions;
    for (let j = 0; j < 17; j++) expect(p[NOW * 51 + 3 * j + 1]).toBeCloseTo(track.positions[3 * 51 + 3 * j + 1], 9);
    const dist = (a: ArrayLike<number>, i: number, j: number, base: number) =>
      Math.hypot(a[base + 3 * i] - a[base + 3 * j], a[base + 3 * i + 2] - a[base + 3 * j + 2]);
    expect(dist(p, 7, 16, NOW * 51)).toBeCloseTo(dist(track.positions, 7, 16, 3 * 51), 9);
    // The plan (what the follower reads as the leader's future) is the recording's future, moved the same way.
    const plan = s.duet.leader.track.root;
    const futureDistance = Math.hypot(plan[2 * (NOW + 30)] - plan[2 * NOW], plan[2 * (NOW + 30) + 1] - plan[2 * NOW + 1]);
    const root = Track.fromMotion(recording).root;
    const recorded = Math.hypot(root[2 * 33] - root[2 * 3], root[2 * 33 + 1] - root[2 * 3 + 1]);
    expect(futureDistance).toBeCloseTo(recorded, 9);
  });

  it('loops at the end and hands back to the model with null', async () => {
    const { sim, lead } = simulation();
    const s = sim as DuetSimulation;
    s.setLeaderPlayback(recording);
    for (let i = 0; i < track.frames + 2; i++) await sim.step(steer, 0.5);
    expect(s.leaderPlayback!.frame).toBe(3);
    expect(finite(sim.leader.positions)).toBe(true);
    s.setLeaderPlayback(null);
    await sim.step(steer, 0.5);
    expect(lead.runs).toBe(1);
  });

  it('leads no figure: those planned go, none is planned or asked for, and the followers read none', async () => {
    const FIGURE = blockSlices(FOLLOWER_INPUT_LAYOUT).figure;
    const { sim, follow } = simulation([{ role: 'follower' }]);
    const s = sim as DuetSimulation;
    for (let i = 0; i < 60; i++) await sim.step(steer, 0.5);
    expect(s.duet.figures.led.length).toBeGreaterThan(0); // his own, planned or danced
    sim.askTurn(1);
    s.setLeaderPlayback(recording);
    expect(sim.figure).toBeNull();
    expect(sim.turnAsked).toBe(0);
    expect(sim.askTurn(-1)).toBe(false);
    for (let i = 0; i < 200; i++) {
      await sim.step(steer, 0.5);
      expect(follow[0].input.subarray(FIGURE.start, FIGURE.end).every((v) => v === 0), `step ${i}: a figure read`).toBe(true);
    }
    expect(s.duet.figures.led).toEqual([]);
    // Back with the model, he plans his own again.
    s.setLeaderPlayback(null);
    await sim.step(steer, 0.5);
    expect(s.duet.figures.led).toHaveLength(1);
  });

  it('after reset() the recording starts over from a still first frame at the start position', async () => {
    const { sim } = simulation();
    const s = sim as DuetSimulation;
    s.setLeaderPlayback(recording);
    await sim.step(steer, 0.5);
    sim.reset();
    expect(s.leaderPlayback!.frame).toBe(0);
    expect(sim.leader.root[0]).toBeCloseTo(0, 12);
    expect(sim.leader.root[1]).toBeCloseTo(0, 12);
    expect(sim.leader.heading).toBeCloseTo(0, 12);
  });
});

describe('foot locking (drawn pose only)', () => {
  it('keeps a planted foot where contact began while the body walks on, then lets it go', async () => {
    const { sim, follow } = simulation([{ role: 'follower', step: 0.003, contacts: [1, 0] }]);
    const s = sim as DuetSimulation;
    await sim.step(steer, 0.5);
    const planted = Array.from(sim.followers[0].positions.subarray(13 * 3, 13 * 3 + 3));
    for (let i = 0; i < 8; i++) await sim.step(steer, 0.5);
    const drawn = sim.followers[0].positions;
    const modelled = s.duet.followers[0].positions;
    for (let a = 0; a < 3; a++) expect(drawn[13 * 3 + a]).toBeCloseTo(planted[a], 5);
    // The model's foot moved on with the body (2.4 cm); the track the features read is untouched.
    expect(Math.abs(modelled[13 * 3 + 2] - planted[2])).toBeGreaterThan(0.02);
    // Bones keep their lengths.
    const bone = (p: ArrayLike<number>, i: number, j: number) => Math.hypot(p[3 * i] - p[3 * j], p[3 * i + 1] - p[3 * j + 1], p[3 * i + 2] - p[3 * j + 2]);
    expect(bone(drawn, 11, 12)).toBeCloseTo(bone(modelled, 11, 12), 5);
    expect(bone(drawn, 12, 13)).toBeCloseTo(bone(modelled, 12, 13), 5);
    // The right foot has no contact: drawn where the model put it on the floor, while the rest of
    // the body trails the walk by the glide's few millimetres (contact.ts HIP_GLIDE): the feet keep
    // the model's timing (within the half millimetre the straightened leg falls short by).
    for (let a = 0; a < 3; a++) expect(drawn[16 * 3 + a]).toBeCloseTo(modelled[16 * 3 + a], 3);
    expect(Math.abs(drawn[2] - modelled[2])).toBeLessThan(0.02);
    expect(Math.abs(drawn[2] - modelled[2])).toBeGreaterThan(0.001);
    expect(drawn[13 * 3 + 1]).toBeGreaterThanOrEqual(ANKLE_FLOOR - 1e-6);

    // Contact ends: within a few steps the drawn foot is the model's again, where the model put it;
    // the body, free, glides and trails the walk.
    follow[0].options.contacts = [0, 0];
    for (let i = 0; i < 8; i++) await sim.step(steer, 0.5);
    const shown = sim.followers[0].positions, model = s.duet.followers[0].positions;
    for (let a = 0; a < 3; a++) expect(shown[13 * 3 + a]).toBeCloseTo(model[13 * 3 + a], 3);
    expect(Math.abs(shown[2] - model[2])).toBeGreaterThan(0.001);
    expect(shown[1]).toBeCloseTo(model[1], 6);
  });
});

describe('the leading variety', () => {
  it('the leader draws at the leading variety while he leads a figure, at his own before and after', async () => {
    const { sim, lead } = simulation([{ role: 'follower' }], { role: 'leader' }, { leaderTemperature: 0.5, leadingTemperature: 0.9 }, false);
    for (let i = 0; i < 10; i++) await sim.step(steer, 0.3);
    sim.askTurn(1);
    while (sim.turnAsked !== 0) await sim.step(steer, 0.3);
    for (let i = 0; i < 5; i++) await sim.step(steer, 0.3);
    // 10 steps before, then every step from the request (the figure starts within LEAD_IN) to its
    // end, then his own (from the step that lets the request go: the figure has ended).
    const leading = lead.temperatures.slice(10, -6);
    expect(lead.temperatures.slice(0, 10)).toEqual(Array(10).fill(0.5));
    expect(leading.length).toBeGreaterThan(30);
    expect(leading).toEqual(Array(leading.length).fill(0.9));
    expect(lead.temperatures.slice(-6)).toEqual(Array(6).fill(0.5));
  });
});
