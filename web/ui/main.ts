// duet: the page. One scene, one loop (three.js examples style).
//
// The simulation advances in fixed 1/30 s steps, decoupled from the display rate: an accumulator
// collects real time (times the speed setting), each step runs the models once, and drawing
// interpolates between the last two steps, so 60 or 120 Hz screens look smooth and a slow frame
// never changes the dance.

import './style.css';
import type { CreateSimulation, DancerView, DuetHook, FigureHook, FigureView, FollowerChoice, Manifest, Simulation } from '../engine/types';
import type { Policy } from '../engine/policy';
import { DuetError, checkBrowserSupport, installGlobalErrorHandlers, showError } from './errors';
import { loadManifest } from '../engine/manifest';
import { Fetcher } from '../engine/fetcher';
import { FOLLOWER_MODELS } from '../engine/firstdance';
import { standingViews } from '../engine/standing';
import { BUILD_MODELS, assetVersion, keepForOffline, modelsVersion, otherDeployment, registerOffline } from '../engine/offline';
import { BootWatchdog, clearRestarts, restartsSoFar, takeRestart } from '../engine/watchdog';
import { SiteUpdatedError, restart, restarting, siteReplaced, siteUpdated, stalled } from './updates';
import { GLUE_URL } from '../engine/wasm';
import { LoadingBar } from './loading';
import { DEFAULT_ORBIT, Stage } from '../draw/scene';
import { readBodies } from '../draw/body';
import { Controls, releaseFocusAfterUse } from './controls';
import { Hud, PauseButton } from './hud';
import { TurnButtons } from './turns';
import { ClipButton, FullscreenButton } from './clip';
import { Panel } from './panel';
import { CompareLayout } from './compare';
import { ViewCentre } from './layout';
import { LIMITS, type Settings, addressQuery, copyLink, defaultSettings, formatCamera, readSettings } from './share';
import { FPS, type Motion } from '../mirror/skeleton';
import { KEYS, N_KEY_JOINTS } from '../mirror/features';
import { DancerTrack } from '../draw/interpolation';
import { MAX_RECORD_FRAMES, Recorder, formatDuration } from './record';
import { RecordPanel } from './recordpanel';
import { LeaderFileInput, MAX_AVATAR_BYTES, displayName } from './dropzone';
import { showToast } from './toast';
import { afterPaint, bootMark, bootSpan, bootTimings } from '../engine/boot';
import { Music } from './music';
import { CountDisplay } from './count';
import { helpFacts } from './help';
import { manifestTempo } from '../mirror/rollout';

// Every static import above (three.js included) has been fetched, parsed and run by now.
bootMark('main');

const DT = 1 / FPS;
const NO_GUARDS = { resets: 0, leashed: 0, upright: 0 };
/** A long stall counts as at most this much time, so the dance never jumps ahead. */
const MAX_FRAME_SECONDS = 0.5;
/** Simulation time the loop may fall behind before it gives up on catching up (slow motion). */
const MAX_BACKLOG_SECONDS = 0.5;
/** Wall time spent stepping before we draw anyway: at least this, or as long as the last frame
 *  took to draw, so that slow drawing (software WebGL) cannot starve the simulation either. */
const MIN_STEP_BUDGET_MS = 50;
const MAX_GHOSTS = LIMITS.ghosts[1];
const WORKER_START_WAIT_MS = 300;
const WARM_UP_DELAY_MS = 500;
const PAUSED_STATUS = 'paused — Space or “resume” to go on';
/** After a drag the camera glides on (OrbitControls' damping, counted in frames: seconds at a low
 *  frame rate). Its place is checked this often, and goes to the address when it changed, until
 *  it stood still for CAMERA_STILL_CHECKS checks. */
const CAMERA_CHECK_MS = 300;
const CAMERA_STILL_CHECKS = 10;
/** Each model gets its own noise stream, all derived from the one seed in the URL. */
const MODEL_NAMES = ['leader', 'follower', 'follower_ccm'];

/** The duet whose step times the hook reports (the page's simulation, once it has one). */
let timed: Pick<Simulation, 'stepMs' | 'networkMs'> | null = null;
const NO_TIMES = Object.freeze({ median: 0, p95: 0 });

const hook: DuetHook = {
  ready: false,
  error: null,
  frame: 0,
  leader: { root: [0, 0], heading: 0 },
  follower: { root: [0, 0], heading: 0 },
  // Read when asked (the HUD each frame, the bench and the tests), not summarized every step.
  get stepMs() {
    return timed ? timed.stepMs() : NO_TIMES;
  },
  get networkMs() {
    return timed ? timed.networkMs() : NO_TIMES;
  },
  model: 'ours',
  paused: false,
  threads: 1,
  modelBytes: 0,
  firstFrameMs: null,
  hold: 0,
  figure: null,
  bootTimings,
  recovered: restartsSoFar(),
};
window.duet = hook;

