// What the page draws between two simulation steps: the animation loop runs at the display rate,
// the simulation at 30 Hz, and drawing interpolates between the last two steps.

import { INTENTION_SIZE, KEYS } from './features';
import { POSITIONS_SIZE } from './skeleton';
import type { DancerView } from './types';

/** Last two simulation states of one dancer, copied so drawing can interpolate between them. */
export class DancerTrack {
  readonly previous = new Float32Array(POSITIONS_SIZE);
  readonly current = new Float32Array(POSITIONS_SIZE);
  readonly drawn = new Float32Array(POSITIONS_SIZE);
  readonly root = new Float32Array(4); // previous x, z, current x, z
  readonly future = new Float32Array(KEYS * 2);
  readonly intention = new Float32Array(INTENTION_SIZE);
  hasIntention = false;

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
