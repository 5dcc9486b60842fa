// Drive the leader from a recorded motion instead of the leader model: each step the leader's
// current frame is the next recorded frame and its plan (future keys) the recording's future, so
// the follower reacts to a real dance. The recording is moved rigidly (turn about Y + shift) so
// that its first frame starts where the leader stands; at the end it loops, re-anchored the same way.

import { FUTURE_OFFSETS, Track, footContacts, wrapAngle } from '../mirror/features';
import { FPS, type Motion, N_JOINTS, POSITIONS_SIZE } from '../mirror/skeleton';
import { NOW } from '../mirror/rollout';


export class LeaderPlayback {
  /** The recording with its root and heading (world, as recorded). */
  readonly recording: Track;
  /** Recording frame shown as the leader's current frame. */
  frame = 0;
  // Rigid move: p' = R_y(turn) (p - from) + to.
  private cos = 1;
  private sin = 0;
  private turn = 0;
  private fromX = 0;
  private fromZ = 0;
  private toX = 0;
  private toZ = 0;
  private readonly current = new Float64Array(POSITIONS_SIZE);
  private readonly previous = new Float64Array(POSITIONS_SIZE);

  constructor(motion: Motion) {
    if (Math.abs(motion.fps - FPS) > 1e-6) throw new RangeError(`a leader recording must be at ${FPS} fps, got ${motion.fps}`);
    if (motion.frames < 2) throw new RangeError('a leader recording needs at least 2 frames');
    this.recording = Track.fromMotion(motion);
  }

  get frames(): number {
    return this.recording.frames;
  }

  /** Anchor: recording frame 0 will stand at (rootX, rootZ), facing `heading`. */
  alignTo(rootX: number, rootZ: number, heading: number): void {
    const r = this.recording;
    this.turn = heading - r.heading[0];
    this.cos = Math.cos(this.turn);
    this.sin = Math.sin(this.turn);
    this.fromX = r.root[0];
    this.fromZ = r.root[1];
    this.toX = rootX;
    this.toZ = rootZ;
  }

  /** Start over at recording frame 0, anchored at the track's current root, with a still history. */
  start(track: Track): void {
    this.alignTo(track.root[2 * NOW], track.root[2 * NOW + 1], track.heading[NOW]);
    this.frame = 0;
    for (let slot = 0; slot <= NOW; slot++) this.writeFrame(track, slot, 0);
    this.writePlan(track);
  }

  /** Take over mid-dance: the leader's current frame counts as recording frame 0 (its past stays). */
  takeOver(track: Track): void {
    this.alignTo(track.root[2 * NOW], track.root[2 * NOW + 1], track.heading[NOW]);
    this.frame = 0;
    this.writePlan(track);
  }

  /** One frame on: shift the past, the current frame is the next recorded one, the plan its future. */
  advance(track: Track, contacts: Float64Array): void {
    this.frame++;
    if (this.frame >= this.frames) {
      // Loop: re-anchor frame 0 where the leader stands now, then continue from frame 1.
      this.alignTo(track.root[2 * NOW], track.root[2 * NOW + 1], track.heading[NOW]);
      this.frame = 1;
    }
    track.shiftPast(NOW);
    this.writeFrame(track, NOW, this.frame);
    this.writePlan(track);
    // A rigid move changes neither heights nor speeds: contacts straight from the recording.
    const p = this.recording.positions;
    for (let i = 0; i < POSITIONS_SIZE; i++) {
      this.current[i] = p[this.frame * POSITIONS_SIZE + i];
      this.previous[i] = p[(this.frame - 1) * POSITIONS_SIZE + i];
    }
    footContacts(this.current, this.previous, contacts, 0);
  }

  /** Future keys of the track = the recording's future of the current frame (held at its end). */
  private writePlan(track: Track): void {
    const r = this.recording;
    for (const off of FUTURE_OFFSETS) {
      const f = Math.min(this.frame + off, this.frames - 1);
      this.movePoint(r.root[2 * f], r.root[2 * f + 1], track.root, 2 * (NOW + off));
      track.heading[NOW + off] = wrapAngle(r.heading[f] + this.turn);
    }
  }

  private writeFrame(track: Track, slot: number, f: number): void {
    const r = this.recording;
    for (let j = 0; j < N_JOINTS; j++) {
      const src = (f * N_JOINTS + j) * 3;
      const dst = (slot * N_JOINTS + j) * 3;
      this.movePoint(r.positions[src], r.positions[src + 2], track.positions, dst, 2);
      track.positions[dst + 1] = r.positions[src + 1];
      // R' = R_y(turn) R, column by column.
      const rs = (f * N_JOINTS + j) * 9;
      const rd = (slot * N_JOINTS + j) * 9;
      for (let k = 0; k < 3; k++) {
        const x = r.rotations[rs + k];
        const y = r.rotations[rs + 3 + k];
        const z = r.rotations[rs + 6 + k];
        track.rotations[rd + k] = this.cos * x + this.sin * z;
        track.rotations[rd + 3 + k] = y;
        track.rotations[rd + 6 + k] = -this.sin * x + this.cos * z;
      }
    }
    this.movePoint(r.root[2 * f], r.root[2 * f + 1], track.root, 2 * slot);
    track.heading[slot] = wrapAngle(r.heading[f] + this.turn);
  }

  /** Moved floor point (x, z) into out[at] and out[at + zStep]. */
  private movePoint(x: number, z: number, out: Float64Array, at: number, zStep = 1): void {
    const dx = x - this.fromX;
    const dz = z - this.fromZ;
    out[at] = this.cos * dx + this.sin * dz + this.toX;
    out[at + zStep] = -this.sin * dx + this.cos * dz + this.toZ;
  }
}