installGlobalErrorHandlers();

/** The hook's figure for the simulation's: only one being danced (a coming one is not yet). */
function figureHook(figure: FigureView | null): FigureHook | null {
  if (!figure || figure.coming) return null;
  return { name: figure.name, way: figure.way > 0 ? 'left' : 'right', asked: figure.asked };
}

function publish(target: DuetHook['leader'], view: DancerView): void {
  target.root[0] = view.root[0];
  target.root[1] = view.root[1];
  target.heading = view.heading;
  target.hip = view.positions[1]; // the drawn hip joint's height, metres
}

/**
 * onnxruntime, the policies and the duet loop (features, both models, pose): loaded with the
 * models, not with the page (ORT alone is 3.7 MB gzipped).
 */
function loadRuntime() {
  // onnxruntime imports its Emscripten loader when the first session is made, which on a first
  // visit is while the last model still downloads: fetch and parse it now, while the link is free.
  const loader = document.createElement('link');
  loader.rel = 'modulepreload';
  loader.href = GLUE_URL;
  document.head.append(loader);
  const runtime = bootSpan('runtime', () => Promise.all([import('../engine/ort'), import('../engine/policy'), import('../engine/simulation')]));
  runtime.catch(() => undefined); // reported where it is awaited
  return runtime;
}

type Runtime = Awaited<ReturnType<typeof loadRuntime>>;

/** The page once the manifest is in: floor, controls, panel, recording, and the animation loop. */
class Page {
  private readonly defaults: Settings;
  private readonly settings: Settings;
  private readonly hasCcm: boolean;
  private readonly stage: Stage;
  private readonly panel: Panel;
  private readonly hud: Hud;
  private readonly controls: Controls;
  private readonly pauseButton: PauseButton;
  private readonly turnButtons: TurnButtons;
  private readonly recorder: Recorder;
  private readonly leaderFileInput: LeaderFileInput;
  private readonly avatarInput: HTMLInputElement;
  private readonly recordPanel: RecordPanel;
  private readonly music: Music;
  private readonly count: CountDisplay;
  /** The manifest's tempo: the address names another only when it differs. */
  private readonly defaultTempo: number;

  private simulation: Simulation | null = null;
  /** The visitor's pause (Space, the pause button). */
  private paused = false;
  /** The help is open: the dance holds still behind it, apart from the visitor's own pause, so
   *  that closing the help leaves the dance as it was (paused stays paused). */
  private helpOpen = false;
  private accumulator = 0;
  private stepping = false;
  private drawMs = 0; // smoothed wall time per animation frame not spent stepping
  private steppedMs = 0; // wall time spent stepping since the last animation frame
  private ghostPoses: Float32Array[] = [];
  private readonly leader = new DancerTrack();
  private readonly followers = [new DancerTrack(), new DancerTrack()];
  /** Compare mode draws the second follower beside the first pair, with a copy of the leader. */
  private readonly compare = new CompareLayout();
  /** Centres the picture in what the open panel leaves visible. */
  private readonly viewCentre: ViewCentre;
  /** Steps, resets and model switches must not overlap: they all go through this queue. */
  private queue: Promise<void> = Promise.resolve();
  private leaderFile: { motion: Motion; name: string } | null = null;
  /** The camera's place as the address last had it, checks since it last moved, and the timer. */
  private cameraPlace = '';
  private cameraStill = 0;
  private cameraCheck = 0;
  /** The simulation's figure the hook's was made from (it keeps its object while unchanged). */
  private hookedFigure: FigureView | null = null;

  // Set once the runtime has loaded.
  private createSimulation: CreateSimulation | null = null;
  private createPolicy: Runtime[1]['createPolicy'] | null = null;
  private readonly policies = new Map<string, Promise<Policy>>();
  /** Sessions are made (and warmed up) one at a time: see policy(). */
  private sessions: Promise<unknown> = Promise.resolve();

  // The display rate, for the HUD.
  private frames = 0;
  private fps = 0;
  private fpsSince = 0;
  private last = 0;

  /** Both dancers in their start pose, drawn until the simulation exists. */
  private readonly still: { leader: DancerView; followers: DancerView[] };

