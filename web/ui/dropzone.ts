// The leader from a BVH file: a file button (through the panel) and drag-and-drop anywhere on the
// page. The file is read with motionFromBvhText (web/mirror/skeleton.ts) and handed to main.ts, which puts
// it on the simulation (setLeaderPlayback). Anything that cannot be danced -- not a BVH, an empty
// or broken one, another skeleton, a frame rate that is not a multiple of 30 -- becomes a toast:
// a short visible message that goes away by itself. The page keeps running; window.duet.error is
// for fatal errors only and stays untouched.

import { BvhError } from '../mirror/bvh';
import { DuetError } from './errors';
import { FPS, JOINT_NAMES, type Motion, motionFromBvhText } from '../mirror/skeleton';
import { type ToastKind, showToast } from './toast';

/** Bigger files are refused before reading (a 10-minute 120 fps take is ~30 MB). */
export const MAX_BVH_BYTES = 64 * 1024 * 1024;
/** The same for avatars (web/draw/avatar.ts), which the page reads into memory whole. */
export const MAX_AVATAR_BYTES = 100 * 1024 * 1024;
/** Plausible standing height of a dancer, metres (foot to head along the bones). */
const HEIGHT_RANGE: [number, number] = [0.5, 4];
const NAME_LENGTH = 60;

// =================================================================================================
// Reading a leader file

/** A file name fit for a message: no control characters, not endless. */
export function displayName(name: string): string {
  const clean = name.replace(/[\u0000-\u001f\u007f]/g, '').trim() || 'the file';
  return clean.length > NAME_LENGTH ? `${clean.slice(0, NAME_LENGTH - 1)}…` : clean;
}

/** Foot-to-head length along the bones (metres): the reduced offsets of hip → lFoot and hip → head. */
function boneHeight(offsets: Float64Array): number {
  const length = (j: number) => Math.hypot(offsets[3 * j], offsets[3 * j + 1], offsets[3 * j + 2]);
  const chain = (names: string[]) => names.reduce((sum, n) => sum + length(JOINT_NAMES.indexOf(n as (typeof JOINT_NAMES)[number])), 0);
  return chain(['abdomen', 'chest', 'neck', 'head']) + chain(['lThigh', 'lShin', 'lFoot']);
}

/**
 * A BVH text as a leader motion (30 fps, metres), or a DuetError whose title and detail say what is
 * wrong with the file in words a dancer understands.
 */
export function leaderMotionFromText(text: string, fileName: string): Motion {
  const name = displayName(fileName);
  const title = `Cannot dance ${name}`;
  if (text.trim() === '') throw new DuetError(title, 'The file is empty. Choose a BVH motion capture file.');
  if (!text.trimStart().startsWith('HIERARCHY')) {
    throw new DuetError(title, 'This is not a BVH file (a BVH starts with HIERARCHY). Choose a .bvh motion capture file.');
  }
  let motion: Motion;
  try {
    motion = motionFromBvhText(text, name);
  } catch (error) {
    const message = error instanceof Error ? error.message : String(error);
    if (error instanceof BvhError && /lacks joint/.test(message)) {
      throw new DuetError(title, `${message}. The leader needs the 17-joint dancer skeleton (${JOINT_NAMES.join(', ')}).`);
    }
    if (error instanceof BvhError && /resample/.test(message)) {
      throw new DuetError(title, `${message}. Use a BVH at 30, 60 or 120 frames per second.`);
    }
    throw new DuetError(title, message);
  }
  if (motion.frames < 2) throw new DuetError(title, `The motion has ${motion.frames} frame at 30 fps; the leader needs at least 2.`);
  for (let i = 0; i < motion.positions.length; i++) {
    if (!Number.isFinite(motion.positions[i])) throw new DuetError(title, 'The motion holds numbers that are not finite (NaN or infinity).');
  }
  const height = boneHeight(motion.offsets);
  if (!(height >= HEIGHT_RANGE[0] && height <= HEIGHT_RANGE[1])) {
    throw new DuetError(title, `The skeleton is ${height.toPrecision(3)} m from foot to head; expected a dancer of ` +
      `${HEIGHT_RANGE[0]}–${HEIGHT_RANGE[1]} m (units as in the CMU dance BVH files).`);
  }
  return motion;
}

