// Keep the dancers in the part of the screen the page leaves them: below the title card, above a
// phone's settings sheet (open, or its folded bar), left of the open panel card or drawer (wide
// and landscape screens), below the folded panel's title bar at the top right. The stage centres
// the picture in that part and keeps the camera far enough for both dancers' heads and feet to
// fit in it (web/draw/scene.ts setFrame, web/draw/framing.ts). Measured only when the panel, the
// title card or the window change size, never per frame.

import type { Rect } from '../draw/framing';
import type { Stage } from '../draw/scene';

/**
 * The free part of a `width` x `height` screen, given the title card's box and the panel's (CSS px).
 * Each covers a band: the title card and a short box at the top (the folded panel's bar) the top,
 * a full-width box at the bottom (the sheet, open or folded) the bottom, a tall box at the right
 * (the open card or drawer) the right side.
 */
export function freePart(width: number, height: number, boxes: readonly (DOMRectReadOnly | Rect | null)[]): Rect {
  const free = { left: 0, top: 0, right: width, bottom: height };
  for (const box of boxes) {
    if (!box || box.right - box.left < 1 || box.bottom - box.top < 1) continue;
    const boxWidth = box.right - box.left, boxHeight = box.bottom - box.top;
    if (boxWidth > 0.9 * width && box.bottom > height - 2) free.bottom = Math.min(free.bottom, box.top);
    else if (box.top < 40 && box.left > width / 2 && boxHeight > height / 3) free.right = Math.min(free.right, box.left);
    else if (box.top < 40 && boxHeight <= height / 3) free.top = Math.max(free.top, box.bottom);
  }
  return free;
}

/**
 * lil-gui opens a folder by animating its list from one height to another over two animation
 * frames, and ends the animation (the list takes its own height again) at the first transition
 * that ends on the list. On a page that draws slowly (a phone, 8 possible reactions) a short
 * transition of the list's own ends between those two frames, and the second frame then set the
 * list to the height it measured and left it there: the open sheet stood 152 px taller than its
 * controls (625 px for 473), over the dancers. A height set on a list outside its animation is
 * taken off again.
 */
function keepListsAtOwnHeight(panel: HTMLElement): void {
  new MutationObserver((records) => {
    for (const { target } of records) {
      if (!(target instanceof HTMLElement) || !target.classList.contains('lil-children') || !target.style.height) continue;
      if (!target.parentElement?.classList.contains('lil-transition')) target.style.height = '';
    }
  }).observe(panel, { subtree: true, attributes: true, attributeFilter: ['style'] });
}

export class ViewCentre {
  private free: Rect;
  /** The free part less the top and bottom bands (loadingUpdate). */
  private sides: Rect;
  /** Where the open card or drawer begins (px from the left), or the window's width. */
  freeWidth = window.innerWidth;

  constructor(private readonly panel: HTMLElement) {
    this.free = { left: 0, top: 0, right: window.innerWidth, bottom: window.innerHeight };
    this.sides = this.free;
    const measure = () => this.measure();
    const observer = new ResizeObserver(measure);
    observer.observe(panel);
    const title = document.getElementById('overlay');
    if (title) observer.observe(title);
    window.addEventListener('resize', measure);
    this.measure();
    keepListsAtOwnHeight(panel);
  }

  private measure(): void {
    // A new object on a change (never per frame): the stage compares it by identity.
    const title = document.getElementById('overlay');
    this.free = freePart(window.innerWidth, window.innerHeight, [title?.getBoundingClientRect() ?? null, this.panel.getBoundingClientRect()]);
    this.freeWidth = this.free.right;
    this.sides = { left: 0, top: 0, right: this.free.right, bottom: window.innerHeight };
  }

  /** The free part as last measured (client px). */
  get part(): Rect {
    return this.free;
  }

  /** Give the stage the free part (the canvas fills the window: client px are canvas px). The
   *  stage acts only on a change: call once per frame. */
  update(stage: Stage): void {
    stage.setFrame(this.free);
  }

  /**
   * While the models load: only an open card or drawer at the right moves the picture's centre.
   * The picture shown from the first paint (index.html's poster, scripts/poster.mjs) is drawn
   * before any script runs, so it can follow the open panel (a fixed width, in its CSS) but not the
   * title card's height, which depends on the words' wrapping; the loading scene stands where
   * the picture did, and the dance, from its first step, in the part the page leaves it.
   */
  loadingUpdate(stage: Stage): void {
    stage.setFrame(this.sides);
  }
}
