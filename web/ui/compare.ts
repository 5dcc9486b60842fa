// Compare mode, side by side. Both followers react to the same leader, so the simulation puts
// them on the same spot: on screen, one tangle of red and orange. Here the second follower, its
// path and a copy of the leader are drawn shifted sideways (across the camera's view, so the two
// pairs always stand next to each other on screen), and each pair gets a label over its heads.
// Drawing only: nothing the models see changes.

import { Vector3 } from 'three';
import { PAIR_HALF_WIDTH, type Stage } from '../draw/scene';

/** Metres between the two pairs' centres: a pair is about a metre wide, so a clear gap. */
export const PAIR_SPACING = 2.2;
/** Half the floor width that must fit on screen in compare mode (both pairs and a margin), m. */
const HALF_WIDTH = PAIR_SPACING / 2 + 1.1;
/** Labels sit this high over the floor (above the heads). */
const LABEL_HEIGHT = 2.05;
/** Pixels kept between the two labels, and between a label and the screen's edge. */
const LABEL_GAP = 8;

const LABELS: [string, string][] = [
  ['pair-label pair-label-partner', 'reads your intention'],
  ['pair-label pair-label-baseline', 'baseline, no intention'],
];

export class CompareLayout {
  /** The second pair's shift this frame (world x, z); zero outside compare mode. */
  readonly offset = { x: 0, z: 0 };
  active = false;
  private readonly forward = { x: 0, z: 1 };
  private readonly labels: HTMLElement[];
  private readonly point = new Vector3();
  private readonly scratch = new Map<string, Float32Array>();
  /** Label widths and the top overlay's bottom edge, measured when compare mode starts. */
  private widths: number[] = [];
  private heights: number[] = [];
  private overlayBottom = 0;
  /** The camera distance before compare mode widened it (restored when it ends). */
  private distanceBefore: number | null = null;

  constructor(parent: HTMLElement = document.body) {
    this.labels = LABELS.map(([className, text]) => {
      const label = document.createElement('div');
      label.className = className;
      label.textContent = text;
      label.hidden = true;
      parent.append(label);
      return label;
    });
  }

  /** Enter or leave compare mode: back the camera off until both pairs fit the screen's width. */
  setActive(stage: Stage, active: boolean): void {
    if (active === this.active) return;
    this.active = active;
    const orbit = stage.getOrbit();
    if (active) {
      this.widths = [];
      this.heights = [];
      const overlay = document.getElementById('overlay');
      this.overlayBottom = overlay ? overlay.getBoundingClientRect().bottom : 0;
      // No pinch can bring the camera closer than this either, while compare mode lasts.
      const needed = stage.keepInView(HALF_WIDTH);
      if (orbit.distance < needed) {
        this.distanceBefore = orbit.distance;
        stage.setOrbit({ ...orbit, distance: needed });
      }
    } else {
      stage.keepInView(PAIR_HALF_WIDTH);
      if (this.distanceBefore !== null) stage.setOrbit({ ...orbit, distance: this.distanceBefore });
      this.distanceBefore = null;
      this.offset.x = this.offset.z = 0;
      for (const label of this.labels) label.hidden = true;
    }
  }

  /** This frame's shift: the camera's right on the floor, times the spacing. */
  update(stage: Stage): void {
    if (!this.active) return;
    stage.viewForward(this.forward);
    this.offset.x = -this.forward.z * PAIR_SPACING;
    this.offset.z = this.forward.x * PAIR_SPACING;
  }

  /** A copy of xyz points moved by the shift (one reused buffer per slot: a dancer keeps its own). */
  shiftPoints(points: Float32Array, slot: number): Float32Array {
    const out = this.buffer(slot, points.length);
    for (let i = 0; i + 2 < points.length; i += 3) {
      out[i] = points[i] + this.offset.x;
      out[i + 1] = points[i + 1];
      out[i + 2] = points[i + 2] + this.offset.z;
    }
    return out;
  }

  /** A copy of (x, z) floor points moved by the shift. */
  shiftFloor(points: Float32Array, slot: number): Float32Array {
    const out = this.buffer(slot, points.length);
    for (let i = 0; i + 1 < points.length; i += 2) {
      out[i] = points[i] + this.offset.x;
      out[i + 1] = points[i + 1] + this.offset.z;
    }
    return out;
  }

  /**
   * Put each label over its pair (the first pair's midpoint is x, z), or hide it off screen.
   * Zoomed out, or on a narrow screen, the pairs stand closer on screen than the labels are wide:
   * the labels then move apart around their midpoint, and where the screen has no room for both
   * side by side the second goes above the first. They never cover each other, and stay clear of
   * the screen's edges and of an open panel card (`freeWidth`: where it begins).
   */
  placeLabels(stage: Stage, x: number, z: number, freeWidth = Infinity): void {
    if (!this.active) return;
    const canvas = stage.canvas;
    const width = canvas.clientWidth, height = canvas.clientHeight;
    // Labels stay left of an open panel card (freeWidth), where they would be hidden under it.
    const edge = Math.min(width, freeWidth);
    const spots: ({ x: number; y: number; half: number; height: number } | null)[] = this.labels.map((label, i) => {
      this.point.set(x + i * this.offset.x, LABEL_HEIGHT, z + i * this.offset.z).project(stage.camera);
      const visible = this.point.z < 1 && Math.abs(this.point.x) < 1.2 && Math.abs(this.point.y) < 1.2;
      label.hidden = !visible;
      if (!visible) return null;
      // The labels' sizes are read once, when first shown (not per frame).
      this.widths[i] ||= label.offsetWidth;
      this.heights[i] ||= label.offsetHeight;
      // y is the label's bottom edge, kept below the title card.
      const y = Math.max(((1 - this.point.y) / 2) * height, this.overlayBottom + this.heights[i] + 4);
      return { x: ((this.point.x + 1) / 2) * width, y, half: this.widths[i] / 2 + LABEL_GAP / 2, height: this.heights[i] };
    });
    const [a, b] = spots;
    if (a && b) {
      const [left, right] = a.x <= b.x ? [a, b] : [b, a];
      const need = left.half + right.half - (right.x - left.x);
      if (need > 0) {
        left.x -= need / 2;
        right.x += need / 2;
      }
      // Kept on screen; if that pushed them together again, there is no room side by side.
      for (const spot of spots) keepOnScreen(spot!, edge);
      if (right.x - left.x < left.half + right.half) {
        // Above the first label, or below it where that would reach under the title card.
        const above = Math.min(a.y, b.y) - a.height - LABEL_GAP;
        b.y = above - b.height >= this.overlayBottom ? above : Math.max(a.y, b.y) + b.height + LABEL_GAP;
      }
    } else {
      for (const spot of spots) if (spot) keepOnScreen(spot, edge);
    }
    spots.forEach((spot, i) => {
      if (spot) this.labels[i].style.transform = `translate(${spot.x.toFixed(1)}px, ${spot.y.toFixed(1)}px) translate(-50%, -100%)`;
    });
  }

  private buffer(slot: number, length: number): Float32Array {
    const key = `${slot}:${length}`;
    let out = this.scratch.get(key);
    if (!out) this.scratch.set(key, (out = new Float32Array(length)));
    return out;
  }
}

/** A label's centre moved so that the label lies between the screen's left edge and `right`. */
function keepOnScreen(spot: { x: number; half: number }, right: number): void {
  spot.x = Math.min(Math.max(spot.x, spot.half), right - spot.half);
}
