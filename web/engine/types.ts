// Shared types between the page shell (main, scene, hud, ...) and the simulation (simulation.ts).
// The shell only ever talks to a `Simulation`; what happens inside one step (features, both
// models, pose) is the simulation's business.

import type { FigureName } from '../mirror/features';
import type { GuardSettings, Ranges } from '../mirror/guard';
import type { OnCountSettings } from '../mirror/on_count';
import type { Motion } from '../mirror/skeleton';
import type { RecordableDuet } from '../ui/record';

/** A 2D steering request on the floor, in world x/z; |(x, z)| is in 0..1. */
export interface Steer {
  x: number;
  z: number;
  /** true while the user is pressing a key or holding the joystick. */
  active: boolean;
}

/** What the shell needs to draw one dancer. All arrays are world space and owned by the
 *  simulation; the shell copies them after each step and never writes to them. */
export interface DancerView {
  /** Root on the floor: [x, z] metres. */
  root: [number, number];
  /** Facing angle in radians; forward = (sin θ, 0, cos θ). */
  heading: number;
  /** 17 joints × (x, y, z). */
  positions: Float32Array;
  /** Future root trajectory: 6 keys × (x, z). */
  future: Float32Array;
  /** Predicted partner key joints (intention): 6 keys × 5 key joints × (x, y, z). */
  intention?: Float32Array;
  /** Optional, for drawing hands, feet and the face: 17 joints × world rotation (row-major 3×3)
   *  of the same frame as `positions`. */
  rotations?: Float32Array;
  /** Optional, for the floor marks under planted feet: foot contact [left, right] in 0..1. */
  contacts?: Float32Array;
  /** Optional, for the hand glow: per hand [left, right], how far the contact layer draws it to
   *  the partner's hand, 0..1. */
  hands?: Float32Array;
}

/** A figure the leader leads (web/mirror/rollout.ts Led), as the page shows it. */
export interface FigureView {
  /** Her turn, or his own. */
  name: FigureName;
  /** The turning dancer's left (+1, counterclockwise seen from above) or right (-1). */
  way: number;
  /** Whether the visitor asked for it (else it is one of his own). */
  asked: boolean;
  /** Planned, not begun yet on the step on screen. */
  coming: boolean;
}

export interface Simulation {
  /** Back to the start pose; keeps the models. */
  reset(): void;
  /** Ask the leader model to lead her turn (-1 her right, +1 her left) on the next beat, or after
   *  the figure running; false while a file leads. */
  askTurn(direction: number): boolean;
  /** The way of her turn the visitor asked for, planned or being led: -1, +1, or 0 when none. */
  readonly turnAsked: number;
  /** Whether the leader leads figures of his own (?figures=1); set: from the next step on. */
  ownFigures: boolean;
  /** The figure danced on the step on screen, else the next one planned (coming), else null. */
  readonly figure: FigureView | null;
  /** The spot the leader dances around (world x, z): it moves only while the visitor steers.
   *  The simulation's own array (read it, do not keep or change it). */
  readonly anchor: ArrayLike<number>;
  /** Advance one 1/30 s step. */
  step(steer: Steer, temperature: number): Promise<void>;
  /**
   * The music the dancers hear from the next step on: its tempo (beats a minute), and the count
   * that step is on (beats), read from the audio clock; null: the dance counts on by itself.
   */
  setCount(beat: number | null, tempo: number): void;
  /** The count of the step on screen (beats since the music started) and the tempo it is at. */
  readonly beat: number;
  readonly tempo: number;
  leader: DancerView;
  /** One follower, or two in compare mode (ours first). */
  followers: DancerView[];
  /** k alternative next follower poses sampled from the model, each 17 × (x, y, z) world. */
  /** k possible futures of the first follower, each dancing on from its own branch point (call once per step). */
  ghosts(k: number): Promise<Float32Array[]>;
  /** Wall time of step() over the last 300 steps, milliseconds. */
  stepMs(): { median: number; p95: number };
  /** The part of each of those steps spent in the networks' runs (onnxruntime), milliseconds: the
   *  rest of a step is the page's own work (features, choices, pose). */
  networkMs(): { median: number; p95: number };
  /** Guard counts since the start: dancers reset after absurd model output, frames the leash
   *  drew a follower toward the leader (see rollout.ts), and steps the upright guard took another
   *  of a follower's samples (web/mirror/guard.ts), and dancers' steps whose sample was chosen on
   *  the count (web/mirror/on_count.ts). */
  guards(): { resets: number; leashed: number; upright: number; counted: number };
  /**
   * Drive the leader from a recorded motion (30 fps) instead of the leader model, or go back to
   * the model with null. Throws, changing nothing, on a motion it cannot play.
   */
  setLeaderPlayback(motion: Motion | null): void;
  /** The dancers as they are now, for the recorder (a new object after reset). */
  readonly duet: RecordableDuet;
}

