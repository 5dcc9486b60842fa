// The page's Simulation: policies in, DancerViews out. One step runs the duet loop of rollout.ts
// (the mirror of training/mirror/rollout.py) with the page's policies, then refreshes what the page draws
// (the contact layer's poses: web/mirror/contact.ts; planned paths, intentions). Also here: the
// upright guards (web/mirror/guard.ts: a batch of fresh samples on the rare step whose body would
// leave the recording's range), the steps on the count (web/mirror/on_count.ts: every step, the
// standing sample whose footwork follows the beat), sampled ghosts and leader playback from a
// recording. Nothing else in this file changes a number the models see.

import { FIGURE_SIZE, FUTURE_OFFSETS, INPUT_SIZE, INTENTION_SIZE, KEYS, OUTPUT_SIZE, figureBlock, followerInput } from '../mirror/features';
import { KEY_JOINTS, type Motion, N_JOINTS, POSITIONS_SIZE, ROTATIONS_SIZE } from '../mirror/skeleton';
import { ContactLayer, HipGlide } from '../mirror/contact';
import { FootLock } from '../mirror/footik';
import { type GuardSettings, type Ranges, hipSlackFor, mostUpright, nearPlan, nearestPlan, showsPlan, slackFor, uprightBody, uprightMargin } from '../mirror/guard';
import { OnCount, STEPPED, drawnFootwork, drawnSteps, hipsTurnBack, nearestCount, planted } from '../mirror/on_count';
import { LeaderPlayback } from './playback';
import { StepTimer } from './timing';
import { createUniform } from './random';
import {
  Dancer, type Duet, NOW, applyOutput, askTurn, finishStep, leadPlan, leaderVariety, musicInput, outputIsAbsurd, planFigures, startDuet, steerPlan, stepInputs,
} from '../mirror/rollout';
import type { DancerView, FigureView, Simulation, SimulationOptions, StepPolicy, Steer } from './types';

/** Per dancer: what the page draws, kept up to date from the dancer after every step. */
class View implements DancerView {
  root: [number, number] = [0, 0];
  heading = 0;
  readonly positions = new Float32Array(POSITIONS_SIZE);
  readonly future = new Float32Array(KEYS * 2);
  intention?: Float32Array;
  readonly rotations = new Float32Array(ROTATIONS_SIZE);
  readonly contacts = new Float32Array(2);
  /** Per hand (left, right): how far the contact layer draws it to the partner's, 0..1. */
  readonly hands = new Float32Array(2);
  /** Path glide and foot locks of a follower beyond the first (compare mode), as ours gets them
   *  from the contact layer: both partners drawn alike, so the comparison is fair. */
  readonly glide = new HipGlide();
  readonly feet = new FootLock();
  resets = -1;

  constructor(withIntention: boolean) {
    if (withIntention) this.intention = new Float32Array(INTENTION_SIZE);
  }

  update(d: Dancer): void {
    this.root[0] = d.rootX;
    this.root[1] = d.rootZ;
    this.heading = d.heading;
    const t = d.track;
    for (let i = 0; i < POSITIONS_SIZE; i++) this.positions[i] = t.positions[NOW * POSITIONS_SIZE + i];
    for (let i = 0; i < ROTATIONS_SIZE; i++) this.rotations[i] = t.rotations[NOW * ROTATIONS_SIZE + i];
    this.contacts[0] = d.contacts[0];
    this.contacts[1] = d.contacts[1];
    this.hands.fill(0);
    for (let k = 0; k < KEYS; k++) {
      this.future[2 * k] = t.root[2 * (NOW + FUTURE_OFFSETS[k])];
      this.future[2 * k + 1] = t.root[2 * (NOW + FUTURE_OFFSETS[k]) + 1];
    }
    if (this.intention && d.intention) this.intention.set(d.intention);
  }
}

/** Steps a possible reaction dances on its own before it branches from the partner again (1 s):
 *  long enough to part from her, short enough to stay a reaction to this moment. */
const GHOST_LIFE = 30;

/** The leader's own figures draw from a stream of their own, derived from the page's seed (the
 *  policies' noise streams are seed + i·0x9e3779b9: main.ts). */
