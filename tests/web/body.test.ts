// web/draw/body.ts: hands, feet and face follow the joint rotations (or the body's facing without
// them), shoes stay above the floor, and contact marks appear only for contacts.

import * as THREE from 'three';
import { describe, expect, it } from 'vitest';
import { ContactMarks, DancerMeshes, SkinnedDancer } from '../../web/draw/body';
import { PRIMARY_CHILD, bindPositions, buildFigure, poseBones } from '../../web/draw/figure';
import { PARENTS } from '../../web/mirror/skeleton';

/** A standing dancer facing +z (left side at +x), arms hanging, ankles 8 cm up. */
function standing(): Float32Array {
  const p = new Float32Array(51);
  const set = (j: number, x: number, y: number, z: number) => p.set([x, y, z], 3 * j);
  set(0, 0, 0.95, 0); set(1, 0, 1.15, 0); set(2, 0, 1.3, 0); set(3, 0, 1.55, 0); set(4, 0, 1.65, 0);
  set(5, 0.18, 1.5, 0); set(6, 0.2, 1.22, 0); set(7, 0.2, 0.95, 0.05);
  set(8, -0.18, 1.5, 0); set(9, -0.2, 1.22, 0); set(10, -0.2, 0.95, 0.05);
  set(11, 0.1, 0.95, 0); set(12, 0.1, 0.52, 0.03); set(13, 0.1, 0.08, 0);
  set(14, -0.1, 0.95, 0); set(15, -0.1, 0.52, 0.03); set(16, -0.1, 0.08, 0);
  return p;
}

/** Rotate positions (and optionally row-major rotations) by `angle` about +y. */
function turned(p: Float32Array, angle: number): Float32Array {
  const out = new Float32Array(p.length);
  const c = Math.cos(angle), s = Math.sin(angle);
  for (let j = 0; j < p.length / 3; j++) {
    out[3 * j] = c * p[3 * j] + s * p[3 * j + 2];
    out[3 * j + 1] = p[3 * j + 1];
    out[3 * j + 2] = -s * p[3 * j] + c * p[3 * j + 2];
  }
  return out;
}

function identityRotations(angle = 0): Float32Array {
  const r = new Float32Array(17 * 9);
  const c = Math.cos(angle), s = Math.sin(angle);
  for (let j = 0; j < 17; j++) r.set([c, 0, s, 0, 1, 0, -s, 0, c], 9 * j);
  return r;
}

const material = () => new THREE.MeshStandardMaterial({ color: 0x2f6fe4 });
/** Extra instance i (0 l-hand, 1 r-hand, 2 l-foot, 3 r-foot, 4 nose, 5 visor): centre and main axis. */
function extra(d: DancerMeshes, i: number): { centre: THREE.Vector3; axis: THREE.Vector3; matrix: THREE.Matrix4 } {
  const mesh = d.group.children[0] as THREE.InstancedMesh;
  const matrix = new THREE.Matrix4();
  mesh.getMatrixAt(17 + i, matrix);
  const e = matrix.elements;
  return { centre: new THREE.Vector3(e[12], e[13], e[14]), axis: new THREE.Vector3(e[0], e[1], e[2]).normalize(), matrix };
}