/** Read a dropped or chosen file as a leader motion; a DuetError says why not. */
export async function readLeaderFile(file: File): Promise<Motion> {
  const name = displayName(file.name);
  if (file.size === 0) throw new DuetError(`Cannot dance ${name}`, 'The file is empty. Choose a BVH motion capture file.');
  if (file.size > MAX_BVH_BYTES) {
    throw new DuetError(`Cannot dance ${name}`, `The file is ${(file.size / 2 ** 20).toFixed(0)} MB; the page reads BVH files up to ${MAX_BVH_BYTES / 2 ** 20} MB.`);
  }
  let text: string;
  try {
    text = await file.text();
  } catch (error) {
    throw new DuetError(`Cannot read ${name}`, (error as Error)?.message || 'The browser could not read the file.');
  }
  return leaderMotionFromText(text, file.name);
}

// =================================================================================================
// The file button and drag-and-drop

export interface LeaderFileOptions {
  /** Put the motion on the leader; may throw (then the message is shown). */
  onMotion(motion: Motion, name: string): void | Promise<void>;
  /** A .vrm avatar dropped at a point of the page (client pixels); shows its own messages. */
  onAvatar?(file: File, clientX: number, clientY: number): void;
  notify?: (title: string, detail: string, kind: ToastKind) => void;
}

export class LeaderFileInput {
  readonly input: HTMLInputElement;
  private readonly hint: HTMLElement;
  private readonly notify: (title: string, detail: string, kind: ToastKind) => void;
  private dragDepth = 0;

  constructor(private readonly options: LeaderFileOptions) {
    this.notify = options.notify ?? ((title, detail, kind) => void showToast(title, detail, kind));
    this.input = document.createElement('input');
    this.input.type = 'file';
    this.input.accept = '.bvh,.BVH';
    this.input.className = 'leader-file';
    this.input.setAttribute('aria-label', 'leader BVH file');
    this.input.addEventListener('change', () => {
      const file = this.input.files?.[0];
      this.input.value = ''; // choosing the same file again fires 'change' again
      if (file) void this.load(file);
    });
    document.body.appendChild(this.input);

    this.hint = document.createElement('div');
    this.hint.className = 'drop-hint';
    this.hint.hidden = true;
    this.hint.textContent = 'Drop a .bvh file: the leader will dance it · a .vrm avatar on a dancer: it wears it';
    document.body.appendChild(this.hint);

    const carriesFiles = (event: DragEvent) => !!event.dataTransfer && Array.from(event.dataTransfer.types).includes('Files');
    window.addEventListener('dragenter', (event) => {
      if (!carriesFiles(event)) return;
      event.preventDefault();
      this.dragDepth++;
      this.hint.hidden = false;
    });
    window.addEventListener('dragover', (event) => {
      if (!carriesFiles(event)) return;
      // Without this the browser would open the file in place of the page.
      event.preventDefault();
      event.dataTransfer!.dropEffect = 'copy';
    });
    window.addEventListener('dragleave', (event) => {
      if (!carriesFiles(event)) return;
      this.dragDepth = Math.max(0, this.dragDepth - 1);
      if (this.dragDepth === 0) this.hint.hidden = true;
    });
    window.addEventListener('drop', (event) => {
      this.dragDepth = 0;
      this.hint.hidden = true;
      if (!event.dataTransfer) return;
      event.preventDefault();
      const files = Array.from(event.dataTransfer.files);
      if (files.length === 0) {
        this.notify('Nothing to dance', 'Drop a .bvh motion capture file on the page.', 'error');
        return;
      }
      const file = files.find((f) => /\.bvh$/i.test(f.name)) ?? files[0];
      if (/\.(vrm|glb)$/i.test(file.name) && this.options.onAvatar) this.options.onAvatar(file, event.clientX, event.clientY);
      else void this.load(file);
    });
  }

  /** Open the browser's file chooser. */
  open(): void {
    this.input.click();
  }

  /** Read a file and hand it to the leader; every failure is a message. */
  async load(file: File): Promise<void> {
    try {
      const motion = await readLeaderFile(file);
      await this.options.onMotion(motion, displayName(file.name));
      this.notify('The leader dances a file', `${displayName(file.name)}: ${(motion.frames / FPS).toFixed(1)} s, looping. “leader back to model” ends it.`, 'info');
    } catch (error) {
      if (error instanceof DuetError) this.notify(error.title, error.detail, 'error');
      else this.notify(`Cannot dance ${displayName(file.name)}`, error instanceof Error ? error.message : String(error), 'error');
    }
  }
}
