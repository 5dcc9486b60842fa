// web/draw/avatar.ts: a VRM avatar posed from the dancer's joint rotations. The avatar is the
// tests' own (tests/e2e/vrm.mjs: other proportions than the dancers, shoulders and an upper chest
// the skeleton lacks), as VRM 1.0 (facing +z) and as VRM 0.0 (facing -z, turned by three-vrm).
// Poses come from forward kinematics on the shipped skeleton, so rotations and positions agree.

import { readFileSync } from 'node:fs';
import * as THREE from 'three';
import { describe, expect, it } from 'vitest';
import { AVATAR_BONES, Avatar } from '../../web/draw/avatar';
import { bindPositions } from '../../web/draw/figure';
import { N_JOINTS, PARENTS } from '../../web/mirror/skeleton';
// @ts-expect-error: a plain JavaScript helper of the browser tests, without types
import { makeVrm } from '../e2e/vrm.mjs';

const manifest = JSON.parse(readFileSync(new URL('../../public/models/manifest.json', import.meta.url), 'utf8'));
const OFFSETS: number[][] = manifest.skeleton.offsets.follower;
const BIND = bindPositions(OFFSETS, PARENTS);

async function avatar(version: '1.0' | '0.0'): Promise<Avatar> {
  // Without its texture: Node has no image decoder (the browser test wears the textured one).
  const bytes: Buffer = makeVrm('Test Dancer', version, { texture: false });
  const a = await Avatar.load(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength) as ArrayBuffer, 'test');
  a.fit(BIND);
  return a;
}

/** World positions and row-major world rotations from local joint rotations (forward kinematics). */
function pose(local: (j: number) => THREE.Quaternion, root = new THREE.Vector3(0, 0.95, 0)) {
  const world: THREE.Quaternion[] = [];
  const positions = new Float32Array(3 * N_JOINTS);
  const rotations = new Float32Array(9 * N_JOINTS);
  const m = new THREE.Matrix4();
  for (let j = 0; j < N_JOINTS; j++) {
    const p = PARENTS[j];
    world[j] = p < 0 ? local(j).clone() : world[p].clone().multiply(local(j));
    const at = p < 0 ? root.clone() : new THREE.Vector3(...OFFSETS[j]).applyQuaternion(world[p]).add(new THREE.Vector3(...positions.slice(3 * p, 3 * p + 3)));
    positions.set([at.x, at.y, at.z], 3 * j);
    const e = m.makeRotationFromQuaternion(world[j]).elements; // column-major
    for (let r = 0; r < 3; r++) for (let c = 0; c < 3; c++) rotations[9 * j + 3 * r + c] = e[4 * c + r];
  }
  return { positions, rotations, world };
}

const bone = (a: Avatar, name: string) => {
  const node = a.vrm.humanoid.getRawBoneNode(name as (typeof AVATAR_BONES)[number])!;
  a.group.updateMatrixWorld(true);
  return node.getWorldPosition(new THREE.Vector3());
};
const rest = () => new THREE.Quaternion();

describe.each(['1.0', '0.0'] as const)('a VRM %s avatar', (version) => {
  it('stands in the dancer T-pose with its feet where the dancer’s are', async () => {
    const a = await avatar(version);
    const { positions, rotations } = pose(rest);
    a.setPose(positions, rotations, 0);
    expect(a.measure().fitDeg).toBeLessThan(0.5);
    expect(a.measure().feetCm).toBeLessThan(3);
    // Facing +z like the dancers: the left hand at +x, the toes forward.
    expect(bone(a, 'leftHand').x).toBeGreaterThan(0.4);
    expect(bone(a, 'rightHand').x).toBeLessThan(-0.4);
    expect(bone(a, 'leftToes').z).toBeGreaterThan(bone(a, 'leftFoot').z + 0.05);
  });

  it('raises the left arm when the dancer does, not the right', async () => {
    const a = await avatar(version);
    // lShldr (joint 5) turned 80° about +z: the left arm points up.
    const up = new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 0, 1), THREE.MathUtils.degToRad(80));
    const { positions, rotations } = pose((j) => (j === 5 ? up : rest()));
    a.setPose(positions, rotations, 0);
    expect(bone(a, 'leftHand').y - bone(a, 'leftUpperArm').y).toBeGreaterThan(0.4);
    expect(Math.abs(bone(a, 'rightHand').y - bone(a, 'rightUpperArm').y)).toBeLessThan(0.02);
    expect(a.measure().fitDeg).toBeLessThan(0.5);
  });

  it('follows random poses, turned anywhere on the floor: bones and twists', async () => {
    const a = await avatar(version);
    let seed = 7;
    const random = () => ((seed = (seed * 16807) % 2147483647) / 2147483647) * 2 - 1;
    for (let trial = 0; trial < 20; trial++) {
      const locals = Array.from({ length: N_JOINTS }, (_, j) =>
        new THREE.Quaternion().setFromEuler(new THREE.Euler(random() * 0.8, j === 0 ? random() * Math.PI : random() * 0.8, random() * 0.8)));
      const { positions, rotations, world } = pose((j) => locals[j], new THREE.Vector3(random(), 0.9, random()));
      a.setPose(positions, rotations, 1 / 30);
      expect(a.measure().fitDeg).toBeLessThan(0.5);
      // Twist too: the head and the hands turn as the dancer's (their rest frames are the identity
      // in both rigs, and neither rig points them at a child), so their world rotations agree.
      for (const [j, name] of [[4, 'head'], [7, 'leftHand'], [10, 'rightHand']] as const) {
        const turned = a.vrm.humanoid.getRawBoneNode(name)!.getWorldQuaternion(new THREE.Quaternion());
        const restTurn = version === '0.0' ? new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 1, 0), Math.PI) : rest();
        expect(THREE.MathUtils.radToDeg(turned.angleTo(world[j].clone().multiply(restTurn)))).toBeLessThan(1);
      }
    }
  });
});

describe('files that are not avatars', () => {
  it('says what is wrong', async () => {
    await expect(Avatar.load(new TextEncoder().encode('HIERARCHY').buffer as ArrayBuffer, 'x')).rejects.toThrow(/not a VRM avatar/);
  });
});