describe('DancerMeshes', () => {
  for (const [label, rotations] of [['joint rotations', identityRotations()], ['positions only', null]] as const) {
    it(`points feet and face forward and hands along the forearm (${label})`, () => {
      const d = new DancerMeshes(PARENTS, 1, material(), false);
      for (const angle of [0, 1.2, -2.5]) {
        d.setPose(0, turned(standing(), angle), rotations && identityRotations(angle));
        const forward = new THREE.Vector3(Math.sin(angle), 0, Math.cos(angle));
        for (const foot of [2, 3]) {
          const { axis, centre } = extra(d, foot);
          expect(axis.dot(forward)).toBeGreaterThan(0.99);
          expect(centre.y).toBeGreaterThan(0);
        }
        const head = new THREE.Vector3(...turned(standing(), angle).slice(12, 15));
        expect(extra(d, 4).centre.sub(head).dot(forward)).toBeGreaterThan(0.08); // the nose is in front
        expect(extra(d, 4).axis.dot(forward)).toBeGreaterThan(0.99);
        // Hands hang down: the mitten runs downward from the wrist (arm straight along -y, so the
        // rotations' +x / -x convention must agree with the forearm).
        if (!rotations) for (const hand of [0, 1]) expect(extra(d, hand).axis.y).toBeLessThan(-0.9);
        for (let i = 0; i < 6; i++) expect(extra(d, i).matrix.determinant()).toBeGreaterThan(0); // no mirrored shape
      }
    });
  }

  it('keeps a shoe above the floor when the ankle is low and the toe points down', () => {
    const d = new DancerMeshes(PARENTS, 1, material(), false);
    const p = standing();
    p[40] = 0.06; // left ankle at its lowest
    const r = identityRotations();
    // Left foot pitched 40° toe-down: forward (col z) tilts to -y.
    const a = (40 * Math.PI) / 180;
    r.set([1, 0, 0, 0, Math.cos(a), Math.sin(a), 0, -Math.sin(a), Math.cos(a)], 9 * 13);
    d.setPose(0, p, r);
    const { matrix } = extra(d, 2);
    // Lowest point of the ellipsoid x^T x <= 1 mapped by the matrix: centre.y - |row y|.
    const e = matrix.elements;
    expect(e[13] - Math.hypot(e[1], e[5], e[9])).toBeGreaterThan(0);
  });

  it('shows rings for planted feet and glows for hands in contact only', () => {
    const dancers = [new DancerMeshes(PARENTS, 1, material(), false), new DancerMeshes(PARENTS, 1, material(), false)];
    const marks = new ContactMarks(3);
    dancers.forEach((d) => d.setPose(0, standing(), null, [0, 0]));
    marks.update(dancers);
    expect(marks.counts).toEqual({ rings: 0, glows: 0 });
    dancers[0].setPose(0, standing(), null, [1, 0.1]);
    dancers[1].setPose(0, standing(), null, [0.9, 0.95]);
    dancers[1].handContact[1] = 0.5;
    marks.update(dancers);
    expect(marks.counts).toEqual({ rings: 3, glows: 1 });
    dancers[1].setCount(0); // hidden dancers leave no marks
    marks.update(dancers);
    expect(marks.counts).toEqual({ rings: 1, glows: 0 });
  });
});

// Skinned characters (web/draw/figure.ts and SkinnedDancer).

/** Offsets of a plausible skeleton (the shipped manifest's leader, rounded). */
const OFFSETS = [
  [0, 0, 0], [0, 0.242, -0.009], [0, 0.137, -0.006], [0, 0.26, -0.026], [-0.003, 0.083, 0.014],
  [0.134, 0.203, -0.04], [0.33, -0.02, 0.006], [0.265, 0.009, 0.083],
  [-0.134, 0.203, -0.04], [-0.33, -0.02, 0.006], [-0.265, 0.009, 0.083],
  [0.103, 0.031, -0.011], [0, -0.431, 0.009], [-0.009, -0.529, -0.06],
  [-0.103, 0.031, -0.011], [0, -0.431, 0.009], [0.009, -0.529, -0.06],
];

/** A random pose by forward kinematics: world rotations (row-major) and positions from OFFSETS. */
function randomPose(seed: number): { positions: Float32Array; rotations: Float32Array } {
  let state = seed;
  const random = () => ((state = (state * 1664525 + 1013904223) >>> 0) / 2 ** 32);
  const positions = new Float32Array(51);
  const rotations = new Float32Array(153);
  const world: THREE.Matrix4[] = [];
  for (let j = 0; j < 17; j++) {
    const local = new THREE.Matrix4().makeRotationFromEuler(new THREE.Euler(random() * 2 - 1, random() * 2 - 1, random() * 2 - 1));
    const p = PARENTS[j];
    world[j] = p >= 0 ? world[p].clone().multiply(local) : local.setPosition(random(), 0.95, random());
    if (p >= 0) {
      const offset = new THREE.Vector3(...OFFSETS[j]).applyMatrix4(new THREE.Matrix4().extractRotation(world[p]));
      world[j].setPosition(new THREE.Vector3(...positions.slice(3 * p, 3 * p + 3)).add(offset));
    }
    const e = world[j].elements;
    positions.set([e[12], e[13], e[14]], 3 * j);
    // Matrix4.elements is column-major; the views' rotations are row-major.
    rotations.set([e[0], e[4], e[8], e[1], e[5], e[9], e[2], e[6], e[10]], 9 * j);
  }
  return { positions, rotations };
}

const at = (a: ArrayLike<number>, j: number) => new THREE.Vector3(a[3 * j], a[3 * j + 1], a[3 * j + 2]);

