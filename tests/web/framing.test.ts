// The framing (web/draw/framing.ts, web/ui/layout.ts): the free part of the screen the page
// leaves the dancers, and the distance at which points fit it, checked against three.js's own
// projection with the same view offset the stage sets.

import * as THREE from 'three';
import { describe, expect, it } from 'vitest';
import { type Basis, type Rect, cylinderPoints, distanceToFit, frameWindow, viewShift } from '../../web/draw/framing';
import { freePart } from '../../web/ui/layout';

/** A camera at `polar` degrees down from above, `azimuth` around, `distance` from `target`, drawing
 *  into a `width` x `height` canvas with its centre moved to the middle of `free` (Stage.setFrame). */
function camera(width: number, height: number, free: Rect, polar: number, azimuth: number, distance: number, target: THREE.Vector3) {
  const c = new THREE.PerspectiveCamera(45, width / height, 0.05, 100);
  const [x, y] = viewShift(free, width, height);
  c.setViewOffset(width, height, x, y, width, height);
  const offset = new THREE.Vector3().setFromSpherical(new THREE.Spherical(distance, THREE.MathUtils.degToRad(polar), THREE.MathUtils.degToRad(azimuth)));
  c.position.copy(target).add(offset);
  c.lookAt(target);
  c.updateMatrixWorld();
  return c;
}

function basisOf(c: THREE.Camera): Basis {
  const e = c.matrixWorld.elements;
  return { right: [e[0], e[1], e[2]], up: [e[4], e[5], e[6]], forward: [-e[8], -e[9], -e[10]] };
}

/** Where world point p is drawn, canvas pixels. */
function project(c: THREE.Camera, p: THREE.Vector3, width: number, height: number): [number, number] {
  const v = p.clone().project(c);
  return [((v.x + 1) / 2) * width, ((1 - v.y) / 2) * height];
}

describe('distanceToFit', () => {
  const target = new THREE.Vector3(0.3, 0.9, -1.2);
  // A phone with its sheet open: the band between the title card and the sheet.
  const cases: [number, number, Rect][] = [
    [390, 844, { left: 0, top: 64, right: 390, bottom: 331 }],
    [1280, 800, { left: 0, top: 103, right: 972, bottom: 800 }],
    [844, 390, { left: 0, top: 102, right: 540, bottom: 390 }],
  ];
  for (const [width, height, free] of cases) {
    for (const polar of [5, 40, 70, 88]) {
      it(`puts the farthest of some points on the free part's edge (${width}x${height}, ${polar}°)`, () => {
        const points = cylinderPoints(0.8, 0.9);
        const world = Array.from({ length: points.length / 3 }, (_, i) => new THREE.Vector3(points[3 * i], points[3 * i + 1], points[3 * i + 2]).add(target));
        const window = frameWindow(free, height, 45, 6);
        const probe = camera(width, height, free, polar, 35, 5, target);
        const need = distanceToFit(points, world.length, basisOf(probe), window);
        const inside = (c: THREE.Camera) =>
          world.every((p) => {
            const [x, y] = project(c, p, width, height);
            return x >= free.left + 5.99 && x <= free.right - 5.99 && y >= free.top + 5.99 && y <= free.bottom - 5.99;
          });
        expect(inside(camera(width, height, free, polar, 35, need, target))).toBe(true);
        expect(inside(camera(width, height, free, polar, 35, need * 1.5, target))).toBe(true);
        expect(inside(camera(width, height, free, polar, 35, need * 0.97, target))).toBe(false);
      });
    }
  }

  it('turns around the vertical axis without changing what a cylinder needs', () => {
    const points = cylinderPoints(0.8, 0.9);
    const free = { left: 0, top: 64, right: 390, bottom: 331 };
    const window = frameWindow(free, 844, 45);
    const needs = [0, 35, 120, 250].map((azimuth) => distanceToFit(points, points.length / 3, basisOf(camera(390, 844, free, 70, azimuth, 5, new THREE.Vector3())), window));
    for (const need of needs) expect(need).toBeCloseTo(needs[0], 2);
  });
});

describe('freePart', () => {
  it('a phone: below the title card, above the open sheet or its folded bar', () => {
    expect(freePart(390, 844, [{ left: 8, top: 8, right: 382, bottom: 64 }, { left: 0, top: 331, right: 390, bottom: 844 }])).toEqual({ left: 0, top: 64, right: 390, bottom: 331 });
    expect(freePart(390, 844, [{ left: 8, top: 8, right: 382, bottom: 116 }, { left: 0, top: 804, right: 390, bottom: 844 }])).toEqual({ left: 0, top: 116, right: 390, bottom: 804 });
  });

  it('a wide screen: left of the open card, below the title; below the folded bar at the top right', () => {
    expect(freePart(1280, 800, [{ left: 8, top: 8, right: 815, bottom: 103 }, { left: 972, top: 8, right: 1272, bottom: 496 }])).toEqual({ left: 0, top: 103, right: 972, bottom: 800 });
    expect(freePart(1280, 800, [{ left: 8, top: 8, right: 815, bottom: 103 }, { left: 972, top: 8, right: 1272, bottom: 33 }])).toEqual({ left: 0, top: 103, right: 1280, bottom: 800 });
  });

  it('a phone held sideways: left of the open drawer', () => {
    expect(freePart(844, 390, [{ left: 8, top: 8, right: 485, bottom: 102 }, { left: 540, top: 0, right: 844, bottom: 390 }])).toEqual({ left: 0, top: 102, right: 540, bottom: 390 });
  });

  it('ignores what is not shown', () => {
    expect(freePart(390, 844, [null, { left: 0, top: 0, right: 0, bottom: 0 }])).toEqual({ left: 0, top: 0, right: 390, bottom: 844 });
  });
});
