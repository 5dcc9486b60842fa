// A VRM avatar worn by a dancer: a .vrm file dropped on the page (web/ui/main.ts) replaces that
// dancer's drawn body; the simulation, the contact marks and the skeleton overlay stay the
// dancer's own. Loaded only when a file is dropped (this module and @pixiv/three-vrm are a chunk
// of their own), so the first visit downloads none of it.
//
// Retargeting. Both rigs rest in a T-pose facing +z with y up: the dancers' skeleton (the BVH
// rest pose, every joint rotation the identity; its left side at +x) and a VRM's normalized
// humanoid (three-vrm's rig in which every bone rests at the identity, for VRM 0.x and 1.0
// alike). A dancer's world rotation G_j therefore carries over to the avatar's bone almost as it
// is: H_j = G_j · A_j, where A_j turns the avatar's rest bone direction onto the skeleton's (the
// two T-poses differ: the dancers' forearms, for one, point 17° forward of a straight arm in the
// manifest's offsets). Then, as the skinned body does (figure.ts), the
// bone is swung onto the direction the dancer's joint positions actually take (the contact layer
// and the foot fixes move positions, not rotations). Each normalized bone gets its local rotation
// from its nearest posed ancestor; bones the skeleton lacks (shoulders, upper chest, toes,
// fingers) stay at rest. The avatar keeps its own size: its hips go where the dancer's are, at
// the height scaled by the ratio of the two leg lengths, so its feet meet the floor.

import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { type VRM, type VRMHumanBoneName, VRMLoaderPlugin, VRMUtils } from '@pixiv/three-vrm';
import { FEET, JOINT_NAMES, N_JOINTS, POSITIONS_SIZE } from '../mirror/skeleton';
import { PRIMARY_CHILD, jointRotation } from './figure';

/** The VRM humanoid bone each skeleton joint drives. */
const BONE_OF: Record<(typeof JOINT_NAMES)[number], VRMHumanBoneName> = {
  hip: 'hips', abdomen: 'spine', chest: 'chest', neck: 'neck', head: 'head',
  lShldr: 'leftUpperArm', lForeArm: 'leftLowerArm', lHand: 'leftHand',
  rShldr: 'rightUpperArm', rForeArm: 'rightLowerArm', rHand: 'rightHand',
  lThigh: 'leftUpperLeg', lShin: 'leftLowerLeg', lFoot: 'leftFoot',
  rThigh: 'rightUpperLeg', rShin: 'rightLowerLeg', rFoot: 'rightFoot',
};
/** The same, by joint index. */
export const AVATAR_BONES: readonly VRMHumanBoneName[] = JOINT_NAMES.map((name) => BONE_OF[name]);
const joint = (name: (typeof JOINT_NAMES)[number]) => JOINT_NAMES.indexOf(name);
const L_THIGH = joint('lThigh'), L_SHIN = joint('lShin'), L_FOOT = joint('lFoot'), R_THIGH = joint('rThigh');

/** Joint j of a 17 × 3 position array into `out`. */
function jointAt(positions: ArrayLike<number>, j: number, out: THREE.Vector3): THREE.Vector3 {
  return out.set(positions[3 * j], positions[3 * j + 1], positions[3 * j + 2]);
}

/** Why a file cannot be worn, in words for the page's message. */
export class AvatarError extends Error {}

/** A whole number with its thousands apart (narrow no-break spaces): 192 232. */
const count = (n: number) => Math.round(n).toString().replace(/\B(?=(\d{3})+(?!\d))/g, '\u202f');

const GLB_HEADER = 12;
const CHUNK_HEADER = 8;
const JSON_CHUNK = 0x4e4f534a; // "JSON", little-endian
const BIN_CHUNK = 0x004e4942; // "BIN\0"
/** Bytes per component of an accessor's componentType, and components per element of its type. */
const COMPONENT_BYTES: Record<number, number> = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 };
const COMPONENTS: Record<string, number> = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };
/** Extensions the page's glTF loader has no decoder for, as a visitor would name what they do. */
const UNREADABLE: Record<string, string> = {
  KHR_draco_mesh_compression: 'compressed meshes (Draco)',
  EXT_meshopt_compression: 'compressed meshes (meshopt)',
  KHR_meshopt_compression: 'compressed meshes (meshopt)',
  KHR_texture_basisu: 'compressed textures (KTX2)',
};