  constructor(
    private readonly manifest: Manifest,
    private readonly fetcher: Fetcher,
    private readonly loading: LoadingBar,
  ) {
    this.defaultTempo = manifestTempo(manifest);
    this.defaults = defaultSettings(manifest.defaultTemperature, this.defaultTempo);
    this.settings = readSettings(location.search, this.defaults);
    this.hasCcm = 'follower_ccm' in manifest.models;
    if (!this.hasCcm) this.settings.model = 'ours';

    // The floor is up while the models download: something to look at, never a blank canvas.
    // Skinned characters unless ?bodies=sticks (the bench compares both); ?skeleton=1 overlays the bones.
    const look = readBodies(location.search);
    bootMark('stage:start');
    this.stage = new Stage(document.getElementById('app')!, manifest.skeleton.parents, MAX_GHOSTS, { ...look, skeleton: this.settings.skeleton, offsets: manifest.skeleton.offsets });
    bootMark('stage:end'); // the renderer and the dancers' bodies: most of the loading scene's own work
    hook.bodies = this.stage.bodies;
    for (const dancer of ['leader', 'follower'] as const) {
      const stage = this.stage;
      Object.defineProperty(hook[dancer], 'screen', { enumerable: true, get: () => stage.screenPoint(dancer) });
      Object.defineProperty(hook[dancer], 'outline', { enumerable: true, get: () => stage.outline(dancer) });
    }
    Object.defineProperty(hook, 'camera', { enumerable: true, get: () => this.stage.getOrbit() });
    Object.defineProperty(hook, 'ghostHips', { enumerable: true, get: () => this.ghostPoses.slice(0, this.settings.ghosts).map((p) => [p[0], p[2]]) });
    if (this.settings.camera) this.stage.setOrbit(this.settings.camera);
    this.still = standingViews(manifest);
    this.leader.capture(this.still.leader, true);
    this.followers[0].capture(this.still.followers[0], true);
    this.snapCamera();
    bootMark('ui:start'); // HUD, controls, panel, recorder: the loading scene waits for these too
    this.hud = new Hud(document.getElementById('overlay')!);
    this.hud.setStatus('loading the dancers…');
    const credit = document.getElementById('credit');
    if (credit) credit.textContent = manifest.credit ?? '';
    // The music starts with the first key press or tap (browsers' autoplay rules): the dance's
    // silent count runs until then, and the band joins it where it is.
    this.music = new Music(this.settings.tempo, this.settings.music, () => this.simulation?.beat ?? 0);
    const startMusic = () => {
      if (this.settings.speed === 1) this.music.gesture();
    };
    window.addEventListener('keydown', startMusic, { capture: true });
    window.addEventListener('pointerdown', startMusic, { capture: true });
    this.count = new CountDisplay(document.getElementById('overlay')!);
    Object.defineProperty(hook, 'music', {
      enumerable: true,
      get: () => ({ state: this.music.state, context: this.music.contextState, scheduled: this.music.scheduled, dropped: this.music.dropped, heard: this.music.heardBeat(), time: this.music.heardTime(), tempo: this.music.playingTempo, problem: this.music.problem }),
    });
    Object.defineProperty(hook, 'beat', { enumerable: true, get: () => this.simulation?.beat ?? 0 });
    Object.defineProperty(hook, 'tempo', { enumerable: true, get: () => this.settings.tempo });
    // Dancers' steps whose sample was chosen on the count (web/mirror/on_count.ts): the tests see it act.
    Object.defineProperty(hook, 'counted', { enumerable: true, get: () => this.simulation?.guards().counted ?? 0 });

    this.controls = new Controls({
      surface: this.stage.canvas,
      viewForward: (out) => this.stage.viewForward(out),
      onPause: () => this.togglePause(),
      onReset: () => this.reset(),
      onTurn: (direction) => this.askTurn(direction),
      onFrame: () => this.resetView(),
    });
    const panel = (this.panel = this.createPanel());
    this.pauseButton = new PauseButton(() => this.togglePause());
    this.turnButtons = new TurnButtons((direction) => this.askTurn(direction));
    // Save a clip of the canvas, and full screen (clip.ts): beside the turn buttons.
    new ClipButton(this.stage.canvas);
    new FullscreenButton();
    hook.askTurn = (direction) => this.askTurn(direction); // tests lead a turn the way T does
    // After a click on a control the keys belong to the dance again (controls.ts).
    releaseFocusAfterUse(document.body);
    this.viewCentre = new ViewCentre(panel.gui.domElement);
    // A drag or a wheel turn moved the camera: the address follows it until it stands still.
    this.stage.controls.addEventListener('end', () => {
      clearTimeout(this.cameraCheck);
      this.cameraStill = 0;
      this.watchCamera();
    });
    this.recorder = new Recorder(MAX_RECORD_FRAMES, () =>
      showToast('Recording stopped', `It reached the ${formatDuration(MAX_RECORD_FRAMES / FPS)} limit. Download the take (“download BVH”).`, 'error', 15_000));
    this.leaderFileInput = new LeaderFileInput({
      notify: showToast,
      onMotion: (motion, name) => this.playLeaderFile(motion, name),
      onAvatar: (file, x, y) => void this.wearAvatar(file, this.stage.nearestDancer(x, y)),
    });
    this.recordPanel = new RecordPanel({
      gui: panel.gui,
      overlay: document.getElementById('overlay')!,
      recorder: this.recorder,
      duet: () => this.simulation?.duet ?? null,
      between: (task) => this.exclusive(task),
      notify: showToast,
      onOpenLeaderFile: () => this.leaderFileInput.open(),
      onLeaderModel: () => this.leaderBackToModel(),
      onOpenAvatar: () => this.avatarInput.click(),
      onPlainBodies: () => this.plainBodies(),
    });
    // The panel's avatar button: a file chooser (phones have no drag and drop).
    this.avatarInput = document.createElement('input');
    this.avatarInput.type = 'file';
    this.avatarInput.accept = '.vrm,.glb';
    this.avatarInput.hidden = true;
    this.avatarInput.setAttribute('aria-label', 'avatar file for the partner');
    this.avatarInput.addEventListener('change', () => {
      const file = this.avatarInput.files?.[0];
      this.avatarInput.value = ''; // choosing the same file again fires 'change' again
      if (file) void this.wearAvatar(file, 'follower');
    });
    document.body.appendChild(this.avatarInput);
    bootMark('ui:end');
  }

