// TEMPORARY development simulation. Replaced by web/rollout.ts (the real leader/follower loop
// built on features.ts and skeleton.ts); see the import of `createSimulation` in main.ts.
//
// The motion here is procedural: the leader walks where it is steered and bobs in place when
// idle, the follower springs to a spot in front of the leader and faces it. The ONNX models are
// still stepped every frame (on dummy inputs) so that step timing, threads and the model-loading
// path are exercised exactly as with the real loop.

import type { CreateSimulation, DancerView, Manifest, Simulation, SimulationOptions, Steer } from './types';
import type { Policy } from './policy';
import { StepTimer } from './timing';
import { createUniform } from './random';

const DT = 1 / 30;
const FUTURE_KEYS = 6;
const KEY_JOINTS = [4, 7, 10, 13, 16];

interface Body {
  x: number;
  z: number;
  vx: number;
  vz: number;
  heading: number;
  phase: number;
}

/** Rest positions of a skeleton relative to its hip, from the manifest's offsets. */
function restPose(offsets: number[][], parents: number[]): Float32Array {
  const rest = new Float32Array(parents.length * 3);
  for (let j = 0; j < parents.length; j++) {
    const p = parents[j];
    for (let a = 0; a < 3; a++) rest[3 * j + a] = (p >= 0 ? rest[3 * p + a] : 0) + offsets[j][a];
  }
  return rest;
}

class DevDancer {
  readonly view: DancerView;
  readonly body: Body = { x: 0, z: 0, vx: 0, vz: 0, heading: 0, phase: 0 };
  private readonly offsets: number[][];
  private readonly parents: number[];
  private readonly angles: Float32Array;
  private readonly rotations: Float32Array;
  private readonly hipHeight: number;

  constructor(manifest: Manifest, role: 'leader' | 'follower', withIntention: boolean) {
    this.offsets = manifest.skeleton.offsets[role];
    this.parents = manifest.skeleton.parents;
    const n = this.parents.length;
    this.angles = new Float32Array(n);
    this.rotations = new Float32Array(n * 9);
    this.view = {
      root: [0, 0],
      heading: 0,
      positions: new Float32Array(n * 3),
      future: new Float32Array(FUTURE_KEYS * 2),
      intention: withIntention ? new Float32Array(FUTURE_KEYS * KEY_JOINTS.length * 3) : undefined,
    };
    // The hip offset may be zero in a real manifest: stand the rest pose on the floor instead.
    const rest = restPose(this.offsets, this.parents);
    let lowest = 0;
    for (let j = 0; j < n; j++) lowest = Math.min(lowest, rest[3 * j + 1]);
    this.hipHeight = this.offsets[0][1] > 0.5 ? this.offsets[0][1] : 0.08 - lowest;
  }

  place(x: number, z: number, heading: number): void {
    Object.assign(this.body, { x, z, vx: 0, vz: 0, heading, phase: 0 });
    this.refresh();
  }

  /** Recompute the view (positions, future) from the body state. */
  refresh(phaseOffset = 0, into = this.view.positions): void {
    const b = this.body;
    const speed = Math.hypot(b.vx, b.vz);
    const phase = b.phase + phaseOffset;
    // Joint pitch angles: legs and arms swing in opposition, more when moving.
    const swing = 0.15 + 0.35 * Math.min(1, speed);
    const a = this.angles;
    a.fill(0);
    a[11] = Math.sin(phase) * swing; // lThigh
    a[14] = -Math.sin(phase) * swing; // rThigh
    a[12] = -Math.max(0, Math.sin(phase + 1.2)) * 0.6; // lShin bends backwards
    a[15] = -Math.max(0, -Math.sin(phase + 1.2)) * 0.6;
    a[5] = -Math.sin(phase) * swing * 0.8; // shoulders
    a[8] = Math.sin(phase) * swing * 0.8;
    a[6] = 0.5;
    a[9] = 0.5; // elbows
    a[1] = 0.1 * Math.min(1, speed); // lean into the walk
    this.forwardKinematics(b.x, 0.05 * Math.abs(Math.sin(phase)), b.z, b.heading, into);

    if (into !== this.view.positions) return;
    this.view.root[0] = b.x;
    this.view.root[1] = b.z;
    this.view.heading = b.heading;
    for (let k = 0; k < FUTURE_KEYS; k++) {
      const t = ((k + 1) * 5) / 30;
      this.view.future[2 * k] = b.x + b.vx * t;
      this.view.future[2 * k + 1] = b.z + b.vz * t;
    }
  }