interface GltfJson {
  extensionsRequired?: string[];
  buffers?: { byteLength?: number; uri?: string }[];
  bufferViews?: { buffer?: number; byteOffset?: number; byteLength?: number }[];
  accessors?: { bufferView?: number; byteOffset?: number; componentType?: number; type?: string; count?: number }[];
}

/**
 * Check a .vrm file's bytes as a binary glTF (GLB: a 12-byte header stating the file's length,
 * then a JSON chunk describing the model and a BIN chunk holding its data) before the glTF loader
 * reads them; an AvatarError says in plain words what is wrong. The loader's own errors on such
 * files are about its internals ("Invalid typed array length: 240" for a file cut short).
 */
export function checkGlb(bytes: ArrayBuffer): void {
  const size = bytes.byteLength;
  if (size === 0) throw new AvatarError('The file is empty. Choose a .vrm avatar file.');
  const magic = String.fromCharCode(...new Uint8Array(bytes, 0, Math.min(4, size)));
  if (magic !== 'glTF') throw new AvatarError('This is not a VRM avatar (a .vrm file is a binary glTF, starting with "glTF").');
  const again = 'Download or export it again.';
  if (size < GLB_HEADER) throw new AvatarError(`The file is cut short: ${size} bytes, less than its ${GLB_HEADER}-byte header. ${again}`);
  const view = new DataView(bytes);
  const version = view.getUint32(4, true);
  if (version !== 2) {
    throw new AvatarError(version === 1
      ? 'This is a glTF 1.0 model, older than VRM; VRM avatars are glTF 2.0 files. Export it again as VRM.'
      : `The file says it is binary glTF version ${version}; VRM avatars are glTF 2.0 files.`);
  }
  const length = view.getUint32(8, true);
  if (length > size) throw new AvatarError(`The file is cut short: ${count(size)} of ${count(length)} bytes. ${again}`);
  const damaged = (what: string) => new AvatarError(`The file is damaged: ${what}. ${again}`);
  // The chunks, as the loader walks them: the JSON chunk (the description of the model) first, then
  // the BIN chunk (its data), if any; chunks of other types are skipped.
  let jsonAt = -1, jsonLength = 0, binLength = -1;
  for (let at = GLB_HEADER; at < length;) {
    if (at + CHUNK_HEADER > length) throw damaged(`its last part is cut off at byte ${count(length)}`);
    const chunkLength = view.getUint32(at, true), type = view.getUint32(at + 4, true);
    const end = at + CHUNK_HEADER + chunkLength;
    if (at === GLB_HEADER && type !== JSON_CHUNK) throw damaged('the description of the model (its JSON chunk) does not follow the header');
    const what = type === JSON_CHUNK ? 'the description of the model (its JSON chunk)' : type === BIN_CHUNK ? 'its data (the BIN chunk)' : 'a part of it';
    if (end > length) throw damaged(`${what} is said to end at byte ${count(end)}, past the file's ${count(length)}`);
    if (type === JSON_CHUNK && jsonAt < 0) [jsonAt, jsonLength] = [at + CHUNK_HEADER, chunkLength];
    else if (type === BIN_CHUNK && binLength < 0) binLength = chunkLength;
    at = end;
  }
  if (jsonAt < 0) throw damaged('the description of the model (its JSON chunk) is missing');
  binLength = Math.max(0, binLength);
  let json: GltfJson;
  try {
    json = JSON.parse(new TextDecoder().decode(new Uint8Array(bytes, jsonAt, jsonLength)));
  } catch {
    throw damaged('the description of the model (its JSON chunk) is not readable JSON');
  }
  if (typeof json !== 'object' || json === null) throw damaged('the description of the model (its JSON chunk) is not a glTF description');
  for (const extension of json.extensionsRequired ?? []) {
    if (UNREADABLE[extension]) {
      throw new AvatarError(`The avatar uses ${UNREADABLE[extension]} (${extension}), which this page cannot read. Export it without compression.`);
    }
  }
  const buffers = json.buffers ?? [];
  buffers.forEach((buffer, b) => {
    if (buffer.uri !== undefined && !buffer.uri.startsWith('data:')) {
      throw new AvatarError(`The avatar's data is in a separate file ("${buffer.uri.slice(0, 60)}"); a .vrm holds everything in one file. Export it as one .vrm file.`);
    }
    if (b === 0 && buffer.uri === undefined && (buffer.byteLength ?? 0) > binLength) {
      throw damaged(`its data should be ${count(buffer.byteLength ?? 0)} bytes, and the file holds ${count(binLength)}`);
    }
  });
  const views = json.bufferViews ?? [];
  views.forEach((v, i) => {
    const end = (v.byteOffset ?? 0) + (v.byteLength ?? 0);
    const buffer = buffers[v.buffer ?? 0];
    if (!buffer) throw damaged(`part ${i} of its data (buffer view ${i}) belongs to no buffer`);
    if (buffer.uri === undefined && end > binLength) {
      throw damaged(`part ${i} of its data (buffer view ${i}) ends at byte ${count(end)} of data that holds ${count(binLength)}`);
    }
  });
  (json.accessors ?? []).forEach((a, i) => {
    if (a.bufferView === undefined) return;
    const v = views[a.bufferView];
    if (!v) throw damaged(`accessor ${i} reads part ${a.bufferView} of the data, which the file does not have`);
    // The least an accessor reads (tightly packed; strides and padding only add to it).
    const need = (a.byteOffset ?? 0) + (a.count ?? 0) * (COMPONENT_BYTES[a.componentType ?? 0] ?? 1) * (COMPONENTS[a.type ?? ''] ?? 1);
    if (need > (v.byteLength ?? 0)) {
      throw damaged(`accessor ${i} reads ${count(need)} bytes of part ${a.bufferView} of the data, which holds ${count(v.byteLength ?? 0)}`);
    }
  });
}

