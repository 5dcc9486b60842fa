// Both dancers standing in their start pose, from the manifest alone: what the page draws while
// onnxruntime and the models download, so the first thing a visitor sees is the pair, not an
// empty floor. The same start as the simulation's (startDuet), without any model.

import { KEYS } from '../mirror/features';
import { POSITIONS_SIZE, ROTATIONS_SIZE } from '../mirror/skeleton';
import { type Dancer, type DuetManifest, NOW, startDuet } from '../mirror/rollout';
import type { DancerView } from './types';

function still(d: Dancer): DancerView {
  const t = d.track;
  const future = new Float32Array(KEYS * 2);
  for (let k = 0; k < KEYS; k++) {
    future[2 * k] = d.rootX;
    future[2 * k + 1] = d.rootZ;
  }
  return {
    root: [d.rootX, d.rootZ],
    heading: d.heading,
    positions: Float32Array.from(t.positions.subarray(NOW * POSITIONS_SIZE, (NOW + 1) * POSITIONS_SIZE)),
    rotations: Float32Array.from(t.rotations.subarray(NOW * ROTATIONS_SIZE, (NOW + 1) * ROTATIONS_SIZE)),
    future,
    contacts: new Float32Array([1, 1]), // both feet on the floor
    hands: new Float32Array(2),
  };
}

/** The leader and one follower in their start pose and place. */
export function standingViews(manifest: DuetManifest): { leader: DancerView; followers: DancerView[] } {
  const duet = startDuet(manifest, 1);
  return { leader: still(duet.leader), followers: duet.followers.map(still) };
}
