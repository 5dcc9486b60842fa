// "Save a clip" and "full screen": two buttons beside pause and the turn buttons by the title.
//
// The clip button records the WebGL canvas for CLIP_SECONDS with MediaRecorder (from
// canvas.captureStream, which in Chromium captures each composited frame, so the renderer needs
// no preserveDrawingBuffer) and saves it as duet-YYYYMMDD-HHMMSS.mp4 where the browser records
// MP4 (Safari), else .webm. While it records, the button counts down ("● 6 s", "● 5 s", …) and a
// small badge says so. A browser without MediaRecorder or captureStream gets a toast instead.
//
// The full screen button toggles document.documentElement fullscreen; it is hidden where
// fullscreen is unavailable (document.fullscreenEnabled false, e.g. iPhone Safari).

import { downloadBlob } from './download';
import { showToast } from './toast';

export const CLIP_SECONDS = 6;
const SVG = 'http://www.w3.org/2000/svg';
const CLIP_FPS = 30;
/** In order of preference: MP4 plays most widely (H.264 first), then WebM. */
const CLIP_TYPES = ['video/mp4;codecs=avc1', 'video/mp4', 'video/webm;codecs=vp9', 'video/webm;codecs=vp8', 'video/webm'];
/** "● clip"; the word is a span of its own, which a phone's one row of buttons folds away (style.css). */
function idleLabel(): (string | Node)[] {
  const word = document.createElement('span');
  word.className = 'clip-word';
  word.textContent = 'clip';
  return ['● ', word];
}
const IDLE_TITLE = `save a ${CLIP_SECONDS} s video clip of the dance`;

/** The first type this browser's MediaRecorder makes, or '' (let it choose). */
export function clipType(isSupported: (type: string) => boolean = (t) => MediaRecorder.isTypeSupported(t)): string {
  return CLIP_TYPES.find((type) => isSupported(type)) ?? '';
}

/** duet-YYYYMMDD-HHMMSS.webm (local time), .mp4 for an MP4 type. */
export function clipName(type: string, at = new Date()): string {
  const two = (n: number) => String(n).padStart(2, '0');
  const stamp = `${at.getFullYear()}${two(at.getMonth() + 1)}${two(at.getDate())}-${two(at.getHours())}${two(at.getMinutes())}${two(at.getSeconds())}`;
  return `duet-${stamp}.${type.startsWith('video/mp4') ? 'mp4' : 'webm'}`;
}

function titleRow(): Element {
  return document.querySelector('#overlay .title-row') ?? document.body;
}

export class ClipButton {
  readonly element: HTMLButtonElement;
  private readonly badge: HTMLElement;
  private recording = false;

  constructor(private readonly canvas: HTMLCanvasElement) {
    this.element = document.createElement('button');
    this.element.type = 'button';
    this.element.className = 'pause-button clip-button';
    this.element.replaceChildren(...idleLabel());
    this.element.title = IDLE_TITLE;
    this.element.setAttribute('aria-label', IDLE_TITLE);
    this.element.addEventListener('click', () => this.record());
    this.badge = document.createElement('div');
    this.badge.className = 'clip-badge';
    this.badge.setAttribute('role', 'status');
    this.badge.hidden = true;
    titleRow().append(this.element);
    // Under the title and the legend, in the overlay's card: clear of the buttons and the dancers.
    (document.getElementById('overlay') ?? document.body).append(this.badge);
  }

  private record(): void {
    if (this.recording) return;
    if (typeof MediaRecorder === 'undefined' || typeof this.canvas.captureStream !== 'function') {
      showToast('This browser cannot record the dance', 'It has no MediaRecorder or canvas capture: try a recent Chrome, Firefox or Safari, or a screen recorder.', 'info', 7000);
      return;
    }
    let recorder: MediaRecorder;
    let stream: MediaStream;
    try {
      stream = this.canvas.captureStream(CLIP_FPS);
      const type = clipType();
      recorder = new MediaRecorder(stream, type ? { mimeType: type, videoBitsPerSecond: 4_000_000 } : { videoBitsPerSecond: 4_000_000 });
    } catch (error) {
      showToast('Cannot record a clip', error instanceof Error ? error.message : String(error), 'error');
      return;
    }
    const chunks: Blob[] = [];
    recorder.addEventListener('dataavailable', (event) => {
      if (event.data.size > 0) chunks.push(event.data);
    });
    this.recording = true;
    this.element.classList.add('recording');
    let left = CLIP_SECONDS;
    const show = () => {
      this.element.textContent = `● ${left} s`;
      this.badge.textContent = `● recording a clip · ${left} s`;
    };
    show();
    this.badge.hidden = false;
    const tick = setInterval(() => {
      left = Math.max(1, left - 1);
      show();
    }, 1000);
    const finish = () => {
      clearInterval(tick);
      stream.getTracks().forEach((track) => track.stop());
      this.recording = false;
      this.element.classList.remove('recording');
      this.element.replaceChildren(...idleLabel());
      this.badge.hidden = true;
    };
    recorder.addEventListener('stop', () => {
      finish();
      const type = recorder.mimeType || chunks[0]?.type || 'video/webm';
      const blob = new Blob(chunks, { type });
      if (blob.size === 0) {
        showToast('The clip is empty', 'The browser recorded no frames.', 'error');
        return;
      }
      downloadBlob(clipName(type), blob);
      showToast('Clip saved', `${clipName(type)} · ${(blob.size / 1e6).toFixed(1)} MB`, 'info', 4000);
    });
    recorder.addEventListener('error', () => {
      finish();
      showToast('Recording the clip failed', 'The browser stopped the recorder.', 'error');
    });
    recorder.start(1000);
    setTimeout(() => {
      if (recorder.state !== 'inactive') recorder.stop();
    }, CLIP_SECONDS * 1000);
  }
}

/** Full screen and back; hidden where the browser offers no fullscreen (iPhone Safari). */
export class FullscreenButton {
  readonly element: HTMLButtonElement;

  constructor() {
    this.element = document.createElement('button');
    this.element.type = 'button';
    this.element.className = 'pause-button fullscreen-button';
    this.element.hidden = !document.fullscreenEnabled;
    this.element.addEventListener('click', () => this.toggle());
    document.addEventListener('fullscreenchange', () => this.show());
    titleRow().append(this.element);
    this.show();
  }

  private toggle(): void {
    const request = document.fullscreenElement ? document.exitFullscreen() : document.documentElement.requestFullscreen();
    request.catch((error: unknown) => showToast('Full screen is not available', error instanceof Error ? error.message : String(error), 'info', 5000));
  }

  private show(): void {
    const full = document.fullscreenElement !== null;
    // Four corners, out (full screen) or in (back): drawn, since phones' fonts lack a ⛶ glyph.
    const svg = document.createElementNS(SVG, 'svg');
    svg.setAttribute('viewBox', '0 0 14 14');
    svg.setAttribute('width', '14');
    svg.setAttribute('height', '14');
    svg.setAttribute('aria-hidden', 'true');
    const path = document.createElementNS(SVG, 'path');
    path.setAttribute('d', full ? 'M5 1v4H1M9 1v4h4M13 9H9v4M1 9h4v4' : 'M1 5V1h4M9 1h4v4M13 9v4H9M5 13H1V9');
    path.setAttribute('fill', 'none');
    path.setAttribute('stroke', 'currentColor');
    path.setAttribute('stroke-width', '1.8');
    svg.append(path);
    this.element.replaceChildren(svg);
    const title = full ? 'leave full screen' : 'full screen';
    this.element.title = title;
    this.element.setAttribute('aria-label', title);
  }
}