/** A glTF loader error in words for a visitor; the loader's own words after them. */
function loaderProblem(error: unknown): string {
  const message = String((error as Error)?.message || error).replace(/^THREE\.GLTFLoader: /, '');
  return `The file could not be read as a VRM avatar: it may be damaged, or use a part of glTF this page cannot read (the glTF reader says: "${message}").`;
}

const _q = new THREE.Quaternion();
const _swing = new THREE.Quaternion();
const _m = new THREE.Matrix4();
const _w = new THREE.Vector3();
const _u = new THREE.Vector3();
const _v = new THREE.Vector3();
const _p = new THREE.Vector3();

export class Avatar {
  /** What the stage draws in the dancer's place. */
  readonly group = new THREE.Group();
  private readonly nodes: (THREE.Object3D | null)[];
  private readonly raw: (THREE.Object3D | null)[];
  /** Per joint: the joint whose position the bone points at (the nearest one the avatar has too). */
  private readonly target: number[];
  /** Per joint: the nearest ancestor joint the avatar has (-1 for the hips). */
  private readonly parent: number[];
  /** The avatar's rest bone directions, in the group's frame. */
  private readonly restDirection: THREE.Vector3[];
  /** A_j, set by fit(). */
  private readonly align: THREE.Quaternion[];
  /** H_j of the last pose. */
  private readonly world: THREE.Quaternion[];
  /** The rig root's rotation in the group's frame (a half turn for VRM 0.x after rotateVRM0). */
  private readonly rigRotation = new THREE.Quaternion();
  private readonly rigInverse = new THREE.Quaternion();
  private readonly rigRootInverse = new THREE.Matrix4();
  private readonly restHips = new THREE.Vector3();
  private readonly restLegs = new THREE.Vector3();
  private readonly avatarLeg: number;
  private scale = 1;
  /** The dancer's joint positions of the last pose, for measure(). */
  private readonly posed = new Float32Array(POSITIONS_SIZE);