  private createPanel(): Panel {
    return new Panel({
      settings: this.settings,
      models: this.hasCcm ? ['ours', 'ccm', 'compare'] : ['ours'],
      onModel: (choice) => this.useModel(choice).catch(this.keepDancingIfUpdated),
      onGhosts: () => this.exclusive(() => this.refreshGhosts()).catch(this.fail),
      onTempo: (bpm) => this.music.setTempo(bpm),
      onMusic: (on) => this.music.setEnabled(on),
      onFigures: (on) => this.exclusive(() => {
        if (this.simulation) this.simulation.ownFigures = on;
      }).catch(this.fail),
      onReset: () => this.reset(),
      onResetView: () => this.resetView(),
      onShare: () => this.share(),
      onSkeleton: this.stage.bodies === 'skinned' ? (on) => (this.stage.skeleton = on) : undefined,
      onSettingsChange: () => this.writeAddress(),
      details: this.hud.details,
      onHelp: (open) => {
        this.helpOpen = hook.helpOpen = open;
        this.music?.hold(this.paused || open);
      },
      facts: helpFacts(this.manifest, this.defaults.temperature),
    });
  }

  /** Run a task after every task queued before it. */
  private exclusive(task: () => Promise<void> | void): Promise<void> {
    const run = this.queue.then(task);
    this.queue = run.catch(() => undefined);
    return run;
  }

  /** A partner this page cannot load since a newer site went up (policy()): say so, and the
   *  partner already dancing dances on. Any other failure is fatal. */
  private readonly keepDancingIfUpdated = (error: unknown): void => {
    if (!(error instanceof SiteUpdatedError && this.simulation)) return this.fail(error);
    showToast(error.title, error.detail, 'error', 15_000);
    this.settings.model = hook.model as FollowerChoice;
    this.panel.refresh();
    this.writeAddress();
  };

  private readonly fail = (error: unknown): void => {
    this.simulation = null; // stop stepping; the overlay explains
    showError(error);
  };

  private status(): string {
    return this.paused ? PAUSED_STATUS : '';
  }

  /** Copy the simulation's views for drawing (snap: no interpolation from the last state). */
  private capture(snap: boolean): void {
    const simulation = this.simulation;
    if (!simulation) return;
    this.leader.capture(simulation.leader, snap);
    for (let i = 0; i < simulation.followers.length; i++) this.followers[i].capture(simulation.followers[i], snap);
    publish(hook.leader, simulation.leader);
    publish(hook.follower, simulation.followers[0]);
    const hands = simulation.leader.hands;
    hook.hold = hands ? Math.max(hands[0], hands[1]) : 0;
    timed = simulation;
    hook.turnAsked = simulation.turnAsked;
    const figure = simulation.figure;
    if (figure !== this.hookedFigure) {
      this.hookedFigure = figure;
      hook.figure = figureHook(figure);
    }
    // Copied into the hook's own pair: no array made per frame.
    const anchor = simulation.anchor;
    hook.anchor ??= [0, 0];
    hook.anchor[0] = anchor[0];
    hook.anchor[1] = anchor[1];
    this.turnButtons.show(simulation.turnAsked);
  }

  /**
   * Ask the leader to lead her turn (T, Shift+T, the turn buttons): on the next beat, or after the
   * figure running, both dancers read it (the figure block: what the joined hands carry), her body
   * and timing are her network's. A leader dancing a file leads nothing, and says so.
   */
  private askTurn(direction: number): boolean {
    const simulation = this.simulation;
    if (!simulation) return false;
    if (!simulation.askTurn(direction)) {
      showToast('The leader dances a file', 'A recorded leader cannot be asked for a turn: choose “leader back to model” first.', 'info', 5000);
      return false;
    }
    this.turnButtons.show(direction);
    return true;
  }

  /** Put the camera between the partners at once. */
  private snapCamera(): void {
    const { leader, followers } = this;
    this.stage.follow(0.5 * (leader.root[2] + followers[0].root[2]), 0.5 * (leader.root[3] + followers[0].root[3]), 0, true);
  }

