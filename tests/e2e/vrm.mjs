// A small VRM avatar (1.0, or 0.0) written from scratch for the tests (tests/e2e/avatar.test.mjs,
// tests/web/avatar.test.ts): one box per humanoid bone, skinned rigidly to it, in a T-pose, with
// proportions unlike the dancers' (shorter legs and arms) and the bones the dancers lack (upper
// chest, shoulders, toes), so that retargeting has something to get wrong. A .vrm is a binary
// glTF (GLB) whose VRMC_vrm extension (VRM 0.0: VRM) names the humanoid bones
// (https://github.com/vrm-c/vrm-specification).
//
// Like nearly every real avatar (VRoid Studio, Blender's VRM add-on, UniVRM), it is textured: a
// small PNG stored in the GLB's binary chunk, worn by an MToon material (VRMC_materials_mtoon for
// 1.0, the VRM extension's materialProperties for 0.0) on a white base colour, so the avatar is
// drawn green only when the texture loads, and plain white when it does not.

import { deflateSync } from 'node:zlib';

/** The texture's one colour (sRGB bytes): a green nothing else on the page has. */
export const TEXTURE_RGB = [40, 170, 80];

const CRC_TABLE = Array.from({ length: 256 }, (_, n) => {
  let c = n;
  for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
  return c >>> 0;
});
function crc32(bytes) {
  let c = 0xffffffff;
  for (const b of bytes) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

/** A `size` × `size` PNG (8-bit RGB) of one colour. */
export function solidPng([r, g, b], size = 8) {
  const chunk = (type, data) => {
    const head = Buffer.alloc(8);
    head.writeUInt32BE(data.length, 0);
    head.write(type, 4, 'ascii');
    const crc = Buffer.alloc(4);
    crc.writeUInt32BE(crc32(Buffer.concat([head.subarray(4), data])), 0);
    return Buffer.concat([head, data, crc]);
  };
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(size, 0);
  ihdr.writeUInt32BE(size, 4);
  ihdr.set([8, 2, 0, 0, 0], 8); // 8 bits per channel, RGB, deflate, no filter method, not interlaced
  const row = Buffer.from([0, ...Array.from({ length: size }, () => [r, g, b]).flat()]); // filter byte 0, then pixels
  const pixels = Buffer.concat(Array.from({ length: size }, () => row));
  return Buffer.concat([
    Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
    chunk('IHDR', ihdr), chunk('IDAT', deflateSync(pixels)), chunk('IEND', Buffer.alloc(0)),
  ]);
}

/** [bone, parent, offset from the parent in metres]; the right side mirrors the left. */
const LEFT = [
  ['leftShoulder', 'upperChest', [0.03, 0.09, 0]],
  ['leftUpperArm', 'leftShoulder', [0.1, 0, 0]],
  ['leftLowerArm', 'leftUpperArm', [0.27, 0, 0]],
  ['leftHand', 'leftLowerArm', [0.24, 0, 0]],
  ['leftUpperLeg', 'hips', [0.09, -0.06, 0]],
  ['leftLowerLeg', 'leftUpperLeg', [0, -0.4, 0]],
  ['leftFoot', 'leftLowerLeg', [0, -0.41, 0]],
  ['leftToes', 'leftFoot', [0, -0.05, 0.12]],
];
export const BONES = [
  ['hips', null, [0, 0.9, 0]],
  ['spine', 'hips', [0, 0.1, 0]],
  ['chest', 'spine', [0, 0.14, 0]],
  ['upperChest', 'chest', [0, 0.12, 0]],
  ['neck', 'upperChest', [0, 0.14, 0]],
  ['head', 'neck', [0, 0.1, 0]],
  ...LEFT,
  ...LEFT.map(([bone, parent, [x, y, z]]) => [bone.replace('left', 'right'), parent.replace('left', 'right'), [-x, y, z]]),
];

/**
 * The GLB bytes of the test avatar. `version` '0.0' writes the older VRM extension, whose avatars
 * face -z in glTF's axes (their left side at -x); '1.0' faces +z. `texture: false` leaves the
 * texture out (a plain green material): Node, where the unit tests run, has no image decoder.
 */
export function makeVrm(name = 'Test Dancer', version = '1.0', { texture = true } = {}) {
  const v0 = version === '0.0';
  const index = new Map(BONES.map(([bone], i) => [bone, i]));
  const offsets = BONES.map(([, , [x, y, z]]) => (v0 ? [-x, y, -z] : [x, y, z]));
  const world = [];
  for (const [b, [, parent]] of BONES.entries()) {
    const offset = offsets[b];
    const base = parent ? world[index.get(parent)] : [0, 0, 0];
    world.push(offset.map((v, k) => v + base[k]));
  }
  // One box per bone, from the bone to its first child (or a small cube at the end bones).
  const positions = [], normals = [], uvs = [], joints = [], weights = [], indices = [];
  BONES.forEach(([bone], b) => {
    const child = BONES.findIndex(([, parent]) => parent === bone);
    const from = world[b], to = child >= 0 ? world[child] : world[b].map((v, k) => v + (k === 1 ? 0.08 : 0));
    const half = 0.035;
    const lo = from.map((v, k) => Math.min(v, to[k]) - half), hi = from.map((v, k) => Math.max(v, to[k]) + half);
    const corner = (x, y, z) => [x ? hi[0] : lo[0], y ? hi[1] : lo[1], z ? hi[2] : lo[2]];
    // Six faces, four vertices each (flat normals).
    const faces = [
      [[1, 0, 0], [[1, 0, 0], [1, 1, 0], [1, 1, 1], [1, 0, 1]]],
      [[-1, 0, 0], [[0, 0, 1], [0, 1, 1], [0, 1, 0], [0, 0, 0]]],
      [[0, 1, 0], [[0, 1, 0], [0, 1, 1], [1, 1, 1], [1, 1, 0]]],
      [[0, -1, 0], [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]]],
      [[0, 0, 1], [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]],
      [[0, 0, -1], [[0, 1, 0], [1, 1, 0], [1, 0, 0], [0, 0, 0]]],
    ];
    for (const [normal, quad] of faces) {
      const first = positions.length / 3;
      quad.forEach((c, k) => {
        positions.push(...corner(...c));
        normals.push(...normal);
        uvs.push(k === 1 || k === 2 ? 1 : 0, k >= 2 ? 1 : 0);
        joints.push(b, 0, 0, 0);
        weights.push(1, 0, 0, 0);
      });
      indices.push(first, first + 1, first + 2, first, first + 2, first + 3);
    }
  });
  const inverseBind = world.flatMap(([x, y, z]) => [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -x, -y, -z, 1]);

  // The binary chunk: each array in its own 4-byte-aligned view, the PNG last.
  const arrays = [
    new Float32Array(positions), new Float32Array(normals), new Uint16Array(joints), new Float32Array(weights),
    new Uint16Array(indices), new Float32Array(inverseBind), new Float32Array(uvs),
  ];
  if (texture) arrays.push(solidPng(TEXTURE_RGB));
  const views = [];
  let length = 0;
  for (const a of arrays) {
    views.push({ buffer: 0, byteOffset: length, byteLength: a.byteLength });
    length += Math.ceil(a.byteLength / 4) * 4;
  }
  const bin = Buffer.alloc(length);
  arrays.forEach((a, i) => Buffer.from(a.buffer, a.byteOffset, a.byteLength).copy(bin, views[i].byteOffset));
  const min = [0, 1, 2].map((k) => Math.min(...positions.filter((_, i) => i % 3 === k)));
  const max = [0, 1, 2].map((k) => Math.max(...positions.filter((_, i) => i % 3 === k)));
  const vertexCount = positions.length / 3;

  const nodes = BONES.map(([bone], b) => {
    const children = BONES.flatMap(([, parent], c) => (parent === bone ? [c] : []));
    return { name: bone, translation: offsets[b], ...(children.length ? { children } : {}) };
  });
  nodes.push({ name: 'body', mesh: 0, skin: 0 });
  // The material. Textured: white MToon whose lit and shaded colours both come from the texture
  // (as VRoid Studio's avatars are); plain: glTF's own material in green.
  const mtoon = { shadeColor: [0.75, 0.75, 0.75], toony: 0.9, shift: 0 };
  const material = texture
    ? {
      name: 'textured',
      pbrMetallicRoughness: { baseColorFactor: [1, 1, 1, 1], baseColorTexture: { index: 0 }, metallicFactor: 0, roughnessFactor: 1 },
      ...(v0 ? {} : {
        extensions: {
          VRMC_materials_mtoon: {
            specVersion: '1.0', shadeColorFactor: mtoon.shadeColor, shadeMultiplyTexture: { index: 0 },
            shadingToonyFactor: mtoon.toony, shadingShiftFactor: mtoon.shift,
          },
        },
      }),
    }
    : { name: 'green', pbrMetallicRoughness: { baseColorFactor: [0.2, 0.65, 0.3, 1], metallicFactor: 0, roughnessFactor: 0.8 } };
  const materialProperties = texture
    ? [{
      name: 'textured', shader: 'VRM/MToon', renderQueue: 2000, keywordMap: {}, tagMap: { RenderType: 'Opaque' },
      textureProperties: { _MainTex: 0, _ShadeTexture: 0 },
      vectorProperties: { _Color: [1, 1, 1, 1], _ShadeColor: [...mtoon.shadeColor, 1] },
      floatProperties: { _ShadeToony: mtoon.toony, _ShadeShift: mtoon.shift },
    }]
    : [{ name: 'green', shader: 'VRM_USE_GLTFSHADER' }];

  const gltf = {
    asset: { version: '2.0', generator: 'duet tests/e2e/vrm.mjs' },
    extensionsUsed: [v0 ? 'VRM' : 'VRMC_vrm', ...(texture && !v0 ? ['VRMC_materials_mtoon'] : [])],
    extensions: v0 ? {
      VRM: {
        exporterVersion: 'duet tests', specVersion: '0.0',
        meta: {
          title: name, version: '1', author: 'duet tests', allowedUserName: 'OnlyAuthor', violentUssageName: 'Disallow',
          sexualUssageName: 'Disallow', commercialUssageName: 'Disallow', licenseName: 'Redistribution_Prohibited',
        },
        humanoid: { humanBones: BONES.map(([bone], b) => ({ bone, node: b, useDefaultValues: true })) },
        materialProperties,
      },
    } : {
      VRMC_vrm: {
        specVersion: '1.0',
        meta: {
          name, version: '1', authors: ['duet tests'], licenseUrl: 'https://vrm.dev/licenses/1.0/',
          avatarPermission: 'onlyAuthor', commercialUsage: 'personalNonProfit', creditNotation: 'required',
          allowRedistribution: false, modification: 'prohibited',
        },
        humanoid: { humanBones: Object.fromEntries(BONES.map(([bone], b) => [bone, { node: b }])) },
      },
    },
    scene: 0,
    scenes: [{ nodes: [0, BONES.length] }],
    nodes,
    meshes: [{ primitives: [{ attributes: { POSITION: 0, NORMAL: 1, TEXCOORD_0: 6, JOINTS_0: 2, WEIGHTS_0: 3 }, indices: 4, material: 0 }] }],
    skins: [{ joints: BONES.map((_, b) => b), inverseBindMatrices: 5, skeleton: 0 }],
    materials: [material],
    ...(texture ? {
      textures: [{ source: 0, sampler: 0 }],
      samplers: [{ magFilter: 9729, minFilter: 9729 }], // linear
      images: [{ name: 'green', bufferView: 7, mimeType: 'image/png' }],
    } : {}),
    accessors: [
      { bufferView: 0, componentType: 5126, count: vertexCount, type: 'VEC3', min, max },
      { bufferView: 1, componentType: 5126, count: vertexCount, type: 'VEC3' },
      { bufferView: 2, componentType: 5123, count: vertexCount, type: 'VEC4' },
      { bufferView: 3, componentType: 5126, count: vertexCount, type: 'VEC4' },
      { bufferView: 4, componentType: 5123, count: indices.length, type: 'SCALAR' },
      { bufferView: 5, componentType: 5126, count: BONES.length, type: 'MAT4' },
      { bufferView: 6, componentType: 5126, count: vertexCount, type: 'VEC2' },
    ],
    bufferViews: views,
    buffers: [{ byteLength: length }],
  };

  let json = Buffer.from(JSON.stringify(gltf));
  json = Buffer.concat([json, Buffer.alloc((4 - (json.length % 4)) % 4, 0x20)]);
  const header = Buffer.alloc(12);
  header.write('glTF', 0, 'ascii');
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + 8 + json.length + 8 + bin.length, 8);
  const chunk = (type, data) => {
    const head = Buffer.alloc(8);
    head.writeUInt32LE(data.length, 0);
    head.write(type, 4, 'ascii');
    return Buffer.concat([head, data]);
  };
  return Buffer.concat([header, chunk('JSON', json), chunk('BIN\0', bin)]);
}