const FIGURES_STREAM = 0x85ebca6b;

export class DuetSimulation implements Simulation {
  readonly leader: DancerView;
  readonly followers: DancerView[];
  duet: Duet;
  private readonly leaderView: View;
  private readonly followerViews: View[];
  private readonly leaderPolicy: StepPolicy;
  private readonly followerPolicies: StepPolicy[];
  private readonly followerInputs: Float32Array[];
  // Own copies of each model's result: two roles may never share a policy's result arrays.
  private readonly leaderOutput = new Float32Array(OUTPUT_SIZE);
  private readonly guardCounts = { resets: 0, leashed: 0, upright: 0, counted: 0 };
  /** Steps in which an upright guard took another of a dancer's samples (follower or leader). */
  private upright = 0;
  /** Dancers' steps whose sample was chosen on the count (on_count.ts), leader and followers. */
  private counted = 0;
  private readonly uprightGuard: { settings: GuardSettings; ranges: Ranges } | null;
  /** The leader's guard (the same test at the manifest's leaderGuard margin). */
  private readonly leaderGuard: { settings: GuardSettings; ranges: Ranges } | null;
  /** Each dancer's chooser on the count (the manifest's onCount, inside its guard); null: off. */
  private readonly leaderOnCount: OnCount | null;
  private readonly followerOnCount: (OnCount | null)[];
  /** Each candidate's upright margin, for the choice on the count. */
  private standing = new Float64Array(0);
  private footwork = new Float64Array(0);
  private turnBack: boolean[] = [];
  /** Which of them the figure being led asks for (OnCount.prefers, from the dancer's input), outside a turn. */
  private prefers: boolean[] = [];
  /** The feet one candidate plants, which the chooser counts as still (on_count.ts planted). */
  private still: boolean[] = [false, false];
  /** Which of his samples are among those nearest a request's hands plan (guard.ts nearPlan). */
  private near: boolean[] = [];
  private readonly body = new Float64Array(3 * N_JOINTS);
  private readonly steps = new Float64Array(3 * STEPPED.length);
  /** The leader model's own variety (the manifest's); the slider sets the followers'. */
  private readonly leaderTemperature: number | null;
  private readonly followerOutputs: Float32Array[];
  private readonly followerIntentions: (Float32Array | null)[];
  private readonly timer = new StepTimer(300);
  /** The networks' part of each step (their policies' networkMs over the step). */
  private readonly networkTimer = new StepTimer(300);
  private readonly layer = new ContactLayer();
  private playback: LeaderPlayback | null = null;
  private temperature: number;
  /** The possible reactions: copies of the first follower dancing on by themselves (ghosts()). */
  private readonly ghostDancers: Dancer[] = [];
  /** Whether each ghost has branched yet (a new one branches at its first call). */
  private ghostBranched: boolean[] = [];
  private ghostCalls = 0;
  private readonly ghostPoses: Float32Array[] = [];
  /** The figure block the possible reactions read (at the frame they step from, as the followers will). */
  private readonly ghostFigure = new Float64Array(FIGURE_SIZE);
  /** Whether the leader leads figures of his own (?figures=, the panel's switch). */
  private own: boolean;
  private figureView: FigureView | null = null;