  /** Both dancers back to the opening pose, and the camera to its first view (R). */
  private reset(): Promise<void> {
    return this.exclusive(() => {
      if (!this.simulation) return;
      this.simulation.reset();
      this.accumulator = 0;
      this.capture(true);
      this.snapCamera();
      this.resetView();
    });
  }

  private resetView(): void {
    this.stage.resetView();
    this.writeAddress();
  }

  private togglePause(): void {
    this.paused = !this.paused;
    this.music.hold(this.paused || this.helpOpen);
    hook.paused = this.paused;
    this.pauseButton.show(this.paused);
    this.hud.setStatus(this.status());
  }

  /** Write the camera's place to the address whenever it moved, until it has stood still a while. */
  private readonly watchCamera = (): void => {
    const place = formatCamera(this.stage.getOrbit());
    if (place !== this.cameraPlace) {
      this.cameraStill = 0;
      this.writeAddress();
    }
    if (++this.cameraStill < CAMERA_STILL_CHECKS) this.cameraCheck = window.setTimeout(this.watchCamera, CAMERA_CHECK_MS);
  };

  /**
   * Write the settings and the camera into the page's address (replaceState: one history entry
   * however many changes), so that the address bar is always a link to this view. The camera only
   * once it was moved from the first view. Returns the address.
   */
  private writeAddress(): string {
    const orbit = this.stage.getOrbit();
    this.cameraPlace = formatCamera(orbit);
    const camera = this.cameraPlace === formatCamera(DEFAULT_ORBIT) ? null : orbit;
    const query = addressQuery(location.search, this.settings, camera, this.defaults.temperature, this.defaultTempo);
    const url = `${location.origin}${location.pathname}?${query}${location.hash}`;
    history.replaceState(history.state, '', url);
    return url;
  }

  /** One model's policy, created once. */
  private policy(name: string): Promise<Policy> {
    let loading = this.policies.get(name);
    if (!loading && siteReplaced()) {
      // The server has a newer site now: its models are not this page's (a mix), so none is
      // fetched; what this page has loaded dances on.
      return Promise.reject(new SiteUpdatedError(name));
    }
    if (!loading) {
      const seed = (this.settings.seed + MODEL_NAMES.indexOf(name) * 0x9e3779b9) >>> 0;
      // The downloads run side by side, the sessions are made one after another: with two made at
      // once (a link with ?model=ccm or compare starts the leader's and the baseline's together)
      // a warm-up run inside onnxruntime-web came back without its outputs ("Cannot read
      // properties of null (reading '3')") on most loads of such a link.
      loading = this.fetcher.model(name).then((bytes) => {
        const created = this.sessions.then(() => bootSpan(`session:${name}`, () => this.createPolicy!(this.manifest, name, bytes, seed)));
        this.sessions = created.catch(() => undefined);
        return created;
      }).then((p) => {
        hook.modelBytes += p.entry.bytes;
        return p;
      });
      this.policies.set(name, loading);
    }
    return loading;
  }

  /** (Re)build the simulation for a follower choice; a new simulation starts from the start pose. */
  private useModel(choice: FollowerChoice): Promise<void> {
    return this.exclusive(async () => {
      this.hud.setStatus('loading the dancers…');
      const [leaderPolicy, ...followerPolicies] = await Promise.all([this.policy('leader'), ...FOLLOWER_MODELS[choice].map((n) => this.policy(n))]);
      this.simulation = this.createSimulation!({
        manifest: this.manifest, leader: leaderPolicy, followers: followerPolicies, seed: this.settings.seed, figures: this.settings.figures,
      });
      this.applyLeaderFile(); // a new simulation keeps the leader's file
      hook.model = choice;
      this.compare.setActive(this.stage, choice === 'compare');
      this.hud.setLegend(choice);
      this.accumulator = 0;
      this.capture(true);
      this.snapCamera();
      this.hud.setStatus(this.status());
    });
  }

  private async refreshGhosts(): Promise<void> {
    const { simulation, settings } = this;
    this.ghostPoses = simulation && settings.ghosts > 0 ? await simulation.ghosts(settings.ghosts) : [];
  }

  /** Write the settings into the address and copy it. */
  private async share(): Promise<void> {
    const url = this.writeAddress();
    if (await copyLink(url)) {
      this.hud.setStatus('link copied');
      setTimeout(() => this.hud.setStatus(this.status()), 2000);
    } else {
      window.prompt('Copy this link:', url);
    }
  }

  private applyLeaderFile(): void {
    this.simulation?.setLeaderPlayback(this.leaderFile?.motion ?? null);
  }

  private playLeaderFile(motion: Motion, name: string): Promise<void> {
    return this.exclusive(() => {
      if (!this.simulation) throw new Error('The dancers are still loading; try again in a moment.');
      this.simulation.setLeaderPlayback(motion); // throws (nothing changed) on a motion it cannot play
      this.leaderFile = { motion, name };
      this.recordPanel.setLeaderFile(name);
    });
  }