/** What one model returns; the arrays are the policy's own and overwritten by its next run. */
export interface PolicyResult {
  /** [B × 323] raw model output (root update, trajectory, key joints, pose, contacts). */
  output: Float32Array;
  /** [B × 90] predicted partner key joints, or null for models without an intention predictor. */
  intention: Float32Array | null;
}

/** What the simulation needs of one model (policy.ts Policy; fakes in the tests). */
export interface StepPolicy {
  /** Write the [660] input features here before run(). */
  readonly input: Float32Array;
  /** Whether run() returns an intention. */
  readonly hasIntention: boolean;
  /** One step for one character: reads `input`. */
  run(temperature: number): Promise<PolicyResult>;
  /** The [k × 660] input block for a batched run (e.g. k ghost samples); write rows here. */
  batchInput(k: number): Float32Array;
  /** k samples at once, each with its own noise: reads batchInput(k), returns [k × ...] results. */
  runBatch(k: number, temperature: number): Promise<PolicyResult>;
  /** k samples of `input` at once, each with its own noise (the encoders run once): output
   *  [k × 323], intention [90] (one: it does not depend on the noise). */
  runDraws(k: number, temperature: number): Promise<PolicyResult>;
  /** Milliseconds spent in the network's runs since the policy was made (onnxruntime's part of a
   *  step: the page's Policy keeps it; a policy without it counts as 0). */
  readonly networkMs?: number;
}

/** What the shell hands to the simulation factory. */
export interface SimulationOptions {
  manifest: Manifest;
  leader: StepPolicy;
  /** [ours] or [ccm], or [ours, ccm] in compare mode. */
  followers: StepPolicy[];
  /** Seed for anything random the simulation does itself (the policies carry their own PRNG):
   *  when and which figures the leader leads of his own. */
  seed: number;
  /** Whether the leader leads figures of his own (?figures=, default true). */
  figures?: boolean;
}

/** simulation.ts exports a function of this type named `createSimulation`. */
export type CreateSimulation = (options: SimulationOptions) => Simulation;

export interface ModelEntry {
  file: string;
  bytes: number;
  /** Codebook channels C and classes D; the noise input is [B, C·D]. */
  channels: number;
  classes: number;
  /** Whether the model has an `intention` output. */
  intention: boolean;
  /** 'leader' or 'follower': which input layout the model reads. */
  role: string;
}

/** public/models/manifest.json, written by training/learning/export.py. */
export interface Manifest {
  version: number;
  fps: number;
  skeleton: {
    names: string[];
    parents: number[];
    offsets: { leader: number[][]; follower: number[][] };
  };
  keyJoints: number[];
  layout: {
    input: number;
    output: number;
    intention: number;
    /** (block name, size) in order, as training/mirror/features.py lays them out (web/mirror/features.ts too). */
    followerInput: [string, number][];
    leaderInput: [string, number][];
    outputBlocks: [string, number][];
  };
  /** Opaque to the shell; read by rollout.ts (startDuet). */
  startPose: unknown;
  models: Record<string, ModelEntry>;
  /** The followers' variety (Gumbel temperature): the slider's default. */
  defaultTemperature: number;
  /** The leader model's own variety; absent in older exports (then the slider's, as the followers). */
  leaderTemperature?: number;
  /** The leader's variety while he leads a figure the visitor asked for (rollout.ts leaderVariety); absent: his own throughout. */
  leadingTemperature?: number;
  /** The followers' upright guard (web/mirror/guard.ts); absent: no guard. */
  guard?: GuardSettings;
  /** The leader's upright guard, the same with its own margin; absent: no guard. */
  leaderGuard?: GuardSettings;
  /** Both guards' choice on the count (web/mirror/on_count.ts): samples each step, the pull's
   *  strength, the hips' weight and figureTurn (the turn the figure being led asks of a sample;
   *  absent or 0: the figure not read); absent: each dancer takes its one sample. */
  onCount?: OnCountSettings;
  /** The recording's range (training/evaluation/plausibility.py); the guard judges against it. */
  plausibility?: Ranges;
  /** What the dancers hear: the tempo (beats a minute) when the address names none, and what the
   *  tempo control offers; absent in older exports (web/mirror/music.ts DEFAULT_TEMPO). */
  music?: { tempo: number; range?: [number, number] };
  credit: string;
}

/** Follower model choices in the panel and the URL. */
export type FollowerChoice = 'ours' | 'ccm' | 'compare';

/** One dancer in the test hook. `hip`: the drawn hip joint's height above the floor, metres;
 *  `screen`: where the hips are drawn, client pixels (read when asked, for tests that drop files
 *  on a dancer); `outline`: where the top of the head and each shoe's toe and heel are drawn,
 *  client pixels (read when asked; null for capsule figures: web/draw/body.ts OUTLINE). */
export interface DancerHook {
  root: [number, number];
  heading: number;
  hip?: number;
  screen?: [number, number] | null;
  outline?: [number, number][] | null;
}

/** A figure in the test hook: its name (her turn or his), the turning dancer's way (left:
 *  counterclockwise seen from above), and whether the visitor asked for it. */