  constructor(private readonly options: SimulationOptions) {
    const { manifest, leader, followers } = options;
    if (followers.length < 1) throw new RangeError('a duet needs at least one follower');
    this.leaderPolicy = leader;
    this.followerPolicies = followers;
    this.followerInputs = followers.map((p) => p.input);
    this.temperature = manifest.defaultTemperature ?? 0.5;
    this.leaderTemperature = manifest.leaderTemperature ?? null;
    const g = manifest.guard;
    this.uprightGuard = g && g.samples >= 2 && manifest.plausibility ? { settings: g, ranges: manifest.plausibility } : null;
    const lg = manifest.leaderGuard;
    this.leaderGuard = lg && lg.samples >= 2 && manifest.plausibility ? { settings: lg, ranges: manifest.plausibility } : null;
    const oc = manifest.onCount && manifest.onCount.samples >= 2 ? manifest.onCount : null;
    // The figure being led read by the choice (on_count.ts figureWay): figureTurn's degrees asked of a
    // candidate; absent (older exports) or 0: off.
    const figureTurn = oc?.figureTurn || null;
    this.leaderOnCount = oc && this.leaderGuard ? new OnCount('leader', oc.samples, oc.strength, oc.hips, figureTurn) : null;
    this.followerOnCount = followers.map(() =>
      (oc && this.uprightGuard ? new OnCount('follower', oc.samples, oc.strength, oc.hips, figureTurn) : null));
    this.own = options.figures ?? true;
    this.duet = this.startDuet(null);
    this.shownBeat = this.duet.beat;
    this.leaderView = new View(false);
    this.followerViews = followers.map((p) => new View(p.hasIntention));
    this.leader = this.leaderView;
    this.followers = this.followerViews;
    this.followerOutputs = followers.map(() => new Float32Array(OUTPUT_SIZE));
    this.followerIntentions = followers.map((p) => (p.hasIntention ? new Float32Array(INTENTION_SIZE) : null));
    this.updateViews(true);
  }

  /** Both dancers in the start pose, the figures drawn anew from the page's seed. */
  private startDuet(tempo: number | null): Duet {
    const random = createUniform((this.options.seed + FIGURES_STREAM) >>> 0);
    return startDuet(this.options.manifest, this.followerPolicies.length, tempo, this.own, random);
  }

  reset(): void {
    this.duet = this.startDuet(this.duet.tempo);
    this.shownBeat = this.duet.beat;
    this.ghostBranched = []; // the possible reactions branch again from the new start
    this.upright = 0;
    this.counted = 0;
    for (const c of [this.leaderOnCount, ...this.followerOnCount]) c?.restart();
    this.playback?.start(this.duet.leader.track);
    this.timer.clear();
    this.updateViews(true);
  }

  /**
   * Ask the leader to lead her turn: +1 counterclockwise seen from above (her left), -1 clockwise.
   * It starts on the next beat, or after the figure running ends (rollout.ts askTurn); both dancers
   * read it (the figure block), as the hand hold carries a lead. A recorded leader (playback) leads
   * nothing: the request then does nothing. Returns whether the leader took it.
   */
  askTurn(direction: number): boolean {
    if (this.playback) return false;
    askTurn(this.duet, direction);
    return true;
  }

  get ownFigures(): boolean {
    return this.own;
  }

  /**
   * Whether the leader leads figures of his own, from the next step on. Switched off, his own
   * figures not begun yet are dropped with it (one planned a few beats ahead would otherwise still
   * come); the visitor's stay.
   */
  set ownFigures(on: boolean) {
    this.own = on;
    const figures = this.duet.figures;
    figures.own = on;
    if (!on) figures.led = figures.led.filter((x) => x.asked || x.start <= this.duet.frame);
  }

  /** The figure danced on the step on screen, else the next one planned (coming), else null. */
  get figure(): FigureView | null {
    const shown = this.duet.frame - 1;
    const led = this.duet.figures.led.find((x) => x.end >= shown) ?? null;
    const view = this.figureView;
    if (!led) return (this.figureView = null);
    const coming = led.start > shown;
    if (view && view.name === led.name && view.way === led.way && view.asked === led.asked && view.coming === coming) return view;
    return (this.figureView = { name: led.name, way: led.way, asked: led.asked, coming });
  }

  get anchor(): ArrayLike<number> {
    return this.duet.steering.anchor;
  }

  /** The way of her turn the visitor asked for, planned or being danced (0: none). */
  get turnAsked(): number {
    const shown = this.duet.frame - 1;
    return this.duet.figures.led.find((x) => x.asked && x.name === 'her_turn' && x.end >= shown)?.way ?? 0;
  }

  /** The count of the last step taken (the one on screen); duet.beat is the next step's. */
  private shownBeat = 0;

  setCount(beat: number | null, tempo: number): void {
    this.duet.tempo = tempo;
    if (beat !== null) this.duet.beat = beat;
  }

  get beat(): number {
    return this.shownBeat;
  }

