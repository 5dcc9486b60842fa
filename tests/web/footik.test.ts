// web/mirror/footik.ts: the two-bone IK keeps bone lengths and reaches what it can; the lock keeps a
// planted foot still, slides a lock that trails too far, and holds ankles above the floor.

import { describe, expect, it } from 'vitest';
import { ANKLE_FLOOR, FootLock, MAX_LOCK_DISTANCE, MAX_STANCE, capStance, twoBoneIk } from '../../web/mirror/footik';

/** A left leg: thigh (11) at hip height, knee (12) forward (bent 0.46 rad, more than the least
 *  bend the foot lock keeps), foot (13) below. */
function leg(): Float64Array {
  const p = new Float64Array(51);
  p.set([0.1, 0.95, 0], 33);
  p.set([0.1, 0.52, 0.1], 36);
  p.set([0.1, 0.09, 0], 39);
  p.set([-0.1, 0.95, 0], 42); // right leg, untouched by a left-foot lock
  p.set([-0.1, 0.52, 0.1], 45);
  p.set([-0.1, 0.09, 0], 48);
  return p;
}
const dist = (p: ArrayLike<number>, i: number, j: number) => Math.hypot(p[3 * i] - p[3 * j], p[3 * i + 1] - p[3 * j + 1], p[3 * i + 2] - p[3 * j + 2]);

describe('twoBoneIk', () => {
  it('puts a reachable foot exactly on the target, bones unchanged, thigh fixed, knee bent forward', () => {
    const p = leg();
    const lengths = [dist(p, 11, 12), dist(p, 12, 13)];
    twoBoneIk(p, 11, 12, 13, 0.15, 0.2, 0.1, 0, 0, 1);
    expect([p[39], p[40], p[41]].map((v, i) => v - [0.15, 0.2, 0.1][i]).every((d) => Math.abs(d) < 1e-12)).toBe(true);
    expect(dist(p, 11, 12)).toBeCloseTo(lengths[0], 12);
    expect(dist(p, 12, 13)).toBeCloseTo(lengths[1], 12);
    expect([p[33], p[34], p[35]]).toEqual([0.1, 0.95, 0]);
    expect(p[38]).toBeGreaterThan(0.05); // the knee stays on its side (forward)
  });

  it('stretches toward an unreachable target without changing bone lengths', () => {
    const p = leg();
    const lengths = [dist(p, 11, 12), dist(p, 12, 13)];
    twoBoneIk(p, 11, 12, 13, 0.1, -1, 0, 0, 0, 1);
    expect(dist(p, 11, 12)).toBeCloseTo(lengths[0], 9);
    expect(dist(p, 12, 13)).toBeCloseTo(lengths[1], 9);
    expect(dist(p, 11, 13)).toBeCloseTo(lengths[0] + lengths[1], 5);
  });
});

