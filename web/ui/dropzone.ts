// The leader from a BVH file: a file button (through the panel) and drag-and-drop anywhere on the
// page. The file is read and checked by leaderMotionFromText (web/ui/leaderfile.ts: the one place
// that says whether a file is a dance), in a worker so a big file does not stop the dance, and handed
// to main.ts, which puts it on the simulation (setLeaderPlayback). Anything that cannot be danced --
// not a BVH, an empty or broken one, another skeleton, a frame rate that is not a multiple of 30,
// numbers no dancer could have recorded -- becomes a toast: a short visible message that goes away
// by itself. The page keeps running; window.duet.error is for fatal errors only and stays untouched.

import { DuetError } from './errors';
import { FPS, type Motion } from '../mirror/skeleton';
import { displayName, leaderMotionFromText } from './leaderfile';
import { type ToastKind, showToast } from './toast';

export { displayName, leaderMotionFromText };

/** Bigger files are refused before reading (a 10-minute 120 fps take is ~30 MB). */
export const MAX_BVH_BYTES = 64 * 1024 * 1024;
/** The same for avatars (web/draw/avatar.ts), which the page reads into memory whole. */
export const MAX_AVATAR_BYTES = 100 * 1024 * 1024;

// =================================================================================================
// Reading a leader file

/** What leaderfile.worker.ts answers to a File: the motion, or the message saying why not. */
export type FromLeaderWorker = { motion: Motion; error?: undefined } | { motion?: undefined; error: { title: string; detail: string } };

/** The worker did not start (its script did not load): the page reads the file itself. */
class NoWorker extends Error {}

/** Read, check and reduce the file in a worker; rejects with a DuetError, or NoWorker. */
function readInWorker(file: File): Promise<Motion> {
  return new Promise((resolve, reject) => {
    let worker: Worker;
    try {
      worker = new Worker(new URL('./leaderfile.worker.ts', import.meta.url), { type: 'module', name: 'duet leader file' });
    } catch (error) {
      reject(new NoWorker(String(error)));
      return;
    }
    worker.onmessage = (event: MessageEvent<FromLeaderWorker>) => {
      worker.terminate();
      const { motion, error } = event.data;
      if (motion) resolve(motion);
      else reject(new DuetError(error!.title, error!.detail));
    };
    worker.onerror = (event) => {
      event.preventDefault();
      worker.terminate();
      reject(new NoWorker(event.message || 'the leader file worker did not start'));
    };
    worker.postMessage(file);
  });
}

/** Read a dropped or chosen file as a leader motion; a DuetError says why not. */
export async function readLeaderFile(file: File): Promise<Motion> {
  const name = displayName(file.name);
  if (file.size === 0) throw new DuetError(`Cannot dance ${name}`, 'The file is empty. Choose a BVH motion capture file.');
  if (file.size > MAX_BVH_BYTES) {
    throw new DuetError(`Cannot dance ${name}`, `The file is ${(file.size / 2 ** 20).toFixed(0)} MB; the page reads BVH files up to ${MAX_BVH_BYTES / 2 ** 20} MB.`);
  }
  if (typeof Worker === 'function') {
    try {
      return await readInWorker(file);
    } catch (error) {
      if (!(error instanceof NoWorker)) throw error;
      // e.g. offline, before the worker's script was ever kept by the service worker: read it here.
    }
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