  /** Dress `dancer` in a .vrm avatar file (dropped on it, or chosen with the panel's button). */
  private async wearAvatar(file: File, dancer: 'leader' | 'follower'): Promise<void> {
    const name = displayName(file.name);
    try {
      if (this.stage.bodies !== 'skinned') throw new DuetError(`Cannot wear ${name}`, 'Avatars replace the shaded bodies: open the page without ?bodies=sticks.');
      if (file.size > MAX_AVATAR_BYTES) throw new DuetError(`Cannot wear ${name}`, `The file is ${(file.size / 2 ** 20).toFixed(0)} MB; the page reads avatars up to ${MAX_AVATAR_BYTES / 2 ** 20} MB.`);
      const { Avatar, AvatarError } = await import('../draw/avatar');
      const avatar = await Avatar.load(await file.arrayBuffer(), name).catch((error: unknown) => {
        throw error instanceof AvatarError ? new DuetError(`Cannot wear ${name}`, error.message) : error;
      });
      this.stage.dress(dancer, avatar);
      hook.avatars = { ...hook.avatars, [dancer]: { name, get fitDeg() { return avatar.measure().fitDeg; }, get feetCm() { return avatar.measure().feetCm; } } };
      this.recordPanel.setDressed(true);
      showToast(dancer === 'leader' ? `You dance as ${name}` : `Your partner wears ${name}`, '“plain bodies again” in the panel takes it off.', 'info');
    } catch (error) {
      if (error instanceof DuetError) showToast(error.title, error.detail, 'error');
      else showToast(`Cannot wear ${name}`, error instanceof Error ? error.message : String(error), 'error');
    }
  }

  private plainBodies(): void {
    this.stage.dress('leader', null);
    this.stage.dress('follower', null);
    hook.avatars = {};
    this.recordPanel.setDressed(false);
  }

  private leaderBackToModel(): void {
    this.exclusive(() => {
      this.leaderFile = null;
      this.applyLeaderFile();
      this.recordPanel.setLeaderFile(null);
    }).catch(this.fail);
  }

  /** Run the steps that real time asks for; called from the animation loop, one call at a time. */
  private async advance(): Promise<void> {
    const began = performance.now();
    let steps = 0;
    while (this.simulation && this.accumulator >= DT) {
      // The count this step is on: while the music plays, what the listener hears now, less the
      // steps still owed after this one (the backlog is dance time not yet shown).
      const tempo = this.settings.tempo;
      const heard = this.music.heardBeat();
      this.simulation.setCount(heard === null ? null : heard - ((this.accumulator - DT) * tempo) / 60, tempo);
      hook.countAt = performance.now();
      await this.simulation.step(this.controls.getSteer(), this.settings.temperature);
      this.accumulator -= DT;
      steps++;
      this.capture(false);
      // The possible reactions dance on one step per step (simulation.ts ghosts()).
      if (this.settings.ghosts > 0) await this.refreshGhosts();
      const duet = this.simulation?.duet;
      if (this.recorder.recording && duet) this.recorder.capture(duet);
      hook.frame++;
      hook.ready = true;
      if (!('first-step' in bootTimings)) {
        bootMark('first-step');
        break; // the first dancing frame goes on screen now, not after the backlog's steps
      }
      // Draw between steps when stepping is slow (software rendering, big models, high speed).
      if (performance.now() - began > Math.max(MIN_STEP_BUDGET_MS, this.drawMs)) break;
    }
    if (steps > 0) this.recordPanel.update();
    if (steps > 0 && this.simulation) this.count.show(this.simulation.beat, this.simulation.figure);
    this.steppedMs += performance.now() - began;
  }

  /** Start the animation loop. */
  startLoop(): void {
    this.fpsSince = performance.now();
    this.last = performance.now();
    // The standing pair at once, not a frame later: the loading scene's moment for the bench.
    this.draw(0, 0);
    bootMark('scene');
    afterPaint((at) => {
      hook.sceneMs = at;
      bootMark('scene-painted', at);
      // index.html's picture of this scene covered the canvas until now: the live one is on
      // screen under it with the same pixels, so taking it away changes nothing a visitor sees
      // (except on a shared link whose camera or bodies differ from the picture's).
      document.getElementById('poster')?.remove();
    }, false);
    // While the models are still coming (a moment after the loading scene is on screen): when
    // they are in already (a repeat visit), starting them and the first step come first.
    setTimeout(() => {
      if (this.simulation || this.fetcher.done) return;
      bootMark('warmup:start');
      this.stage.warmUp();
      bootMark('warmup:end');
    }, WARM_UP_DELAY_MS);
    requestAnimationFrame(this.frame);
    // Browsers stop animation frames in hidden tabs: start timing afresh when the tab comes back.
    document.addEventListener('visibilitychange', () => {
      this.last = performance.now();
    });
  }

