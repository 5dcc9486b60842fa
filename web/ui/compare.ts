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
      stage.keepInView(HALF_WIDTH);
      const needed = stage.controls.minDistance;
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

  /** Put each label over its pair (the first pair's midpoint is x, z), or hide it off screen. */
  placeLabels(stage: Stage, x: number, z: number): void {
    if (!this.active) return;
    const canvas = stage.canvas;
    const width = canvas.clientWidth, height = canvas.clientHeight;
    this.labels.forEach((label, i) => {
      this.point.set(x + i * this.offset.x, LABEL_HEIGHT, z + i * this.offset.z).project(stage.camera);
      const visible = this.point.z < 1 && Math.abs(this.point.x) < 1.2 && Math.abs(this.point.y) < 1.2;
      label.hidden = !visible;
      if (!visible) return;
      // Kept on screen and below the title card (the labels' widths are read once, when shown).
      this.widths[i] ||= label.offsetWidth;
      this.heights[i] ||= label.offsetHeight;
      const half = this.widths[i] / 2 + 4;
      const left = Math.min(Math.max(((this.point.x + 1) / 2) * width, half), width - half);
      const top = Math.max(((1 - this.point.y) / 2) * height, this.overlayBottom + this.heights[i] + 4);
      label.style.transform = `translate(${left.toFixed(1)}px, ${top.toFixed(1)}px) translate(-50%, -100%)`;
    });
  }

  private buffer(slot: number, length: number): Float32Array {
    const key = `${slot}:${length}`;
    let out = this.scratch.get(key);
    if (!out) this.scratch.set(key, (out = new Float32Array(length)));
    return out;
  }
}
