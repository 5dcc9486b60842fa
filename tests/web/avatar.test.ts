// web/draw/avatar.ts: a VRM avatar posed from the dancer's joint rotations. The avatar is the
// tests' own (tests/e2e/vrm.mjs: other proportions than the dancers, shoulders and an upper chest
// the skeleton lacks), as VRM 1.0 (facing +z) and as VRM 0.0 (facing -z, turned by three-vrm).
// Poses come from forward kinematics on the shipped skeleton, so rotations and positions agree.

import { readFileSync } from 'node:fs';
import * as THREE from 'three';
import { describe, expect, it } from 'vitest';
import { AVATAR_BONES, Avatar, AvatarError, checkGlb } from '../../web/draw/avatar';
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
    await expect(Avatar.load(new ArrayBuffer(0), 'x')).rejects.toThrow(/The file is empty/);
  });
});

/** A Node Buffer's bytes as an ArrayBuffer of their own. */
const own = (bytes: Uint8Array) => bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength) as ArrayBuffer;
/** The message checkGlb gives, thin spaces as plain ones; '' when it passes. */
function problem(bytes: Uint8Array): string {
  try {
    checkGlb(own(bytes));
  } catch (error) {
    expect(error).toBeInstanceOf(AvatarError);
    return (error as Error).message.replace(/\u202f/g, ' ');
  }
  return '';
}
/** The test avatar with its JSON chunk edited (and the GLB's lengths written to match). */
function withJson(edit: (gltf: Record<string, any>) => void): Buffer {
  const glb: Buffer = makeVrm('Test Dancer', '1.0');
  const jsonLength = glb.readUInt32LE(12);
  const gltf = JSON.parse(glb.subarray(20, 20 + jsonLength).toString());
  edit(gltf);
  let json = Buffer.from(JSON.stringify(gltf));
  json = Buffer.concat([json, Buffer.alloc((4 - (json.length % 4)) % 4, 0x20)]);
  const rest = glb.subarray(20 + jsonLength);
  const head = Buffer.alloc(20);
  head.write('glTF', 0, 'ascii');
  head.writeUInt32LE(2, 4);
  head.writeUInt32LE(20 + json.length + rest.length, 8);
  head.writeUInt32LE(json.length, 12);
  head.write('JSON', 16, 'ascii');
  return Buffer.concat([head, json, rest]);
}

describe('a damaged avatar file (checkGlb)', () => {
  const glb: Buffer = makeVrm('Test Dancer', '1.0');
  const total = glb.length;
  const grouped = (n: number) => n.toLocaleString('en-US').replace(/,/g, ' ');

  it('passes the intact test avatars, VRM 1.0 and 0.x, with and without their texture', () => {
    for (const version of ['1.0', '0.0']) for (const texture of [true, false]) expect(problem(makeVrm('x', version, { texture }))).toBe('');
  });

  it('cut short anywhere: "the file is cut short: N of M bytes", the length its header states', async () => {
    // Inside the JSON chunk (the glTF loader said "Invalid typed array length: 240"), at its end,
    // inside the binary chunk, and one byte short.
    const jsonEnd = 20 + glb.readUInt32LE(12);
    for (const cut of [240, jsonEnd, jsonEnd + 100, 20_000, total - 1]) {
      expect(problem(glb.subarray(0, cut))).toBe(`The file is cut short: ${grouped(cut)} of ${grouped(total)} bytes. Download or export it again.`);
    }
    // The same through Avatar.load, as the page reads a dropped file.
    await expect(Avatar.load(own(glb.subarray(0, 20_000)), 'x')).rejects.toThrow(`The file is cut short: 20\u202f000 of ${grouped(total).replace(' ', '\u202f')} bytes`);
    expect(problem(glb.subarray(0, 8))).toMatch(/^The file is cut short: 8 bytes, less than its 12-byte header/);
  });

  it('other damage is named too, never in the glTF reader\'s own words', () => {
    const v1 = Buffer.from(glb);
    v1.writeUInt32LE(1, 4);
    expect(problem(v1)).toMatch(/glTF 1\.0 model.*VRM avatars are glTF 2\.0 files/);
    const badJson = Buffer.from(glb);
    badJson.write('}', 20, 'ascii');
    expect(problem(badJson)).toMatch(/damaged: the description of the model \(its JSON chunk\) is not readable JSON/);
    const longBin = Buffer.from(glb);
    const binAt = 20 + glb.readUInt32LE(12);
    longBin.writeUInt32LE(glb.readUInt32LE(binAt) + 1000, binAt);
    expect(problem(longBin)).toMatch(/damaged: its data \(the BIN chunk\) is said to end at byte/);
    expect(problem(withJson((g) => (g.accessors[0].count *= 2)))).toMatch(/damaged: accessor 0 reads .* bytes of part 0 of the data, which holds/);
    expect(problem(withJson((g) => (g.bufferViews[2].byteOffset += 1e6)))).toMatch(/damaged: part 2 of its data \(buffer view 2\) ends at byte/);
    expect(problem(withJson((g) => (g.buffers[0].uri = 'body.bin')))).toMatch(/separate file \("body\.bin"\).*one \.vrm file/);
    expect(problem(withJson((g) => (g.extensionsRequired = ['KHR_draco_mesh_compression'])))).toMatch(/compressed meshes \(Draco\).*cannot read/);
  });
});
