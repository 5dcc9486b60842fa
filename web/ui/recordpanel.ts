// The panel's "record · leader file" folder and the "● REC 0:12.3" indicator: buttons that drive
// the Recorder (record.ts) and hand leader-file requests to main.ts.

import type GUI from 'lil-gui';
import type { Controller } from 'lil-gui';
import { type RecordableDuet, type Recorder, formatDuration, timestamp } from './record';
import { downloadText } from './download';
import { FPS } from '../mirror/skeleton';
import { CONTROLS } from './panel';

export interface RecordPanelOptions {
  gui: GUI;
  /** Where the "● REC 0:12.3" line goes (the HUD overlay). */
  overlay: HTMLElement;
  recorder: Recorder;
  /** The running duet, or null while models load. */
  duet(): RecordableDuet | null;
  /** Run a task between simulation steps (main.ts's exclusive queue). */
  between(task: () => void): Promise<void>;
  /** A short message for people (toast.ts showToast); returns the toast so it can be taken back. */
  notify(title: string, detail: string, kind: 'info' | 'error'): HTMLElement | void;
  onOpenLeaderFile(): void;
  onLeaderModel(): void;
  /** Choose a .vrm file for the partner to wear (avatar.ts). */
  onOpenAvatar(): void;
  /** Take off the avatars. */
  onPlainBodies(): void;
}

export class RecordPanel {
  private readonly folder: GUI;
  private readonly recordButton: Controller;
  private readonly modelButton: Controller;
  private readonly plainButton: Controller;
  private readonly indicator: HTMLElement;
  private leaderFile: string | null = null;
  private lastText = '';
  private lastLabel = '';
  /** This panel's last complaint ("Nothing recorded yet", "Not yet"): stale once a take starts. */
  private complaint: HTMLElement | null = null;

  constructor(private readonly options: RecordPanelOptions) {
    const { gui } = options;
    this.folder = gui.addFolder('record · play a file');
    const actions = {
      record: () => this.toggle(),
      download: () => this.download(),
      open: () => options.onOpenLeaderFile(),
      model: () => options.onLeaderModel(),
      avatar: () => options.onOpenAvatar(),
      plain: () => options.onPlainBodies(),
    };
    this.recordButton = this.folder.add(actions, 'record');
    this.folder.add(actions, 'download').name(`${CONTROLS.download[0]} (both dancers)`);
    this.folder.add(actions, 'open').name(CONTROLS.open[0]);
    this.modelButton = this.folder.add(actions, 'model').name(CONTROLS.leaderModel[0]).disable();
    this.folder.add(actions, 'avatar').name(CONTROLS.avatar[0]);
    this.plainButton = this.folder.add(actions, 'plain').name(CONTROLS.plainBodies[0]).disable();
    this.indicator = document.createElement('div');
    this.indicator.className = 'record-status';
    this.indicator.hidden = true;
    options.overlay.appendChild(this.indicator);
    this.update();
  }

  /** Whether a dancer wears an avatar ("plain bodies again" can take it off). */
  setDressed(dressed: boolean): void {
    this.plainButton.enable(dressed);
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
    const label = recorder.recording ? '■ stop recording' : CONTROLS.record[0];
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
      this.complain(notify('Not yet', 'The dancers are still loading; record once they move.', 'error'));
      return;
    }
    if (recorder.frames > 0 && !recorder.saved &&
      !window.confirm(`Start a new take? The last one (${formatDuration(recorder.seconds)}) was not downloaded and will be lost.`)) {
      return;
    }
    this.options.between(() => {
      const current = this.options.duet();
      if (current) {
        recorder.start(current);
        this.complain(null); // "nothing recorded yet" is no longer true
      }
      this.update();
    }).catch((error) => notify('Could not record', String((error as Error)?.message ?? error), 'error'));
  }

  /** Replace this panel's standing complaint (or just take it back, with null). */
  private complain(toast: HTMLElement | void | null): void {
    this.complaint?.remove();
    this.complaint = toast ?? null;
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
      this.complain(notify('Nothing recorded yet', 'Press “● record”, dance a little, then download.', 'error'));
      return;
    }
    const stamp = timestamp();
    downloadText(`duet-leader-${stamp}.bvh`, files.leader);
    downloadText(`duet-follower-${stamp}.bvh`, files.follower);
    notify('BVH saved', `${files.frames} frames (${formatDuration(files.frames / FPS)}) per dancer: duet-leader-${stamp}.bvh and duet-follower-${stamp}.bvh.`, 'info');
    this.update();
  }
}
