// Keep the dancers in the part of the screen the panel leaves free. On a wide screen the open
// panel is a card over the right edge (a drawer on a short screen); the camera's picture is
// shifted left by half its width. On a phone the open panel is a sheet over the bottom, as tall
// as its controls (half the screen): the picture moves up, so that the pair stands in the middle
// of the band between the title card and the sheet. A view offset: the orbit, the steering and
// the follow target are unchanged. The folded panel covers nothing that matters and leaves the
// picture centred.

import type { Stage } from '../draw/scene';

export class ViewCentre {
  private shiftX = 0;
  private shiftY = 0;
  private applied = '';
  /** Where the open card or drawer begins (px from the left), or the window's width. */
  freeWidth = window.innerWidth;

  constructor(private readonly panel: HTMLElement, private readonly isOpen: () => boolean) {
    const measure = () => this.measure();
    const observer = new ResizeObserver(measure);
    observer.observe(panel);
    const title = document.getElementById('overlay');
    if (title) observer.observe(title);
    window.addEventListener('resize', measure);
    this.measure();
  }

  /** Measured only when the panel, the title card or the window changes size, never per frame. */
  private measure(): void {
    const rect = this.panel.getBoundingClientRect();
    const width = window.innerWidth, height = window.innerHeight;
    const open = this.isOpen();
    // A card or drawer at the top right (not a full-width sheet at the bottom).
    const card = open && rect.top < 40 && rect.left > width / 2 && rect.height > 80;
    this.shiftX = card ? Math.round((width - rect.left) / 2) : 0;
    this.freeWidth = card ? rect.left : width;
    // A sheet across the bottom, open (taller than its folded bar).
    const sheet = open && rect.width > 0.9 * width && rect.bottom > height - 2 && rect.height > 80;
    const titleBottom = document.getElementById('overlay')?.getBoundingClientRect().bottom ?? 0;
    this.shiftY = sheet ? Math.max(0, Math.round(height / 2 - (titleBottom + rect.top) / 2)) : 0;
  }

  /** Apply the shift to the camera when it, or the canvas size, changed (call once per frame). */
  update(stage: Stage): void {
    const canvas = stage.canvas;
    const width = canvas.clientWidth, height = canvas.clientHeight;
    const key = `${this.shiftX} ${this.shiftY} ${width} ${height}`;
    if (key === this.applied) return;
    this.applied = key;
    if (this.shiftX > 0 || this.shiftY > 0) stage.camera.setViewOffset(width, height, this.shiftX, this.shiftY, width, height);
    else stage.camera.clearViewOffset();
  }
}