  get tempo(): number {
    return this.duet.tempo;
  }

  async step(steer: Steer, temperature: number): Promise<void> {
    const started = performance.now();
    const inNetworks = this.networkTotal();
    this.temperature = temperature;
    const duet = this.duet;
    const playing = this.playback !== null;
    if (!playing) {
      const sx = steer.active ? steer.x : 0;
      const sz = steer.active ? steer.z : 0;
      planFigures(duet);
      steerPlan(duet.leader, duet.steering, sx, sz);
      leadPlan(duet);
    }
    this.shownBeat = duet.beat;
    stepInputs(duet, playing ? null : this.leaderPolicy.input, this.followerInputs);
    if (!playing) await this.stepLeader(leaderVariety(duet, this.leaderTemperature ?? temperature));
    for (let i = 0; i < this.followerPolicies.length; i++) {
      if (await this.followerOnTheCount(i, temperature)) continue;
      const result = await this.followerPolicies[i].run(temperature);
      this.followerOutputs[i].set(result.output);
      if (result.intention) this.followerIntentions[i]?.set(result.intention);
      await this.keepUpright(i, temperature);
    }
    // The feet each chooser's dancer plants in the step it took: still in the next step's footwork now.
    if (!playing) this.leaderOnCount?.took(this.leaderOutput);
    for (let i = 0; i < this.followerOutputs.length; i++) this.followerOnCount[i]?.took(this.followerOutputs[i]);
    if (this.playback) this.playback.advance(duet.leader.track, duet.leader.contacts);
    finishStep(duet, playing ? null : this.leaderOutput, this.followerOutputs, this.followerIntentions);
    this.updateViews(false);
    this.timer.add(performance.now() - started);
    this.networkTimer.add(this.networkTotal() - inNetworks);
  }

  /** Milliseconds all of this duet's policies have spent in their networks' runs. */
  private networkTotal(): number {
    let sum = this.leaderPolicy.networkMs ?? 0;
    for (const policy of this.followerPolicies) sum += policy.networkMs ?? 0;
    return sum;
  }

  /**
   * The upright guard (web/mirror/guard.ts) on follower i's output of this step: when the body it
   * would draw comes within the margin of the recording's range (her hips within the hipMargin),
   * draw fresh samples of the same input
   * (runDraws: the encoders once) and keep the most upright (each one step on from the same state:
   * no jump).
   */
  private async keepUpright(i: number, temperature: number): Promise<void> {
    const guard = this.uprightGuard;
    if (!guard) return;
    const offsets = this.duet.followers[i].offsets;
    const policy = this.followerPolicies[i];
    const { margin, hipMargin } = guard.settings;
    const hipSlack = hipSlackFor(margin, hipMargin);
    if (uprightMargin(this.followerOutputs[i], 0, guard.ranges, offsets, 0, hipSlack) >= guard.settings.margin) return;
    const k = guard.settings.samples;
    const { output, intention } = await policy.runDraws(k, temperature);
    const best = mostUpright(output, k, OUTPUT_SIZE, guard.ranges, offsets, 0, hipSlack);
    this.followerOutputs[i].set(output.subarray(best * OUTPUT_SIZE, (best + 1) * OUTPUT_SIZE));
    if (intention) this.followerIntentions[i]?.set(intention);
    this.upright++;
  }

  /**
   * Follower i's step on the count (web/mirror/on_count.ts): her samples drawn at once, the standing
   * one whose footwork is nearest what the count asks taken, one whose hips turn back passed over;
   * while she turns, the first standing one whose hips go on. Returns false when she has no chooser,
   * or turns with hips weighing nothing (then her step is taken as any other); when none of the
   * samples stands, her guard draws its own and takes the most upright.
   */
  private async followerOnTheCount(i: number, temperature: number): Promise<boolean> {
    const onCount = this.followerOnCount[i];
    const guard = this.uprightGuard;
    if (!onCount || !guard) return false;
    const offsets = this.duet.followers[i].offsets;
    const policy = this.followerPolicies[i];
    const target = onCount.target(policy.input);
    if (target === null && !(onCount.hips > 0)) return false; // she turns: her own sample, as any step
    const { margin, hipMargin } = guard.settings;
    const hipSlack = hipSlackFor(margin, hipMargin);
    const k = onCount.samples;
    const { output, intention } = await policy.runDraws(k, temperature);
    if (intention) this.followerIntentions[i]?.set(intention);
    const best = this.nearestOnCount(onCount, output, policy.input, target, guard.ranges, offsets, 0, hipSlack, margin);
    if (best < 0) {
      this.followerOutputs[i].set(output.subarray(0, OUTPUT_SIZE));   // judged below as any step is
      await this.keepUpright(i, temperature);
      return true;
    }
    this.followerOutputs[i].set(output.subarray(best * OUTPUT_SIZE, (best + 1) * OUTPUT_SIZE));
    if (target !== null) this.counted++;
    return true;
  }

