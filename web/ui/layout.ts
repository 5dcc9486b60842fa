// Keep the dancers in the part of the screen the panel leaves free. On a wide screen the open
// panel is a card over the right edge; the camera's picture is shifted left by half its width
// (a view offset: the orbit, the steering and the follow target are unchanged), so the pair, and
// both pairs in compare mode, stand in the middle of what is visible. Phones' bottom sheet and
// folded panels cover nothing that matters and leave the picture centred.

import type { Stage } from '../draw/scene';

export class ViewCentre {
  private shift = 0;
  private applied = -1;
  private width = 0;
  private height = 0;

  constructor(private readonly panel: HTMLElement, private readonly isOpen: () => boolean) {
    const measure = () => this.measure();
    new ResizeObserver(measure).observe(panel);
    window.addEventListener('resize', measure);
    this.measure();
  }

  /** Measured only when the panel or the window changes size, never per frame. */
  private measure(): void {
    const rect = this.panel.getBoundingClientRect();
    const width = window.innerWidth;
    // A card at the top right (not a full-width sheet at the bottom) that is open.
    const card = this.isOpen() && rect.top < 40 && rect.left > width / 2 && rect.height > 80;
    this.shift = card ? Math.round((width - rect.left) / 2) : 0;
  }

  /** Apply the shift to the camera when it, or the canvas size, changed (call once per frame). */
  update(stage: Stage): void {
    const canvas = stage.canvas;
    const width = canvas.clientWidth, height = canvas.clientHeight;
    if (this.shift === this.applied && width === this.width && height === this.height) return;
    this.applied = this.shift;
    this.width = width;
    this.height = height;
    if (this.shift > 0) stage.camera.setViewOffset(width, height, this.shift, 0, width, height);
    else stage.camera.clearViewOffset();
  }
}