describe('FootLock', () => {
  it('holds a planted foot while the body moves, leaves the other foot alone', () => {
    const lock = new FootLock();
    const p = leg();
    lock.apply(p, [1, 0], 0);
    const moved = leg();
    for (let i = 0; i < 51; i += 3) moved[i + 2] += 0.03; // the whole body 3 cm forward
    const right = Array.from(moved.subarray(42, 51));
    lock.apply(moved, [1, 0], 0);
    expect(moved[41]).toBeCloseTo(0, 9);
    expect(moved[39]).toBeCloseTo(0.1, 9);
    expect(Array.from(moved.subarray(42, 51))).toEqual(right);
  });

  it('slides a lock that fell too far behind along, MAX_LOCK_DISTANCE behind the foot', () => {
    const lock = new FootLock();
    lock.apply(leg(), [1, 1], 0);
    const far = leg();
    for (let i = 0; i < 51; i += 3) far[i] += MAX_LOCK_DISTANCE + 0.1;
    lock.apply(far, [1, 1], 0);
    // Both ankles drawn back toward where they were planted (the lock now 0.25 m behind the model's
    // ankle, reached as far as the knee's least bend lets), not snapped onto the model's ankle.
    const model = [0.1 + MAX_LOCK_DISTANCE + 0.1, -0.1 + MAX_LOCK_DISTANCE + 0.1];
    [far[39], far[48]].forEach((x, i) => {
      expect(x).toBeGreaterThan(model[i] - MAX_LOCK_DISTANCE - 1e-9);
      expect(x).toBeLessThan(model[i] - 0.2);
    });
  });

  it('trails the network\'s own foot: a glide of the drawn body during a contact never slides the lock', () => {
    // The network's body stays; the contact layer's glide moves the drawn body 0.3 m back (more
    // than MAX_LOCK_DISTANCE). Told of the glide, the lock stays where the foot was planted and the
    // leg reaches back to it; not told, it slides to MAX_LOCK_DISTANCE behind the drawn foot.
    const moved = () => {
      const p = leg();
      for (let i = 0; i < 51; i += 3) p[i] -= 0.3;
      return p;
    };
    const told = new FootLock();
    told.apply(leg(), [1, 0], 0, [0, 0]);
    const glided = moved();
    told.apply(glided, [1, 0], 0, [-0.3, 0]);
    const blind = new FootLock();
    blind.apply(leg(), [1, 0], 0);
    const slid = moved();
    blind.apply(slid, [1, 0], 0);
    expect(glided[39]).toBeGreaterThan(slid[39] + 0.01);   // nearer the planted spot (x 0.1)
    expect(slid[39]).toBeLessThanOrEqual(0.1 - 0.3 + MAX_LOCK_DISTANCE + 1e-9);
  });

  it('locks from its own threshold (the follower is unsure of its feet)', () => {
    const follower = new FootLock(0.3);
    const leader = new FootLock();
    const a = leg();
    const b = leg();
    follower.apply(a, [0.4, 0.2], 0);
    leader.apply(b, [0.4, 0.2], 0);
    for (const p of [a, b]) for (let i = 0; i < 51; i += 3) p[i + 2] += 0.03;
    follower.apply(a, [0.4, 0.2], 0);
    leader.apply(b, [0.4, 0.2], 0);
    expect(a[41]).toBeCloseTo(0, 9); // locked at 0.4 > 0.3
    expect(b[41]).toBeCloseTo(0.03, 9); // free at 0.4 < 0.5
    expect(a[50]).toBeCloseTo(0.03, 9); // 0.2: free for both
  });

  it('never draws an ankle below the floor', () => {
    const lock = new FootLock();
    const low = leg();
    for (let i = 0; i < 51; i += 3) low[i + 1] -= 0.08; // ankle at 1 cm
    lock.apply(low, [0, 0], 0);
    expect(low[40]).toBeCloseTo(ANKLE_FLOOR, 9);
    const planted = leg();
    for (let i = 0; i < 51; i += 3) planted[i + 1] -= 0.08;
    new FootLock().apply(planted, [1, 1], 0);
    expect(planted[40]).toBeCloseTo(ANKLE_FLOOR, 9);
  });
});

describe('twoBoneIk with a least bend', () => {
  it('stops short of a straight chain, keeping the bend and the bone lengths', () => {
    const p = leg();
    const lengths = [dist(p, 11, 12), dist(p, 12, 13)];
    twoBoneIk(p, 11, 12, 13, 0.1, -1, 0, 0, 0, 1, 0.2);
    expect(dist(p, 11, 12)).toBeCloseTo(lengths[0], 9);
    expect(dist(p, 12, 13)).toBeCloseTo(lengths[1], 9);
    const ux = p[36] - p[33], uy = p[37] - p[34], uz = p[38] - p[35];
    const vx = p[39] - p[36], vy = p[40] - p[37], vz = p[41] - p[38];
    const bend = Math.acos((ux * vx + uy * vy + uz * vz) / (Math.hypot(ux, uy, uz) * Math.hypot(vx, vy, vz)));
    expect(bend).toBeCloseTo(0.2, 6);
  });
});

describe('capStance', () => {
  it('brings a lock back along the line to the foot until the stance is MAX_STANCE (as test_contact.py)', () => {
    expect(MAX_STANCE).toBe(0.9);
    const other = new Float64Array([-0.5, 0.1, 0]);
    const t = new Float64Array([0, 0, 0, 1, 0.1, 0]); // the second foot's lock, 1.5 m from the other foot
    capStance(t, 3, 0, 0.1, 0, other, 0);
    expect(Array.from(t.subarray(3)).map((v, i) => Math.abs(v - [0.4, 0.1, 0][i]) < 1e-12)).toEqual([true, true, true]);
    const wide = new Float64Array([2, 0.1, 0]);
    capStance(wide, 0, 1.5, 0.1, 0, other, 0);
    expect(Array.from(wide)).toEqual([1.5, 0.1, 0]);
    const near = new Float64Array([0.2, 0.1, 0]);
    capStance(near, 0, 0, 0.1, 0, other, 0);
    expect(Array.from(near)).toEqual([0.2, 0.1, 0]);
  });
});