  /** The standing candidate of the chooser's draws whose drawn footwork is nearest the target (none
   *  while the dancer turns), a candidate whose hips turn back passed over unless the others miss by
   *  onCount.hips more, the candidates the figure in the dancer's input asks for preferred (on_count.ts
   *  nearestCount, OnCount.prefers); -1 when none stands. Each body is drawn once for both judgements,
   *  into arrays kept between steps. */
  private nearestOnCount(
    onCount: OnCount, output: ArrayLike<number>, input: ArrayLike<number>, target: number | null, ranges: Ranges,
    offsets: ArrayLike<number>, slack: number, hipSlack: number, margin: number,
    k = onCount.samples, only: boolean[] | null = null,
  ): number {
    if (this.standing.length < k) {
      this.standing = new Float64Array(k);
      this.footwork = new Float64Array(k);
      this.turnBack = new Array<boolean>(k).fill(false);
      this.prefers = new Array<boolean>(k).fill(false);
    }
    for (let n = 0; n < k; n++) {
      this.standing[n] = uprightBody(output, n * OUTPUT_SIZE, ranges, offsets, slack, hipSlack, this.body);
      if (only && !only[n]) this.standing[n] = -Infinity; // not among those the choice may take
      drawnSteps(output, n * OUTPUT_SIZE, this.body, input, onCount.role, this.steps);
      this.footwork[n] = drawnFootwork(this.steps, planted(output, n * OUTPUT_SIZE, this.still));
      this.turnBack[n] = hipsTurnBack(this.steps, input, onCount.role);
    }
    const preferred = onCount.prefers(output, k, OUTPUT_SIZE, this.prefers, input);
    return nearestCount(this.footwork, this.turnBack, k, target, this.standing, margin, onCount.hips,
      preferred ? this.prefers : null);
  }

