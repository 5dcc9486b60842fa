// Recording the duet and saving it as BVH: one file per dancer (duet-leader-<time>.bvh and
// duet-follower-<time>.bvh), written by bvhwriter.ts.
//
// Every simulation step appends the leader's and the (first) follower's current frame: the hip
// position and the world rotations of the rollout Track, not the foot-IK'd drawn positions, so FK
// on the file reproduces the model's skeleton exactly. Frames are turned into BVH channel values
// as they arrive (54 numbers per dancer and frame, in chunks), so ten minutes take ~16 MB.
//
// Stopping keeps the take; "download" saves what was recorded so far, also while recording (which
// goes on). At MAX_RECORD_FRAMES the recording stops and says so; no frame is ever dropped silently.

import type GUI from 'lil-gui';
import type { Controller } from 'lil-gui';
import { HISTORY } from './features';
import { CHANNELS_PER_FRAME, frameChannels, writeBvh } from './bvhwriter';
import { FPS } from './skeleton';

/** 10 minutes at 30 fps. */
export const MAX_RECORD_FRAMES = 10 * 60 * FPS;
/** The current frame of a rollout Track (rollout.ts NOW). */
const NOW = HISTORY;
const CHUNK_FRAMES = 900; // 30 s per chunk

/** What the recorder reads of a rollout.ts Dancer. */
export interface RecordableDancer {
  /** [17 × 3] metres. */
  readonly offsets: ArrayLike<number>;
  readonly track: { readonly positions: ArrayLike<number>; readonly rotations: ArrayLike<number> };
}

/** What the recorder reads of a rollout.ts Duet (simulation.ts DuetSimulation.duet). */
export interface RecordableDuet {
  readonly leader: RecordableDancer;
  readonly followers: readonly RecordableDancer[];
}

/** Channel values of one dancer, chunk by chunk. */
class DancerTake {
  readonly offsets: Float64Array;
  private readonly chunks: Float64Array[] = [];
  frames = 0;

  constructor(offsets: ArrayLike<number>) {
    this.offsets = Float64Array.from(offsets);
  }

  append(dancer: RecordableDancer): void {
    const f = this.frames;
    const chunk = Math.floor(f / CHUNK_FRAMES);
    if (chunk === this.chunks.length) this.chunks.push(new Float64Array(CHUNK_FRAMES * CHANNELS_PER_FRAME));
    const at = (f % CHUNK_FRAMES) * CHANNELS_PER_FRAME;
    // The previous frame's angles (for continuous curves) may sit at the end of the last chunk.
    let previous: Float64Array | null = null;
    let prevAt = 0;
    if (f > 0) {
      previous = this.chunks[Math.floor((f - 1) / CHUNK_FRAMES)];
      prevAt = ((f - 1) % CHUNK_FRAMES) * CHANNELS_PER_FRAME;
    }
    const t = dancer.track;
    frameChannels(t.positions, NOW * 51, t.rotations, NOW * 153, this.chunks[chunk], at, previous, prevAt);
    this.frames++;
  }

  /** The first `frames` frames as one BVH file. */
  bvh(frames = this.frames): string {
    const channels = new Float64Array(frames * CHANNELS_PER_FRAME);
    for (let c = 0; c * CHUNK_FRAMES < frames; c++) {
      const count = Math.min(CHUNK_FRAMES, frames - c * CHUNK_FRAMES);
      channels.set(this.chunks[c].subarray(0, count * CHANNELS_PER_FRAME), c * CHUNK_FRAMES * CHANNELS_PER_FRAME);
    }
    return writeBvh({ offsets: this.offsets, frames, channels, fps: FPS });
  }
}

export class Recorder {
  recording = false;
  /** The recording stopped because it reached maxFrames. */
  full = false;
  /** The current take has been saved since its last frame. */
  saved = true;
  private leader: DancerTake | null = null;
  private follower: DancerTake | null = null;

  constructor(
    readonly maxFrames = MAX_RECORD_FRAMES,
    /** Called once when the recording stops at maxFrames. */
    private readonly onFull: () => void = () => undefined,
  ) {
    if (!(maxFrames >= 1)) throw new RangeError('maxFrames must be at least 1');
  }

  /** Frames in the current take. */
  get frames(): number {
    return this.leader?.frames ?? 0;
  }

  get seconds(): number {
    return this.frames / FPS;
  }

  /** A new take, starting with the dancers' current frame. */
  start(duet: RecordableDuet): void {
    this.leader = new DancerTake(duet.leader.offsets);
    this.follower = new DancerTake(duet.followers[0].offsets);
    this.recording = true;
    this.full = false;
    this.saved = false;
    this.append(duet);
  }

  /** Stop appending; the take stays until the next start(). */
  stop(): void {
    this.recording = false;
  }

  /** After every simulation step: append the current frame while recording. */
  capture(duet: RecordableDuet): void {
    if (this.recording) this.append(duet);
  }

  /** Both dancers' BVH files of everything recorded so far (null when nothing was). */
  export(): { leader: string; follower: string; frames: number } | null {
    const frames = this.frames;
    if (!this.leader || !this.follower || frames === 0) return null;
    const files = { leader: this.leader.bvh(frames), follower: this.follower.bvh(frames), frames };
    this.saved = true;
    return files;
  }

  private append(duet: RecordableDuet): void {
    if (this.frames >= this.maxFrames) return;
    this.leader!.append(duet.leader);
    this.follower!.append(duet.followers[0]);
    this.saved = false;
    if (this.frames >= this.maxFrames) {
      this.recording = false;
      this.full = true;
      this.onFull();
    }
  }
}

