// web/mirror/contact.ts against training/mirror/contact.py: the contact layer over the fixture's 40 frames of two
// procedural dancers walked into each other and apart (spines pushed apart, hands drawn together
// and let go, feet locked and released, one clear() as after a reset), plus the geometry alone.

import { describe, expect, it } from 'vitest';
import {
  ContactLayer, HAND_FULL, HAND_REACH, HIP_GLIDE, HipGlide, SEPARATION, closestOnSegments, reachWeight, separate, spineGap,
} from '../../web/mirror/contact';
import { expectClose, fixture } from './fixture';

const J3 = 17 * 3;

describe('ContactLayer mirrors training/mirror/contact.py', () => {
  const data = fixture('contact');

  it('shows the same poses, hold, hands and push at every step', () => {
    const layer = new ContactLayer();
    for (let t = 0; t < data.steps; t++) {
      const a = Float64Array.from(data.leader.slice(t * J3, (t + 1) * J3));
      const b = Float64Array.from(data.follower.slice(t * J3, (t + 1) * J3));
      if (t === data.clearAt) layer.clear();
      layer.apply(a, b, data.leaderContacts.slice(2 * t, 2 * t + 2), data.followerContacts.slice(2 * t, 2 * t + 2),
        data.leaderHeading[t], data.followerHeading[t]);
      expectClose(a, data.shownLeader.slice(t * J3, (t + 1) * J3), `step ${t}: shown leader`);
      expectClose(b, data.shownFollower.slice(t * J3, (t + 1) * J3), `step ${t}: shown follower`);
      expectClose([layer.hold, layer.pushed], [data.hold[t], data.pushed[t]], `step ${t}: hold, pushed`);
      expect([layer.hands[0], layer.hands[1]], `step ${t}: hands`).toEqual(data.hands.slice(2 * t, 2 * t + 2));
    }
  });
});

describe('contact geometry', () => {
  it('closestOnSegments clamps to the ends and handles a point', () => {
    const a = Float64Array.from([0, 0, 0, 1, 0, 0]);
    const b = Float64Array.from([2, 1, 0, 3, 1, 0, 0.5, 1, 0, 0.5, 1, 0]);
    const st = new Float64Array(2);
    closestOnSegments(a, 0, 1, b, 0, 1, st);
    expect([st[0], st[1]]).toEqual([1, 0]);
    closestOnSegments(a, 0, 1, b, 2, 3, st); // q is a point above the middle of p
    expect(st[0]).toBeCloseTo(0.5, 12);
  });

  it('separate leaves apart bodies alone and pushes overlapping spines to SEPARATION', () => {
    const spine = (x: number) => {
      const p = new Float64Array(J3);
      for (let j = 0; j < 17; j++) p.set([x, 1 + 0.1 * Math.min(j, 3), 0], 3 * j);
      return p;
    };
    const far = [spine(0), spine(1)];
    expect(separate(far[0], far[1])).toBe(0);
    const a = spine(0), b = spine(0.1);
    const push = separate(a, b);
    expect(push).toBeCloseTo((SEPARATION - 0.1) / 2, 12);
    expect(spineGap(a, b, new Float64Array(3))).toBeCloseTo(SEPARATION, 12);
    expect(a[1]).toBe(1); // only horizontal
  });

  it('reachWeight is 1 within HAND_FULL and 0 beyond HAND_REACH', () => {
    expect(reachWeight(HAND_FULL - 0.01)).toBe(1);
    expect(reachWeight(HAND_REACH + 0.01)).toBe(0);
    expect(reachWeight((HAND_FULL + HAND_REACH) / 2)).toBeCloseTo(0.5, 12);
  });
});

describe('HipGlide (the shown path over the floor)', () => {
  const body = (x: number, z: number) => {
    const p = new Float64Array(17 * 3);
    for (let j = 0; j < 17; j++) {
      p[3 * j] = x;
      p[3 * j + 1] = 0.1 * j;
      p[3 * j + 2] = z;
    }
    return p;
  };
  it('steps by a running mean of the network\'s steps: a jump shown a HIP_GLIDE share at once and the rest later, never back', () => {
    const glide = new HipGlide();
    const first = body(3, 0);
    glide.apply(first);
    expect(Array.from(first)).toEqual(Array.from(body(3, 0)));
    const jumped = body(3, 1);
    glide.apply(jumped);
    for (let j = 0; j < 17; j++) {
      expect(jumped[3 * j + 2]).toBeCloseTo(HIP_GLIDE, 12);
      expect(jumped[3 * j]).toBeCloseTo(3, 12);
      expect(jumped[3 * j + 1]).toBeCloseTo(0.1 * j, 12);
    }
    // The network stays: the shown hips go on the same way, each step (1 - HIP_GLIDE) of the last,
    // and come to the network's place without passing it.
    let z = HIP_GLIDE;
    let step = HIP_GLIDE;
    for (let n = 0; n < 60; n++) {
      const still = body(3, 1);
      glide.apply(still);
      step *= 1 - HIP_GLIDE;
      z += step;
      expect(still[2]).toBeCloseTo(z, 12);
      expect(still[2]).toBeLessThanOrEqual(1 + 1e-12);
    }
    expect(z).toBeCloseTo(1, 6);
    glide.clear();
    const again = body(5, 1.5);
    glide.apply(again);
    expect(Array.from(again)).toEqual(Array.from(body(5, 1.5)));
  });
  it('leaves a steady walk as it is, once it has caught up', () => {
    const glide = new HipGlide();
    let last = body(0, 0);
    for (let n = 0; n < 80; n++) {
      last = body(0, 0.03 * n);
      glide.apply(last);
    }
    expect(last[2]).toBeCloseTo(0.03 * 79 - (0.03 * (1 - HIP_GLIDE)) / HIP_GLIDE, 6);   // trails by (1 - g) / g steps
  });
});
