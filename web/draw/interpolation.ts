// What the page draws between two simulation steps: the animation loop runs at the display rate,
// the simulation at 30 Hz, and drawing interpolates between the last two steps.

import { INTENTION_SIZE, KEYS } from '../mirror/features';
import { POSITIONS_SIZE, ROTATIONS_SIZE } from '../mirror/skeleton';
import type { DancerView } from '../engine/types';

/** Last two simulation states of one dancer, copied so drawing can interpolate between them. */
export class DancerTrack {
  readonly previous = new Float32Array(POSITIONS_SIZE);
  readonly current = new Float32Array(POSITIONS_SIZE);
  readonly drawn = new Float32Array(POSITIONS_SIZE);
  readonly root = new Float32Array(4); // previous x, z, current x, z
  readonly future = new Float32Array(KEYS * 2);
  readonly intention = new Float32Array(INTENTION_SIZE);
  hasIntention = false;
  // Joint rotations (for the hands, feet and face) interpolate like the positions; contacts and
  // the hand holds of the contact layer do not.
  readonly previousRotations = new Float32Array(ROTATIONS_SIZE);
  readonly currentRotations = new Float32Array(ROTATIONS_SIZE);
  readonly drawnRotations = new Float32Array(ROTATIONS_SIZE);
  readonly contacts = new Float32Array(2);
  readonly hands = new Float32Array(2);
  hasRotations = false;

  capture(view: DancerView, snap: boolean): void {
    this.previous.set(snap ? view.positions : this.current);
    this.current.set(view.positions);
    this.root[0] = snap ? view.root[0] : this.root[2];
    this.root[1] = snap ? view.root[1] : this.root[3];
    this.root[2] = view.root[0];
    this.root[3] = view.root[1];
    this.future.set(view.future);
    this.hasIntention = view.intention !== undefined;
    if (view.intention) this.intention.set(view.intention);
    this.hasRotations = view.rotations !== undefined;
    if (view.rotations) {
      this.previousRotations.set(snap ? view.rotations : this.currentRotations);
      this.currentRotations.set(view.rotations);
    }
    if (view.contacts) this.contacts.set(view.contacts);
    else this.contacts.fill(0);
    if (view.hands) this.hands.set(view.hands);
    else this.hands.fill(0);
  }

  /** Rotations between the last two steps, or null when the simulation gives none. */
  interpolateRotations(alpha: number): Float32Array | null {
    if (!this.hasRotations) return null;
    const a = this.previousRotations, b = this.currentRotations, out = this.drawnRotations;
    for (let i = 0; i < ROTATIONS_SIZE; i++) out[i] = a[i] + (b[i] - a[i]) * alpha;
    return out;
  }

  interpolate(alpha: number): Float32Array {
    for (let i = 0; i < POSITIONS_SIZE; i++) this.drawn[i] = this.previous[i] + (this.current[i] - this.previous[i]) * alpha;
    return this.drawn;
  }

  rootX(alpha: number): number {
    return this.root[0] + (this.root[2] - this.root[0]) * alpha;
  }

  rootZ(alpha: number): number {
    return this.root[1] + (this.root[3] - this.root[1]) * alpha;
  }
}