  /** The leader's output of this step, under the same guard (mirror/guard.py's UprightGuard wraps
   *  his policy alike): his head judged from the headMargin, his hips from the hipMargin, when the
   *  manifest has them. With keepPlan, while a request runs, every step draws the samples at once
   *  and takes the standing one whose lead hand is nearest the plan (guard.ts nearestPlan). */
  private async stepLeader(temperature: number): Promise<void> {
    const guard = this.leaderGuard;
    if (!guard) {
      this.leaderOutput.set((await this.leaderPolicy.run(temperature)).output);
      return;
    }
    const offsets = this.duet.leader.offsets;
    const policy = this.leaderPolicy;
    const { margin, headMargin, hipMargin, keepPlan, samples: k } = guard.settings;
    const slack = slackFor(policy.input, margin, headMargin);
    const hipSlack = hipSlackFor(margin, hipMargin);
    const nearest = keepPlan === true ? 1 : Number(keepPlan ?? 0);
    const plan = nearest > 0 && showsPlan(policy.input);
    if (plan) {
      // His lead: among the `nearest` standing samples whose hand is nearest the plan, the one on
      // the count (guard.py UprightGuard: the hand keeps to the lead, the feet to the beat).
      const { output } = await policy.runDraws(k, temperature);
      const onCount = nearest > 1 ? this.leaderOnCount : null;
      let best = -1;
      if (onCount) {
        if (this.near.length < k) this.near = new Array<boolean>(k).fill(false);
        nearPlan(output, k, OUTPUT_SIZE, policy.input, guard.ranges, offsets, margin, nearest, this.near, slack, hipSlack);
        const target = onCount.target(policy.input);
        best = this.nearestOnCount(onCount, output, policy.input, target, guard.ranges, offsets, slack, hipSlack, margin, k, this.near);
        if (best >= 0 && target !== null) this.counted++;
      }
      if (best < 0) best = nearestPlan(output, k, OUTPUT_SIZE, policy.input, guard.ranges, offsets, margin, slack, hipSlack);
      this.leaderOutput.set(output.subarray(best * OUTPUT_SIZE, (best + 1) * OUTPUT_SIZE));
      if (uprightMargin(this.leaderOutput, 0, guard.ranges, offsets, slack, hipSlack) < margin) this.upright++;
      return;
    }
    const onCount = this.leaderOnCount;
    // His step on the count (on_count.ts): the standing sample whose footwork follows the beat and
    // whose hips go on; while he turns, the first standing one whose hips go on.
    const target = onCount ? onCount.target(policy.input) : null;
    if (onCount && (target !== null || onCount.hips > 0)) {
      const n = onCount.samples;
      const { output } = await policy.runDraws(n, temperature);
      const best = this.nearestOnCount(onCount, output, policy.input, target, guard.ranges, offsets, slack, hipSlack, margin);
      if (best >= 0) {
        this.leaderOutput.set(output.subarray(best * OUTPUT_SIZE, (best + 1) * OUTPUT_SIZE));
        if (target !== null) this.counted++;
        return;
      }
    } else {
      const result = await policy.run(temperature);
      this.leaderOutput.set(result.output);
      if (uprightMargin(this.leaderOutput, 0, guard.ranges, offsets, slack, hipSlack) >= margin) return;
    }
    const { output } = await policy.runDraws(k, temperature);
    const best = mostUpright(output, k, OUTPUT_SIZE, guard.ranges, offsets, slack, hipSlack);
    this.leaderOutput.set(output.subarray(best * OUTPUT_SIZE, (best + 1) * OUTPUT_SIZE));
    this.upright++;
  }

  /**
   * k possible futures of the first follower, drawn as faint partners ("possible reactions").
   * Each is a copy of her that branched off and dances on by her model with its own noise, one
   * step per call (one batched run for all k: call once per step). The copies branch again from
   * her every GHOST_LIFE calls, each at its own moment, so at any time they are k different ages
   * along their own futures and stand apart (hips 29-32 cm apart on average, in the e2e test):
   * sampled one step from the same pose, as the page first drew them, they were 2.9 cm apart and
   * read as one blur. A copy whose model output is absurd branches again at once. The real
   * dancers are never touched.
   */
  async ghosts(k: number): Promise<Float32Array[]> {
    if (k <= 0) return [];
    const policy = this.followerPolicies[0];
    const follower = this.duet.followers[0];
    while (this.ghostDancers.length < k) this.ghostDancers.push(new Dancer(follower.offsets));
    for (let i = 0; i < k; i++) {
      // Ghost i branches when the count reaches its own offset in the cycle (i of k parts of it).
      if (!this.ghostBranched[i] || (this.ghostCalls + Math.round((i * GHOST_LIFE) / k)) % GHOST_LIFE === 0) this.ghostDancers[i].copyFrom(follower);
      this.ghostBranched[i] = true;
    }
    const input = policy.batchInput(k);
    const heard = musicInput(this.duet);
    // The figure being led, as the followers read it (rollout.ts stepInputs): every reaction feels the same lead.
    figureBlock(this.duet.figures.spans(this.duet.frame), NOW, this.ghostFigure, 0);
    for (let i = 0; i < k; i++) {
      followerInput(this.duet.leader.track, this.ghostDancers[i].track, NOW, input, i * INPUT_SIZE, this.ghostFigure, heard);
    }
    const { output } = await policy.runBatch(k, this.temperature);
    while (this.ghostPoses.length < k) this.ghostPoses.push(new Float32Array(POSITIONS_SIZE));
    for (let i = 0; i < k; i++) {
      const ghost = this.ghostDancers[i];
      if (outputIsAbsurd(output, i * OUTPUT_SIZE)) ghost.copyFrom(follower);
      else applyOutput(ghost, output, i * OUTPUT_SIZE);
      const p = ghost.track.positions;
      for (let n = 0; n < POSITIONS_SIZE; n++) this.ghostPoses[i][n] = p[NOW * POSITIONS_SIZE + n];
    }
    this.ghostCalls++;
    return this.ghostPoses.slice(0, k);
  }