  /** Pitch-only FK: good enough to look like a person in development screenshots. */
  private forwardKinematics(x: number, bob: number, z: number, heading: number, out: Float32Array): void {
    const R = this.rotations;
    const parents = this.parents;
    for (let j = 0; j < parents.length; j++) {
      const p = parents[j];
      const c = Math.cos(this.angles[j]);
      const s = Math.sin(this.angles[j]);
      // local rotation about x: [1 0 0; 0 c -s; 0 s c]
      let r0, r1, r2, r3, r4, r5, r6, r7, r8;
      if (p < 0) {
        // root: yaw by heading (θ = 0 faces +z)
        const ch = Math.cos(heading);
        const sh = Math.sin(heading);
        [r0, r1, r2, r3, r4, r5, r6, r7, r8] = [ch, 0, sh, 0, 1, 0, -sh, 0, ch];
      } else {
        const q = 9 * p;
        [r0, r3, r6] = [R[q], R[q + 3], R[q + 6]];
        [r1, r4, r7] = [R[q + 1] * c + R[q + 2] * s, R[q + 4] * c + R[q + 5] * s, R[q + 7] * c + R[q + 8] * s];
        [r2, r5, r8] = [-R[q + 1] * s + R[q + 2] * c, -R[q + 4] * s + R[q + 5] * c, -R[q + 7] * s + R[q + 8] * c];
      }
      R.set([r0, r1, r2, r3, r4, r5, r6, r7, r8], 9 * j);
      const o = this.offsets[j];
      if (p < 0) {
        out[0] = x;
        out[1] = this.hipHeight + bob;
        out[2] = z;
      } else {
        const q = 9 * p;
        for (let row = 0; row < 3; row++) {
          out[3 * j + row] = out[3 * p + row] + R[q + 3 * row] * o[0] + R[q + 3 * row + 1] * o[1] + R[q + 3 * row + 2] * o[2];
        }
      }
    }
  }
}

class DevSimulation implements Simulation {
  readonly leader: DancerView;
  readonly followers: DancerView[];
  private readonly lead: DevDancer;
  private readonly follow: DevDancer[];
  private readonly timer = new StepTimer(300);
  private readonly uniform: () => number;
  private ghostPoses: Float32Array[] = [];

  constructor(private readonly options: SimulationOptions) {
    const { manifest } = options;
    this.uniform = createUniform(options.seed);
    this.lead = new DevDancer(manifest, 'leader', options.leader.hasIntention);
    this.follow = options.followers.map((p) => new DevDancer(manifest, 'follower', p.hasIntention));
    this.leader = this.lead.view;
    this.followers = this.follow.map((d) => d.view);
    this.reset();
  }

  reset(): void {
    this.lead.place(0, 0, 0);
    // Partners face each other 0.8 m apart; compare-mode followers stand side by side.
    this.follow.forEach((f, i) => f.place((i - (this.follow.length - 1) / 2) * 0.9, 0.8, Math.PI));
    this.timer.clear();
  }