  /** The steps real time asks for, as a task of their own (frame() queues it, one at a time). */
  private readonly runSteps = (): void => {
    this.exclusive(() => this.advance())
      .catch(this.fail)
      .finally(() => (this.stepping = false));
  };

  private readonly frame = (now: number): void => {
    requestAnimationFrame(this.frame);
    const elapsed = Math.min(Math.max(0, now - this.last) / 1000, MAX_FRAME_SECONDS);
    this.drawMs += 0.2 * (Math.max(0, elapsed * 1000 - this.steppedMs) - this.drawMs);
    this.steppedMs = 0;
    this.last = now;
    this.countFrame(now);

    // A device that cannot keep up runs the dance in slow motion rather than piling up work.
    const { settings } = this;
    if (this.simulation && !this.paused && !this.helpOpen) this.accumulator = Math.min(this.accumulator + elapsed * settings.speed, MAX_BACKLOG_SECONDS * settings.speed);
    if (this.simulation && !this.stepping && this.accumulator >= DT) {
      this.stepping = true;
      // The steps run in a task of their own, after this frame is on screen. Started from here
      // they would be microtasks of this callback (onnxruntime's run resolves at once), and the
      // browser would paint the frame drawn below only after them: a frame's worth of steps
      // (at least MIN_STEP_BUDGET_MS) later than it could.
      setTimeout(this.runSteps, 0);
    }

    // While the models load (or after an error) nothing moves but the camera: redraw only when
    // the picture would change, and leave the main thread to the downloads and to starting the
    // models (in the phone bench, at 4x CPU, each redraw of the standing pair was a 0.2-0.5 s
    // task, and they took most of the main thread while loading). The same until the first step
    // of the first dance is in: a draw of the not yet moving pair would only delay that step.
    const dancing = this.dancing;
    if (!dancing) this.viewCentre.loadingUpdate(this.stage);
    if (dancing || this.stage.needsRender()) this.draw(Math.min(1, this.accumulator / DT), elapsed);
    const guards = this.simulation ? this.simulation.guards() : NO_GUARDS;
    this.hud.update(now, { stepMs: hook.stepMs, fps: this.fps, threads: hook.threads, modelBytes: hook.modelBytes, guards });
  };

  private countFrame(now: number): void {
    this.frames++;
    if (now - this.fpsSince >= 500) {
      this.fps = (this.frames * 1000) / (now - this.fpsSince);
      this.frames = 0;
      this.fpsSince = now;
    }
  }

  /** Whether the first dance has its first step in (before: the loading scene). */
  private get dancing(): boolean {
    return this.simulation !== null && hook.frame > 0;
  }

  private draw(alpha: number, elapsed: number): void {
    const { stage, simulation, leader, followers } = this;
    // Until the models are in, the pair stands still in the start pose (this.still).
    const count = simulation ? simulation.followers.length : 1;
    stage.leader.setCount(1);
    const leaderPose = leader.interpolate(alpha), leaderRotations = leader.interpolateRotations(alpha);
    stage.leader.setPose(0, leaderPose, leaderRotations, leader.contacts);
    // Hand glows: dancer 0 is the leader, 1 and 2 the followers (Stage.setHandContact).
    for (let h = 0; h < 2; h++) {
      stage.setHandContact(0, h, simulation ? leader.hands[h] : 0);
      for (let i = 0; i < stage.followers.length; i++) stage.setHandContact(i + 1, h, i < count ? followers[i].hands[h] : 0);
    }
    const compare = this.compare;
    compare.update(stage);
    if (this.dancing) this.viewCentre.update(stage);
    else this.viewCentre.loadingUpdate(stage);
    for (let i = 0; i < stage.followers.length; i++) {
      stage.followers[i].setCount(i < count ? 1 : 0);
      if (i < count) {
        const pose = followers[i].interpolate(alpha);
        stage.followers[i].setPose(0, i > 0 ? compare.shiftPoints(pose, i) : pose, followers[i].interpolateRotations(alpha), followers[i].contacts);
      }
    }
    const copy = compare.active && count > 1;
    stage.leaderCopy.setCount(copy ? 1 : 0);
    if (copy) stage.leaderCopy.setPose(0, compare.shiftPoints(leaderPose, 0), leaderRotations, leader.contacts);
    this.drawOverlays(alpha, count);
    const midX = 0.5 * (leader.rootX(alpha) + followers[0].rootX(alpha)), midZ = 0.5 * (leader.rootZ(alpha) + followers[0].rootZ(alpha));
    // In compare mode the camera looks between the two pairs.
    if (simulation) stage.follow(midX + 0.5 * compare.offset.x, midZ + 0.5 * compare.offset.z, elapsed);
    compare.placeLabels(stage, midX, midZ, this.viewCentre.freeWidth);
    stage.render();
    hook.drawn = (hook.drawn ?? 0) + 1;
    hook.afterDraw?.();
    if (hook.frame > 0 && !('first-drawn' in bootTimings)) {
      bootMark('first-drawn');
      afterPaint((at) => {
        hook.firstFrameMs = at;
        bootMark('first-painted', at);
      }, true);
    }
  }