export interface FigureHook {
  name: FigureName;
  way: 'left' | 'right';
  asked: boolean;
}

/** The test hook on window.duet: the end-to-end tests (tests/e2e) read only this. */
export interface DuetHook {
  ready: boolean;
  error: string | null;
  /** Simulation steps taken since the page loaded (not reset by R). */
  frame: number;
  /** The two dancers (DancerHook). */
  leader: DancerHook;
  follower: DancerHook;
  /** Called after each frame is drawn, if set (tests read `outline` and the camera there). */
  afterDraw?: () => void;
  /** step() wall time over the last 300 steps: features + both models + pose. */
  stepMs: { median: number; p95: number };
  /** The part of those steps spent in the networks' runs (onnxruntime). */
  networkMs: { median: number; p95: number };
  /** Follower model in use: 'ours', 'ccm' or 'compare'. */
  model: string;
  /** Ask the leader to lead her turn, as T does (-1 her right, +1 her left): it starts on the next
   *  beat, or after the figure running; false before the dance starts or while a file leads. */
  askTurn?: (direction: number) => boolean;
  /** The way of her turn the visitor asked for, planned or being led: -1, +1, or 0 when none. */
  turnAsked?: number;
  /** The figure being danced on the step on screen (asked for or his own), or null. */
  figure?: FigureHook | null;
  /** The spot the leader dances around (world x, z): it moves only while the visitor steers. */
  anchor?: [number, number];
  /** The music's tempo, beats a minute, and the count of the step on screen (beats since the
   *  music started, float): the music's while it plays, the dance's own silent count otherwise. */
  tempo?: number;
  beat?: number;
  /** performance.now() when the step on screen read its count (from the music while it plays). */
  countAt?: number;
  /** The music (read when asked): its state, the audio context's, notes the band scheduled,
   *  eighths it dropped (a main thread held past the lookahead), the count the listener hears now
   *  and the audio clock's time of it, seconds, and the tempo the band plays (all null while none
   *  plays). */
  music?: { state: string; context: string; scheduled: number; dropped: number; heard: number | null; time: number | null; tempo: number | null; problem: string };
  /** The contact layer's hand hold between the leader and the (first) follower, 0..1
   *  (web/mirror/contact.ts): 1 when the closest hands meet. */
  hold: number;
  // Extras for the bench and for debugging (not part of the contract).
  paused: boolean;
  threads: number;
  /** Bytes of the ONNX files loaded so far. */
  modelBytes: number;
  /** performance.now() once the first dancing frame (the first step's pose) is painted: the
   *  rendering update that shows it has run (boot.ts, afterPaint). Cold load to a dancing page. */
  firstFrameMs: number | null;
  /** performance.now() once the floor and the standing pair are first painted (loading scene). */
  sceneMs?: number | null;
  /** Bytes of the first dance's downloads (wasm + models), so far and in all: compressed, as
   *  they travel, once `sized`; decoded before. */
  download?: { loaded: number; total: number; sized: boolean };
  /** How the dancers are drawn: skinned characters, or capsule figures (?bodies=sticks). */
  bodies?: 'skinned' | 'sticks';
  /** Where the camera is (read when asked): degrees around, degrees down from above, metres from
   *  the pair's midpoint (web/draw/orbit.ts CameraOrbit). */
  camera?: { azimuth: number; polar: number; distance: number };
  /** Frames drawn so far (animation frames that drew nothing are not counted). */
  drawn?: number;
  /** When each stage of the start happened, ms since navigation (web/engine/boot.ts). */
  bootTimings?: Record<string, number>;
  /** What the fetcher worker downloaded (this page's resource timing does not list it): sizes,
   *  and times in ms since navigation. */
  workerFiles?: { url: string; transferSize: number; encodedBodySize: number; start: number; firstByte: number; end: number }[];
  /** The avatar each dancer wears (a dropped .vrm): its name; in the last pose, the worst angle,
   *  degrees, between its bones as drawn and the dancer's, and how far, cm, its ankles are from the
   *  dancer's, scaled to its size (web/draw/avatar.ts). */
  avatars?: Partial<Record<'leader' | 'follower', { name: string; fitDeg: number; feetCm: number }>>;
  /** The possible reactions drawn now: each one's hip on the floor (x, z), metres (read when asked). */
  ghostHips?: [number, number][];
  /** Whether the help is open (the dance holds still behind it, `paused` or not). */
  helpOpen?: boolean;
  /** The version of the models and wasm this page runs (the service worker's cache is named by
   *  it), of the models its manifest names, and of the models the page's build shipped with ('' in
   *  development): the last two differ only on a page and manifest of two deployments. */
  version?: string;
  modelsVersion?: string;
  buildVersion?: string;
  /** How many times the start's watchdog restarted this visit before it danced (watchdog.ts). */
  recovered?: number;
}

declare global {
  interface Window {
    duet?: DuetHook;
  }
}