  private constructor(readonly vrm: VRM, readonly name: string) {
    const { humanoid } = vrm;
    this.group.add(vrm.scene);
    this.nodes = AVATAR_BONES.map((b) => humanoid.getNormalizedBoneNode(b));
    this.raw = AVATAR_BONES.map((b) => humanoid.getRawBoneNode(b));
    const has = (j: number) => j >= 0 && this.nodes[j] !== null;
    this.target = AVATAR_BONES.map((_, j) => {
      let t = PRIMARY_CHILD[j];
      while (t >= 0 && !has(t)) t = PRIMARY_CHILD[t];
      return t;
    });
    this.parent = AVATAR_BONES.map((_, j) => {
      const mine = this.nodes[j];
      for (let node = mine?.parent ?? null; node; node = node.parent) {
        const k = this.nodes.indexOf(node);
        if (k >= 0) return k;
      }
      return -1;
    });

    // The rest pose, measured in the group's frame.
    humanoid.resetNormalizedPose();
    this.group.updateMatrixWorld(true);
    const rest = this.nodes.map((n) => (n ? n.getWorldPosition(new THREE.Vector3()) : null));
    this.restDirection = AVATAR_BONES.map((_, j) => {
      const t = this.target[j];
      return rest[j] && t >= 0 && rest[t] ? rest[t]!.clone().sub(rest[j]!).normalize() : new THREE.Vector3();
    });
    const rigRoot = humanoid.normalizedHumanBonesRoot;
    rigRoot.getWorldQuaternion(this.rigRotation);
    this.rigInverse.copy(this.rigRotation).invert();
    this.rigRootInverse.copy(rigRoot.matrixWorld).invert();
    const node = (b: VRMHumanBoneName) => humanoid.getNormalizedBoneNode(b)!.getWorldPosition(new THREE.Vector3());
    this.restHips.copy(node('hips'));
    this.restLegs.copy(node('leftUpperLeg')).add(node('rightUpperLeg')).multiplyScalar(0.5);
    this.avatarLeg = node('leftUpperLeg').distanceTo(node('leftLowerLeg')) + node('leftLowerLeg').distanceTo(node('leftFoot'));
    this.align = AVATAR_BONES.map(() => new THREE.Quaternion());
    this.world = AVATAR_BONES.map(() => new THREE.Quaternion());
  }

  /** Read a .vrm (VRM 0.x or 1.0) file's bytes; an AvatarError says why it cannot be worn. */
  static async load(bytes: ArrayBuffer, name: string): Promise<Avatar> {
    checkGlb(bytes);
    const loader = new GLTFLoader();
    loader.register((parser) => new VRMLoaderPlugin(parser));
    let vrm: VRM | undefined;
    try {
      const gltf = await loader.parseAsync(bytes, '');
      vrm = gltf.userData.vrm as VRM | undefined;
    } catch (error) {
      throw new AvatarError(loaderProblem(error));
    }
    if (!vrm) throw new AvatarError('The file is a 3D model but not a VRM avatar (it has no humanoid bones).');
    for (const bone of AVATAR_BONES) {
      // The skeleton's spine joints may be missing from an avatar (VRM requires only some bones).
      if (!vrm.humanoid.getNormalizedBoneNode(bone) && !['chest', 'neck'].includes(bone)) {
        throw new AvatarError(`The avatar has no "${bone}" bone; a dancer needs hips, spine, head, arms, hands, legs and feet.`);
      }
    }
    VRMUtils.rotateVRM0(vrm); // VRM 0.x avatars face -z: turn them to face +z as VRM 1.0 ones do
    VRMUtils.combineSkeletons(vrm.scene); // fewer bone textures to upload per frame
    vrm.scene.traverse((object) => {
      object.frustumCulled = false; // the avatar moves anywhere; its rest bounds would cull it
      if ((object as THREE.Mesh).isMesh) object.castShadow = true;
    });
    return new Avatar(vrm, name);
  }