/** "20250131-154501" in local time. */
export function timestamp(date = new Date()): string {
  const two = (n: number) => String(n).padStart(2, '0');
  return `${date.getFullYear()}${two(date.getMonth() + 1)}${two(date.getDate())}-${two(date.getHours())}${two(date.getMinutes())}${two(date.getSeconds())}`;
}

/** "1:02.5" */
export function formatDuration(seconds: number): string {
  const minutes = Math.floor(seconds / 60);
  return `${minutes}:${(seconds - 60 * minutes).toFixed(1).padStart(4, '0')}`;
}

/** Save text as a file through a temporary link (no server involved). */
export function downloadText(name: string, text: string, type = 'text/plain'): void {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const link = document.createElement('a');
  link.href = url;
  link.download = name;
  link.style.display = 'none';
  document.body.appendChild(link);
  link.click();
  link.remove();
  // Revoking at once can cancel the download in some browsers.
  setTimeout(() => URL.revokeObjectURL(url), 60_000);
}

// =================================================================================================
// The panel folder and the recording indicator.

export interface RecordPanelOptions {
  gui: GUI;
  /** Where the "● REC 0:12.3" line goes (the HUD overlay). */
  overlay: HTMLElement;
  recorder: Recorder;
  /** The running duet, or null while models load. */
  duet(): RecordableDuet | null;
  /** Run a task between simulation steps (main.ts's exclusive queue). */
  between(task: () => void): Promise<void>;
  /** A short message for people (dropzone.ts showToast). */
  notify(title: string, detail: string, kind: 'info' | 'error'): void;
  onOpenLeaderFile(): void;
  onLeaderModel(): void;
}

export class RecordPanel {
  private readonly folder: GUI;
  private readonly recordButton: Controller;
  private readonly modelButton: Controller;
  private readonly indicator: HTMLElement;
  private leaderFile: string | null = null;
  private lastText = '';
  private lastLabel = '';

  constructor(private readonly options: RecordPanelOptions) {
    const { gui } = options;
    this.folder = gui.addFolder('record · leader file');
    const actions = {
      record: () => this.toggle(),
      download: () => this.download(),
      open: () => options.onOpenLeaderFile(),
      model: () => options.onLeaderModel(),
    };
    this.recordButton = this.folder.add(actions, 'record');
    this.folder.add(actions, 'download').name('download BVH (leader + follower)');
    this.folder.add(actions, 'open').name('leader from BVH file…');
    this.modelButton = this.folder.add(actions, 'model').name('leader back to model').disable();
    this.indicator = document.createElement('div');
    this.indicator.className = 'record-status';
    this.indicator.hidden = true;
    options.overlay.appendChild(this.indicator);
    this.update();
  }

  /** The leader dances a file (its name) or the model (null). */
  setLeaderFile(name: string | null): void {
    this.leaderFile = name;
    this.modelButton.enable(name !== null);
    this.update();
  }

  /** Refresh the button label and the indicator (cheap; call after steps). */
  update(): void {
    const { recorder } = this.options;
    const label = recorder.recording ? '■ stop recording' : '● record';
    if (label !== this.lastLabel) this.recordButton.name((this.lastLabel = label));
    const lines: string[] = [];
    if (recorder.recording) lines.push(`● REC ${formatDuration(recorder.seconds)}`);
    else if (recorder.full) lines.push(`recording stopped at the ${formatDuration(recorder.seconds)} limit — download it`);
    else if (recorder.frames > 0 && !recorder.saved) lines.push(`take ${formatDuration(recorder.seconds)} not downloaded yet`);
    if (this.leaderFile) lines.push(`leader dances ${this.leaderFile}`);
    const text = lines.join('\n');
    if (text === this.lastText) return;
    this.lastText = text;
    this.indicator.textContent = text;
    this.indicator.hidden = text === '';
    this.indicator.classList.toggle('recording', recorder.recording);
  }

  toggle(): void {
    const { recorder, notify } = this.options;
    if (recorder.recording) {
      recorder.stop();
      notify('Recording stopped', `${formatDuration(recorder.seconds)} recorded — “download BVH” saves it.`, 'info');
      this.update();
      return;
    }
    const duet = this.options.duet();
    if (!duet) {
      notify('Not yet', 'The dancers are still loading; record once they move.', 'error');
      return;
    }
    if (recorder.frames > 0 && !recorder.saved &&
      !window.confirm(`Start a new take? The last one (${formatDuration(recorder.seconds)}) was not downloaded and will be lost.`)) {
      return;
    }
    this.options.between(() => {
      const current = this.options.duet();
      if (current) recorder.start(current);
      this.update();
    }).catch((error) => notify('Could not record', String((error as Error)?.message ?? error), 'error'));
  }

  download(): void {
    const { recorder, notify } = this.options;
    let files: ReturnType<Recorder['export']>;
    try {
      files = recorder.export();
    } catch (error) {
      notify('Could not write the BVH files', String((error as Error)?.message ?? error), 'error');
      return;
    }
    if (!files) {
      notify('Nothing recorded yet', 'Press “● record”, dance a little, then download.', 'error');
      return;
    }
    const stamp = timestamp();
    downloadText(`duet-leader-${stamp}.bvh`, files.leader);
    downloadText(`duet-follower-${stamp}.bvh`, files.follower);
    notify('BVH saved', `${files.frames} frames (${formatDuration(files.frames / FPS)}) per dancer: duet-leader-${stamp}.bvh and duet-follower-${stamp}.bvh.`, 'info');
    this.update();
  }
}