  /** The leader's and each follower's future root path; the followers' intentions; the ghosts. */
  private drawOverlays(alpha: number, count: number): void {
    const { stage, settings, leader, followers } = this;
    for (let i = 0; i < stage.trajectories.length; i++) {
      const overlay = stage.trajectories[i];
      const track = i === 0 ? leader : followers[i - 1];
      overlay.group.visible = settings.trajectories && this.simulation !== null && i <= count;
      // The compare follower's path moves with it (compare.ts).
      const dx = i > 1 ? this.compare.offset.x : 0, dz = i > 1 ? this.compare.offset.z : 0;
      if (overlay.group.visible) overlay.setFloorPath(track.rootX(alpha) + dx, track.rootZ(alpha) + dz, i > 1 ? this.compare.shiftFloor(track.future, i) : track.future);
    }
    for (let i = 0; i < stage.intentions.length; i++) {
      const overlay = stage.intentions[i];
      overlay.group.visible = settings.intentions && i < count && followers[i].hasIntention;
      if (overlay.group.visible) overlay.setKeyMajorPoints(i > 0 ? this.compare.shiftPoints(followers[i].intention, 10 + i) : followers[i].intention, KEYS, N_KEY_JOINTS);
    }
    const ghosts = settings.ghosts > 0 ? Math.min(this.ghostPoses.length, settings.ghosts) : 0;
    stage.ghosts.setCount(ghosts);
    for (let i = 0; i < ghosts; i++) stage.ghosts.setPose(i, this.ghostPoses[i]);
  }

  /** The runtime is in: make the policies and the simulation, and start dancing. */
  async attach([ortModule, policyModule, simulationModule]: Runtime, wasm: WebAssembly.Module): Promise<void> {
    bootMark('attach');
    this.loading.compiling();
    hook.threads = ortModule.configureThreads(this.settings.threads, wasm);
    this.createPolicy = policyModule.createPolicy;
    this.createSimulation = simulationModule.createSimulation;
    await this.useModel(this.settings.model);
    this.loading.hide();
    const since = (epoch: number) => epoch - performance.timeOrigin;
    hook.workerFiles = this.fetcher.files.map((f) => ({ ...f, start: since(f.start), firstByte: since(f.firstByte), end: since(f.end) }));
    // The worker's downloads are not in this page's resource timing: name them. A new version's
    // worker takes over with this message, now that onnxruntime has started (offline.ts).
    keepForOffline(hook.version ?? assetVersion(this.manifest), [this.fetcher.scriptUrl.href, ...this.fetcher.files.map((file) => file.url)]);
  }
}

async function start(): Promise<void> {
  checkBrowserSupport();
  // Progress is a new boot stage (the fetcher worker's included) or more bytes downloaded.
  const watchdog = new BootWatchdog(() => `${Object.keys(bootTimings).length} ${hook.download?.loaded ?? 0}`, stalled);
  watchdog.start();
  try {
    await boot();
  } finally {
    watchdog.stop();
  }
  if (!restarting()) clearRestarts();
}

async function boot(): Promise<void> {
  // Start every download at once: the fetcher worker downloads onnxruntime's wasm (compiling it),
  // the manifest and the first dance's models by itself; onnxruntime's and the simulation's code
  // now; the floor is drawn meanwhile.
  const fetcher = new Fetcher();
  const runtime = loadRuntime();
  const loading = new LoadingBar();
  fetcher.onProgress = (loaded, total, sized) => {
    hook.download = { loaded, total, sized };
    loading.update(loaded, total, sized);
  };
  const manifest = await bootSpan('manifest', () => loadManifest());
  hook.version = assetVersion(manifest);
  hook.modelsVersion = modelsVersion(manifest);
  hook.buildVersion = BUILD_MODELS;
  const other = otherDeployment(manifest);
  if (other) {
    // This page is of one deployment and the manifest of another (the site changed between the
    // two requests, or the page came from a cache): never dance that mix.
    if (takeRestart()) return restart('The site was being updated as this page loaded: starting again.');
    throw new DuetError('duet is being updated', other);
  }
  registerOffline(hook.version, siteUpdated);
  // Building the page is one long task, and a worker only gets going once this thread has taken
  // note of its start: let it start first (it usually has; at most WORKER_START_WAIT_MS of the
  // loading scene's time), or its downloads wait for the whole task.
  await Promise.race([fetcher.started, new Promise((resolve) => setTimeout(resolve, WORKER_START_WAIT_MS))]);
  const page = new Page(manifest, fetcher, loading);
  page.startLoop();
  const [modules, wasmModule] = await Promise.all([runtime, fetcher.wasm]);
  await page.attach(modules, wasmModule);
}

start().catch((error) => {
  clearRestarts();
  showError(error);
});