  /**
   * Fit to a dancer's rest pose (bind: 17 joint positions, the skeleton's T-pose): the rest
   * alignment A_j and the height scale.
   */
  fit(bind: ArrayLike<number>): void {
    for (let j = 0; j < N_JOINTS; j++) {
      const t = this.target[j];
      this.align[j].identity();
      if (t < 0 || this.restDirection[j].lengthSq() === 0) continue;
      jointAt(bind, t, _u).sub(jointAt(bind, j, _v)).normalize();
      this.align[j].setFromUnitVectors(this.restDirection[j], _u);
    }
    const ourLeg = jointAt(bind, L_SHIN, _u).distanceTo(jointAt(bind, L_THIGH, _v)) + jointAt(bind, L_FOOT, _u).distanceTo(jointAt(bind, L_SHIN, _v));
    this.scale = ourLeg > 1e-6 ? this.avatarLeg / ourLeg : 1;
  }

  /**
   * Pose the avatar from 17 world joint positions and rotations (row-major 3×3, as the simulation
   * gives them); `dt` advances the avatar's own motion (spring bones: hair, skirts).
   */
  setPose(positions: ArrayLike<number>, rotations: ArrayLike<number>, dt: number): void {
    for (let j = 0; j < N_JOINTS; j++) {
      const node = this.nodes[j];
      if (!node) continue;
      const h = this.world[j].setFromRotationMatrix(jointRotation(rotations, j, _m)).multiply(this.align[j]);
      const t = this.target[j];
      if (t >= 0) {
        // Swing the bone onto where the dancer's joints are.
        _u.copy(this.restDirection[j]).applyQuaternion(h);
        jointAt(positions, t, _v).sub(jointAt(positions, j, _p));
        if (_v.lengthSq() > 1e-12) h.premultiply(_swing.setFromUnitVectors(_u, _v.normalize()));
      }
      const p = this.parent[j];
      // local = S⁻¹ · H_parent⁻¹ · H_j · S (S: the rig root's rotation; H of the hips' parent is 1)
      _q.copy(this.rigInverse);
      if (p >= 0) _q.multiply(_swing.copy(this.world[p]).invert());
      node.quaternion.copy(_q.multiply(h).multiply(this.rigRotation));
    }
    // The hips: the avatar's hip joints (the legs' tops) where the dancer's are, scaled in height.
    jointAt(positions, L_THIGH, _u).add(jointAt(positions, R_THIGH, _v)).multiplyScalar(0.5);
    _u.y *= this.scale;
    _v.copy(this.restHips).sub(this.restLegs).applyQuaternion(this.world[0]);
    this.nodes[0]!.position.copy(_u.add(_v).applyMatrix4(this.rigRootInverse));
    this.vrm.update(dt);
    this.posed.set(positions);
  }

  /**
   * How well the last pose fits the dancer, as drawn: the worst angle, degrees, between an avatar
   * bone and the dancer's, and how far, cm, its ankles are from the dancer's ankle heights scaled
   * to its size. For tests (window.duet.avatars): not computed per frame.
   */
  measure(): { fitDeg: number; feetCm: number } {
    const positions = this.posed;
    this.group.updateMatrixWorld(true);
    let worst = 0;
    for (let j = 0; j < N_JOINTS; j++) {
      const t = this.target[j];
      const from = this.raw[j], to = t >= 0 ? this.raw[t] : null;
      if (!from || !to) continue;
      to.getWorldPosition(_u).sub(from.getWorldPosition(_v));
      jointAt(positions, t, _p).sub(jointAt(positions, j, _w));
      if (_u.lengthSq() < 1e-12 || _p.lengthSq() < 1e-12) continue;
      worst = Math.max(worst, THREE.MathUtils.radToDeg(_u.angleTo(_p)));
    }
    let feet = 0;
    for (const j of FEET) {
      const foot = this.raw[j];
      if (foot) feet = Math.max(feet, Math.abs(foot.getWorldPosition(_u).y - positions[3 * j + 1] * this.scale));
    }
    return { fitDeg: worst, feetCm: 100 * feet };
  }

  dispose(): void {
    this.group.removeFromParent();
    VRMUtils.deepDispose(this.vrm.scene);
  }
}