describe('buildFigure', () => {
  for (const kind of ['leader', 'follower'] as const) {
    it(`weights every vertex of the ${kind} to valid bones, summing to 1`, () => {
      const g = buildFigure(OFFSETS, PARENTS, { kind, color: 0xff0000 });
      const index = g.getAttribute('skinIndex');
      const weight = g.getAttribute('skinWeight');
      expect(index.count).toBe(g.getAttribute('position').count);
      expect(index.count).toBeLessThan(4000); // cheap: a few thousand vertices
      const used = new Set<number>();
      for (let i = 0; i < index.count; i++) {
        let sum = 0;
        for (let k = 0; k < 4; k++) {
          const b = index.getComponent(i, k), w = weight.getComponent(i, k);
          expect(b).toBeGreaterThanOrEqual(0);
          expect(b).toBeLessThan(17);
          expect(w).toBeGreaterThanOrEqual(0);
          if (w > 0) used.add(b);
          sum += w;
        }
        expect(sum).toBeCloseTo(1, 5);
      }
      expect(used.size).toBe(17); // every bone moves some of the body
      expect(g.getIndex()!.count / 3).toBeLessThan(8000);
    });
  }

  it('places the bind pose at the summed offsets (a T-pose facing +z)', () => {
    const bind = bindPositions(OFFSETS, PARENTS);
    for (let j = 1; j < 17; j++) {
      const expected = at(bind, PARENTS[j]).add(new THREE.Vector3(...OFFSETS[j]));
      expect(at(bind, j).distanceTo(expected)).toBeLessThan(1e-6);
    }
    // The mesh wraps its bones: the head's vertices are near the head joint, the hands at ±x.
    const g = buildFigure(OFFSETS, PARENTS, { kind: 'leader', color: 0x2f6fe4 });
    g.computeBoundingBox();
    const box = g.boundingBox!;
    expect(box.max.x).toBeGreaterThan(bind[3 * 7] + 0.1); // left fingers beyond the wrist
    expect(box.min.x).toBeLessThan(bind[3 * 10] - 0.1);
    expect(box.max.y).toBeGreaterThan(bind[3 * 4 + 1] + 0.08); // top of the head
    expect(box.min.y).toBeLessThan(bind[3 * 13 + 1] - 0.04); // soles below the ankles
  });
});

describe('poseBones', () => {
  for (const withRotations of [true, false]) {
    it(`puts every joint and each bone's child on the drawn positions (${withRotations ? 'rotations' : 'positions only'})`, () => {
      const bind = bindPositions(OFFSETS, PARENTS);
      const out = new Float32Array(17 * 16);
      for (let seed = 1; seed < 6; seed++) {
        const { positions, rotations } = randomPose(seed);
        // The contact layer moves positions without touching the rotations: move a wrist by 5 cm.
        positions[3 * 7] += 0.05;
        poseBones(bind, positions, withRotations ? rotations : null, out);
        for (let j = 0; j < 17; j++) {
          const m = new THREE.Matrix4().fromArray(out, 16 * j);
          expect(at(bind, j).applyMatrix4(m).distanceTo(at(positions, j))).toBeLessThan(1e-4);
          const c = PRIMARY_CHILD[j];
          if (c >= 0) expect(at(bind, c).applyMatrix4(m).distanceTo(at(positions, c))).toBeLessThan(1e-4);
          expect(m.determinant()).toBeGreaterThan(0); // never mirrored
        }
        if (withRotations) {
          // A leaf (the head) takes its rotation as it is: the face looks along the head's +z.
          const m = new THREE.Matrix4().fromArray(out, 16 * 4);
          const face = new THREE.Vector3(0, 0, 1).transformDirection(m);
          expect(face.dot(new THREE.Vector3(rotations[9 * 4 + 2], rotations[9 * 4 + 5], rotations[9 * 4 + 8]))).toBeGreaterThan(0.999);
        }
      }
    });
  }

  it('turns the skinned dancer with its joints', () => {
    const d = new SkinnedDancer(PARENTS, OFFSETS, { kind: 'follower', color: 0xe0413a }, false);
    const angle = 1.1;
    d.setPose(0, turned(standing(), angle), identityRotations(angle), [1, 0]);
    const face = new THREE.Vector3(0, 0, 1).transformDirection(d.boneMatrix(4));
    expect(face.dot(new THREE.Vector3(Math.sin(angle), 0, Math.cos(angle)))).toBeGreaterThan(0.99);
    expect(d.footContact[0]).toBe(1); // the contact state comes with the pose
    expect(d.mesh.skeleton.bones).toHaveLength(17);
  });
});