  /** Called every animation frame by the HUD: sums into one reused object, allocates nothing. */
  guards(): { resets: number; leashed: number; upright: number; counted: number } {
    const g = this.guardCounts;
    g.upright = this.upright;
    g.counted = this.counted;
    g.resets = this.duet.leader.resets;
    g.leashed = this.duet.leader.leashed;
    for (const f of this.duet.followers) {
      g.resets += f.resets;
      g.leashed += f.leashed;
    }
    return g;
  }

  stepMs(): { median: number; p95: number } {
    return this.timer.summary();
  }

  networkMs(): { median: number; p95: number } {
    return this.networkTimer.summary();
  }

  /**
   * Drive the leader from a recorded motion (30 fps, e.g. motionFromBvhText) instead of the leader
   * model, or go back to the model with null. The recording starts where the leader stands now,
   * facing where it faces, and loops. A recording leads no figure: the figures planned or danced
   * are dropped, and none is planned while it plays (the followers read none); back with the
   * model, he plans his own again.
   */
  setLeaderPlayback(motion: Motion | null): void {
    if (!motion) {
      this.playback = null;
      return;
    }
    const playback = new LeaderPlayback(motion);
    playback.takeOver(this.duet.leader.track);
    this.playback = playback;
    this.duet.figures.led = [];
  }

  /** Whether the leader follows a recording; the recording's current frame and length. */
  get leaderPlayback(): { frame: number; frames: number } | null {
    return this.playback ? { frame: this.playback.frame, frames: this.playback.frames } : null;
  }

  private updateViews(jumped: boolean): void {
    const leader = this.duet.leader;
    this.leaderView.update(leader);
    this.duet.followers.forEach((f, i) => {
      const view = this.followerViews[i];
      view.update(f);
      // Before the first prediction: the leader's key joints where they are now, at every key.
      if (view.intention && !f.intention) {
        for (let k = 0; k < KEYS; k++) {
          KEY_JOINTS.forEach((j, n) => {
            for (let a = 0; a < 3; a++) view.intention![(k * KEY_JOINTS.length + n) * 3 + a] = leader.track.positions[NOW * POSITIONS_SIZE + 3 * j + a];
          });
        }
      }
    });
    this.showContacts(jumped);
  }

  /**
   * The contact layer (web/mirror/contact.ts) on the views: between the leader and the first follower
   * (the duet on screen); a compare-mode follower keeps its own glide and foot locks.
   */
  private showContacts(jumped: boolean): void {
    const leader = this.duet.leader, first = this.duet.followers[0];
    const lv = this.leaderView, fv = this.followerViews[0];
    // A dancer that was just placed anew must not drag its old locks or hold along.
    if (jumped || leader.resets !== lv.resets || first.resets !== fv.resets) this.layer.clear();
    lv.resets = leader.resets;
    fv.resets = first.resets;
    const layer = this.layer;
    layer.apply(lv.positions, fv.positions, leader.contacts, first.contacts, leader.heading, first.heading);
    lv.hands[layer.hands[0]] = layer.hold;
    fv.hands[layer.hands[1]] = layer.hold;
    for (let i = 1; i < this.followerViews.length; i++) {
      const view = this.followerViews[i], f = this.duet.followers[i];
      if (jumped || f.resets !== view.resets) {
        view.glide.clear();
        view.feet.clear();
      }
      view.resets = f.resets;
      view.glide.apply(view.positions);
      view.feet.apply(view.positions, f.contacts, f.heading, view.glide.glided());
    }
  }
}

/** The page's factory (see CreateSimulation in types.ts). */
export function createSimulation(options: SimulationOptions): DuetSimulation {
  return new DuetSimulation(options);
}
