// duet: the page. One scene, one loop (three.js examples style).
//
// The simulation advances in fixed 1/30 s steps, decoupled from the display rate: an accumulator
// collects real time (times the speed setting), each step runs the models once, and drawing
// interpolates between the last two steps, so 60 or 120 Hz screens look smooth and a slow frame
// never changes the dance.

import './style.css';
import type { CreateSimulation, DancerView, DuetHook, FollowerChoice, Manifest, Simulation } from './types';
import type { Policy } from './policy';
import { checkBrowserSupport, installGlobalErrorHandlers, showError } from './errors';
import { fetchModelBytes, loadManifest } from './manifest';
import { Stage } from './scene';
import { Controls } from './controls';
import { Hud } from './hud';
import { Panel } from './panel';
import { LIMITS, copyLink, defaultSettings, readSettings, writeSettings } from './share';
import type { Motion } from './skeleton';
import { MAX_RECORD_FRAMES, type RecordableDuet, Recorder, formatDuration } from './record';
import { RecordPanel } from './recordpanel';
import { LeaderFileInput } from './dropzone';
import { showToast } from './toast';

/** The duet loop (features, both models, pose): loaded with the models, not with the page. */
const loadSimulationModule = () => import('./simulation');

const DT = 1 / 30;
const NO_GUARDS = { resets: 0, leashed: 0 };
/** A long stall counts as at most this much time, so the dance never jumps ahead. */
const MAX_FRAME_SECONDS = 0.5;
/** Simulation time the loop may fall behind before it gives up on catching up (slow motion). */
const MAX_BACKLOG_SECONDS = 0.5;
/** Wall time spent stepping before we draw anyway: at least this, or as long as the last frame
 *  took to draw, so that slow drawing (software WebGL) cannot starve the simulation either. */
const MIN_STEP_BUDGET_MS = 50;
const MAX_GHOSTS = LIMITS.ghosts[1];
const FOLLOWER_MODELS: Record<FollowerChoice, string[]> = {
  ours: ['follower'],
  ccm: ['follower_ccm'],
  compare: ['follower', 'follower_ccm'],
};

const hook: DuetHook = {
  ready: false,
  error: null,
  frame: 0,
  leader: { root: [0, 0], heading: 0 },
  follower: { root: [0, 0], heading: 0 },
  stepMs: { median: 0, p95: 0 },
  model: 'ours',
  paused: false,
  threads: 1,
  modelBytes: 0,
  firstFrameMs: null,
};
window.duet = hook;
installGlobalErrorHandlers();

/** Last two simulation states of one dancer, copied so drawing can interpolate between them. */
class DancerTrack {
  readonly previous = new Float32Array(51);
  readonly current = new Float32Array(51);
  readonly drawn = new Float32Array(51);
  readonly root = new Float32Array(4); // previous x, z, current x, z
  readonly future = new Float32Array(12);
  readonly intention = new Float32Array(90);
  hasIntention = false;

  capture(view: DancerView, snap: boolean): void {
    this.previous.set(snap ? view.positions : this.current);
    this.current.set(view.positions);
    this.root[0] = snap ? view.root[0] : this.root[2];
    this.root[1] = snap ? view.root[1] : this.root[3];
    this.root[2] = view.root[0];
    this.root[3] = view.root[1];
    this.future.set(view.future);
    this.hasIntention = view.intention !== undefined;
    if (view.intention) this.intention.set(view.intention);
  }

  interpolate(alpha: number): Float32Array {
    for (let i = 0; i < 51; i++) this.drawn[i] = this.previous[i] + (this.current[i] - this.previous[i]) * alpha;
    return this.drawn;
  }

  rootX(alpha: number): number {
    return this.root[0] + (this.root[2] - this.root[0]) * alpha;
  }

  rootZ(alpha: number): number {
    return this.root[1] + (this.root[3] - this.root[1]) * alpha;
  }
}

function publish(target: DuetHook['leader'], view: DancerView): void {
  target.root[0] = view.root[0];
  target.root[1] = view.root[1];
  target.heading = view.heading;
}

