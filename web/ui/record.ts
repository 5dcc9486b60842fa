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
// The panel folder and the recording indicator are recordpanel.ts.

import { CHANNELS_PER_FRAME, frameChannels, writeBvh } from './bvhwriter';
import { FPS, POSITIONS_SIZE, ROTATIONS_SIZE } from '../mirror/skeleton';
import { NOW } from '../mirror/rollout';

/** 10 minutes at 30 fps. */
export const MAX_RECORD_FRAMES = 10 * 60 * FPS;
const CHUNK_FRAMES = 30 * FPS; // 30 s per chunk

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
    frameChannels(t.positions, NOW * POSITIONS_SIZE, t.rotations, NOW * ROTATIONS_SIZE, this.chunks[chunk], at, previous, prevAt);
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