  async step(steer: Steer, temperature: number): Promise<void> {
    const started = performance.now();
    await this.runModels(temperature);

    // Leader: velocity follows the steering through a critically damped first-order filter.
    const L = this.lead.body;
    const maxSpeed = 1.3;
    const blend = 1 - Math.exp(-6 * DT);
    L.vx += (steer.x * maxSpeed - L.vx) * blend;
    L.vz += (steer.z * maxSpeed - L.vz) * blend;
    L.x += L.vx * DT;
    L.z += L.vz * DT;
    const speed = Math.hypot(L.vx, L.vz);
    if (speed > 0.15) L.heading = turnToward(L.heading, Math.atan2(L.vx, L.vz), 4 * DT);
    L.phase += DT * 2 * Math.PI * (1.2 + speed * 0.6);
    this.lead.refresh();

    // Followers: spring toward a spot in front of the leader, facing it.
    this.follow.forEach((f, i) => {
      const F = f.body;
      const side = (i - (this.follow.length - 1) / 2) * 0.9;
      const fx = Math.sin(L.heading);
      const fz = Math.cos(L.heading);
      const tx = L.x + fx * 0.8 + fz * side;
      const tz = L.z + fz * 0.8 - fx * side;
      const k = 1 - Math.exp(-3 * DT);
      const wobble = 0.05 * temperature * (this.uniform() - 0.5);
      F.vx += ((tx - F.x) * 3 - F.vx) * k + wobble;
      F.vz += ((tz - F.z) * 3 - F.vz) * k - wobble;
      F.x += F.vx * DT;
      F.z += F.vz * DT;
      F.heading = turnToward(F.heading, Math.atan2(L.x - F.x, L.z - F.z), 5 * DT);
      F.phase += DT * 2 * Math.PI * (1.2 + Math.hypot(F.vx, F.vz) * 0.6);
      f.refresh();
      this.writeIntention(f.view);
    });

    this.timer.add(performance.now() - started);
  }

  async ghosts(k: number): Promise<Float32Array[]> {
    if (k <= 0 || this.follow.length === 0) return [];
    const policy = this.options.followers[0];
    policy.batchInput(k).fill(0);
    const { output } = await policy.runBatch(k, 0.5);
    while (this.ghostPoses.length < k) this.ghostPoses.push(new Float32Array(51));
    const f = this.follow[0];
    for (let i = 0; i < k; i++) {
      // Use the sampled output (random in dev) to pick a phase: different codes, different poses.
      f.refresh(1.5 * Math.sin(1000 * output[i * 323]) + (i + 1) * 0.4, this.ghostPoses[i]);
    }
    return this.ghostPoses.slice(0, k);
  }

  stepMs(): { median: number; p95: number } {
    return this.timer.summary();
  }

  /** Step every model once on a dummy input, as the real loop would, for honest timings. */
  private async runModels(temperature: number): Promise<void> {
    const run = (policy: Policy, source: Float32Array) => {
      policy.input.fill(0);
      policy.input.set(source, policy.input.length - source.length);
      return policy.run(temperature);
    };
    await run(this.options.leader, this.lead.view.positions);
    for (let i = 0; i < this.options.followers.length; i++) {
      await run(this.options.followers[i], this.follow[i].view.positions);
    }
  }

  /** The follower's "guess" of the leader's key joints: the leader's joints carried forward. */
  private writeIntention(view: DancerView): void {
    if (!view.intention) return;
    const L = this.lead.body;
    const p = this.lead.view.positions;
    for (let k = 0; k < FUTURE_KEYS; k++) {
      const t = ((k + 1) * 5) / 30;
      KEY_JOINTS.forEach((j, n) => {
        const o = (k * KEY_JOINTS.length + n) * 3;
        view.intention![o] = p[3 * j] + L.vx * t;
        view.intention![o + 1] = p[3 * j + 1];
        view.intention![o + 2] = p[3 * j + 2] + L.vz * t;
      });
    }
  }
}

function turnToward(angle: number, target: number, maxStep: number): number {
  let delta = target - angle;
  delta = Math.atan2(Math.sin(delta), Math.cos(delta));
  return angle + Math.max(-maxStep, Math.min(maxStep, delta));
}

export const createSimulation: CreateSimulation = (options) => new DevSimulation(options);