async function start(): Promise<void> {
  checkBrowserSupport();
  // Start every download at once: onnxruntime and the simulation code now, the models as soon as
  // the manifest names them; the floor is drawn meanwhile.
  const runtime = Promise.all([import('./ort'), import('./policy'), loadSimulationModule()]);
  runtime.catch(() => undefined); // reported where it is awaited
  const manifest: Manifest = await loadManifest();
  const defaults = defaultSettings(manifest.defaultTemperature);
  const settings = readSettings(location.search, defaults);
  const hasCcm = 'follower_ccm' in manifest.models;
  if (!hasCcm) settings.model = 'ours';

  const downloads = new Map<string, Promise<Uint8Array>>();
  const download = (name: string) => {
    if (!downloads.has(name)) {
      const bytes = fetchModelBytes(manifest, name);
      bytes.catch(() => undefined); // reported where it is awaited
      downloads.set(name, bytes);
    }
    return downloads.get(name)!;
  };
  for (const name of ['leader', ...FOLLOWER_MODELS[settings.model]]) download(name);

  // The floor is up while the models download: something to look at, never a blank canvas.
  const app = document.getElementById('app')!;
  const stage = new Stage(app, manifest.skeleton.parents, MAX_GHOSTS);
  if (settings.camera) stage.setOrbit(settings.camera);
  const hud = new Hud(document.getElementById('overlay')!);
  hud.setStatus('loading models…');
  const credit = document.getElementById('credit');
  if (credit) credit.textContent = manifest.credit ?? '';

  let simulation: Simulation | null = null;
  let paused = false;
  let accumulator = 0;
  let stepping = false;
  let drawMs = 0; // smoothed wall time per animation frame not spent stepping
  let steppedMs = 0; // wall time spent stepping since the last animation frame
  let ghostPoses: Float32Array[] = [];
  const leader = new DancerTrack();
  const followers = [new DancerTrack(), new DancerTrack()];

  // Steps, resets and model switches must not overlap: they all go through this queue.
  let queue: Promise<void> = Promise.resolve();
  const exclusive = (task: () => Promise<void> | void): Promise<void> => {
    const run = queue.then(task);
    queue = run.catch(() => undefined);
    return run;
  };
  const fail = (error: unknown) => {
    simulation = null; // stop stepping; the overlay explains
    showError(error);
  };

  const capture = (snap: boolean) => {
    if (!simulation) return;
    leader.capture(simulation.leader, snap);
    for (let i = 0; i < simulation.followers.length; i++) followers[i].capture(simulation.followers[i], snap);
    publish(hook.leader, simulation.leader);
    publish(hook.follower, simulation.followers[0]);
    const stats = simulation.stepMs();
    hook.stepMs.median = stats.median;
    hook.stepMs.p95 = stats.p95;
  };

  const reset = () =>
    exclusive(() => {
      if (!simulation) return;
      simulation.reset();
      accumulator = 0;
      capture(true);
      stage.follow(0.5 * (leader.root[2] + followers[0].root[2]), 0.5 * (leader.root[3] + followers[0].root[3]), 0, true);
    });

  const togglePause = () => {
    paused = !paused;
    hook.paused = paused;
    hud.setStatus(paused ? 'paused — Space to resume' : '');
  };

  const controls = new Controls({
    surface: stage.canvas,
    viewForward: (out) => stage.viewForward(out),
    onPause: togglePause,
    onReset: reset,
  });

  // Models load after the floor is drawn: ORT alone is 3.7 MB gzipped.
  let createSimulation: CreateSimulation | null = null;
  let createPolicy: ((manifest: Manifest, name: string, bytes: Uint8Array, seed: number) => Promise<Policy>) | null = null;

  // Each model gets its own noise stream, all derived from the one seed in the URL.
  const policies = new Map<string, Promise<Policy>>();
  const modelNames = ['leader', 'follower', 'follower_ccm'];
  const policy = (name: string): Promise<Policy> => {
    let loading = policies.get(name);
    if (!loading) {
      const seed = (settings.seed + modelNames.indexOf(name) * 0x9e3779b9) >>> 0;
      loading = download(name).then((bytes) => createPolicy!(manifest, name, bytes, seed)).then((p) => {
        hook.modelBytes += p.entry.bytes;
        return p;
      });
      policies.set(name, loading);
    }
    return loading;
  };

  /** (Re)build the simulation for a follower choice; a new simulation starts from the start pose. */
  const useModel = (choice: FollowerChoice) =>
    exclusive(async () => {
      hud.setStatus('loading models…');
      const [leaderPolicy, ...followerPolicies] = await Promise.all([policy('leader'), ...FOLLOWER_MODELS[choice].map(policy)]);
      simulation = createSimulation!({ manifest, leader: leaderPolicy, followers: followerPolicies, seed: settings.seed });
      applyLeaderFile(); // record & leader file: a new simulation keeps the leader's file
      hook.model = choice;
      accumulator = 0;
      capture(true);
      stage.follow(0.5 * (leader.root[2] + followers[0].root[2]), 0.5 * (leader.root[3] + followers[0].root[3]), 0, true);
      hud.setStatus(paused ? 'paused — Space to resume' : '');
    });

  const refreshGhosts = async () => {
    ghostPoses = simulation && settings.ghosts > 0 ? await simulation.ghosts(settings.ghosts) : [];
  };

  const panel = new Panel({
    settings,
    models: hasCcm ? ['ours', 'ccm', 'compare'] : ['ours'],
    onModel: (choice) => useModel(choice).catch(fail),
    onGhosts: () => exclusive(refreshGhosts).catch(fail),
    onReset: reset,
    onShare: async () => {
      const query = writeSettings(settings, stage.getOrbit(), defaults.temperature);
      const url = `${location.origin}${location.pathname}?${query}`;
      history.replaceState(null, '', url);
      if (await copyLink(url)) {
        hud.setStatus('link copied');
        setTimeout(() => hud.setStatus(paused ? 'paused — Space to resume' : ''), 2000);
      } else {
        window.prompt('Copy this link:', url);
      }
    },
  });

  // --- Record & leader file (record.ts, dropzone.ts) --------------------------------------------
  const recordable = (): RecordableDuet | null => simulation?.duet ?? null;
  const recorder = new Recorder(MAX_RECORD_FRAMES, () =>
    showToast('Recording stopped', `It reached the ${formatDuration(MAX_RECORD_FRAMES / 30)} limit. Download the take (“download BVH”).`, 'error', 15_000));
  let leaderFile: { motion: Motion; name: string } | null = null;
  function applyLeaderFile(): void {
    if (simulation) simulation.setLeaderPlayback(leaderFile?.motion ?? null);
  }
  const leaderFileInput = new LeaderFileInput({
    notify: showToast,
    onMotion: (motion, name) =>
      exclusive(() => {
        if (!simulation) throw new Error('The dancers are still loading; try again in a moment.');
        simulation.setLeaderPlayback(motion); // throws (nothing changed) on a motion it cannot play
        leaderFile = { motion, name };
        recordPanel.setLeaderFile(name);
      }),
  });
  const recordPanel = new RecordPanel({
    gui: panel.gui,
    overlay: document.getElementById('overlay')!,
    recorder,
    duet: recordable,
    between: (task) => exclusive(task),
    notify: showToast,
    onOpenLeaderFile: () => leaderFileInput.open(),
    onLeaderModel: () =>
      exclusive(() => {
        leaderFile = null;
        applyLeaderFile();
        recordPanel.setLeaderFile(null);
      }).catch(fail),
  });
  // --- end record & leader file ------------------------------------------------------------------

  /** Run the steps that real time asks for; called from the animation loop, one call at a time. */
  const advance = async () => {
    const began = performance.now();
    let steps = 0;
    while (simulation && accumulator >= DT) {
      await simulation.step(controls.getSteer(), settings.temperature);
      accumulator -= DT;
      steps++;
      capture(false);
      if (recorder.recording && recordable()) recorder.capture(recordable()!); // record & leader file
      hook.frame++;
      if (hook.firstFrameMs === null) hook.firstFrameMs = performance.now();
      hook.ready = true;
      // Draw between steps when stepping is slow (software rendering, big models, high speed).
      if (performance.now() - began > Math.max(MIN_STEP_BUDGET_MS, drawMs)) break;
    }
    if (steps > 0 && settings.ghosts > 0) await refreshGhosts();
    if (steps > 0) recordPanel.update(); // record & leader file
    steppedMs += performance.now() - began;
  };

  // Measure the display rate for the HUD.
  let frames = 0;
  let fps = 0;
  let fpsSince = performance.now();
  let last = performance.now();
  let lastIdleDraw = -Infinity;

  const frame = (now: number) => {
    requestAnimationFrame(frame);
    const elapsed = Math.min(Math.max(0, now - last) / 1000, MAX_FRAME_SECONDS);
    drawMs += 0.2 * (Math.max(0, elapsed * 1000 - steppedMs) - drawMs);
    steppedMs = 0;
    last = now;
    frames++;
    if (now - fpsSince >= 500) {
      fps = (frames * 1000) / (now - fpsSince);
      frames = 0;
      fpsSince = now;
    }

    // A device that cannot keep up runs the dance in slow motion rather than piling up work.
    if (simulation && !paused) accumulator = Math.min(accumulator + elapsed * settings.speed, MAX_BACKLOG_SECONDS * settings.speed);
    if (simulation && !stepping && accumulator >= DT) {
      stepping = true;
      exclusive(advance)
        .catch(fail)
        .finally(() => (stepping = false));
    }

    // While models load (or after an error) there is nothing moving: redraw rarely and leave the
    // CPU to downloading and compiling.
    if (simulation || now - lastIdleDraw > 250) {
      lastIdleDraw = now;
      draw(Math.min(1, accumulator / DT), elapsed);
    }
    const guards = simulation ? simulation.guards() : NO_GUARDS;
    hud.update(now, { stepMs: hook.stepMs, fps, threads: hook.threads, modelBytes: hook.modelBytes, guards });
  };

  const draw = (alpha: number, elapsed: number) => {
    const count = simulation ? simulation.followers.length : 0;
    stage.leader.setCount(simulation ? 1 : 0);
    if (simulation) stage.leader.setPose(0, leader.interpolate(alpha));
    for (let i = 0; i < stage.followers.length; i++) {
      stage.followers[i].setCount(i < count ? 1 : 0);
      if (i < count) stage.followers[i].setPose(0, followers[i].interpolate(alpha));
    }

    // Overlays: the leader's and each follower's future root path; the followers' intentions.
    for (let i = 0; i < stage.trajectories.length; i++) {
      const overlay = stage.trajectories[i];
      const track = i === 0 ? leader : followers[i - 1];
      overlay.group.visible = settings.trajectories && simulation !== null && i <= count;
      if (overlay.group.visible) overlay.setFloorPath(track.rootX(alpha), track.rootZ(alpha), track.future);
    }
    for (let i = 0; i < stage.intentions.length; i++) {
      const overlay = stage.intentions[i];
      overlay.group.visible = settings.intentions && i < count && followers[i].hasIntention;
      if (overlay.group.visible) overlay.setKeyMajorPoints(followers[i].intention, 6, 5);
    }

    const ghosts = settings.ghosts > 0 ? Math.min(ghostPoses.length, settings.ghosts) : 0;
    stage.ghosts.setCount(ghosts);
    for (let i = 0; i < ghosts; i++) stage.ghosts.setPose(i, ghostPoses[i]);

    if (simulation) stage.follow(0.5 * (leader.rootX(alpha) + followers[0].rootX(alpha)), 0.5 * (leader.rootZ(alpha) + followers[0].rootZ(alpha)), elapsed);
    stage.render();
  };

  requestAnimationFrame(frame);
  // Browsers stop animation frames in hidden tabs: start timing afresh when the tab comes back.
  document.addEventListener('visibilitychange', () => {
    last = performance.now();
  });

  const [ortModule, policyModule, simulationModule] = await runtime;
  hook.threads = ortModule.configureThreads(settings.threads);
  createPolicy = policyModule.createPolicy;
  createSimulation = simulationModule.createSimulation;
  await useModel(settings.model);
}

start().catch(showError);
