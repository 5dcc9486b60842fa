// How a dancer is drawn. By default a skinned character (SkinnedDancer: the geometry and the bone
// matrices are in figure.ts); with ?bodies=sticks, and for the translucent ghosts, the capsule
// figure (DancerMeshes): capsules for the limbs (cylinders capped by joint spheres), plus six
// oriented ellipsoids that make hands, feet and facing readable at a glance: a mitten per hand, a
// shoe per foot and a nose + visor on the head. The ellipsoids are extra instances of the joint
// spheres (one geometry, one material, per-instance colour), so they cost no draw call; the floor
// rings under planted feet and the glow at a hand in contact are one instanced mesh each for all
// dancers (ContactMarks), drawn only while something is in contact. A skinned dancer carries a thin
// capsule figure too: the skeleton overlay, and the source of its contact points.
//
// Orientation comes from the simulation's world joint rotations when the view has them (columns
// of the row-major 3x3: a foot's and the head's local z is forward, a left hand's local +x and a
// right hand's -x run from the wrist to the fingers, y is up / the back of the hand); without them
// (the sampled ghosts) it is derived from the positions: facing from the hips and the shoulders,
// hands along the forearm. Nothing here allocates per frame.

import type { Avatar } from './avatar';
import * as THREE from 'three';
import { HEAD, JOINT_NAMES, N_JOINTS } from '../mirror/skeleton';
import { type FigureStyle, bindPositions, buildFigure, poseBones } from './figure';

const JOINT_RADIUS = 0.055;
const HEAD_RADIUS = 0.11;
const BONE_RADIUS = 0.045;

// Joint indices, by name (web/mirror/skeleton.ts JOINT_NAMES): the shoulder, elbow and wrist are the
// skeleton's lShldr, lForeArm and lHand; the hip and ankle its lThigh and lFoot.
const joint = (name: (typeof JOINT_NAMES)[number]): number => JOINT_NAMES.indexOf(name);
const NECK = joint('neck');
const L_SHOULDER = joint('lShldr');
const L_ELBOW = joint('lForeArm');
const L_WRIST = joint('lHand');
const R_SHOULDER = joint('rShldr');
const R_ELBOW = joint('rForeArm');
const R_WRIST = joint('rHand');
const L_HIP = joint('lThigh');
const L_ANKLE = joint('lFoot');
const R_HIP = joint('rThigh');
const R_ANKLE = joint('rFoot');

/**
 * Where a skinned dancer's body ends (figure.ts), each as a joint and an offset from it in the bind
 * pose, metres (y up, z where the body faces): the top of the head (the head's ellipsoid and the
 * follower's bun reach 0.133 m above the head joint), and the toe and the heel of each shoe (its
 * sole 0.052 m below the ankle, its tip 0.167 m ahead and its heel 0.077 m behind). The framing
 * keeps these in the picture (web/draw/framing.ts) and the tests check it (tests/e2e/framing.test.mjs).
 */
export const OUTLINE: readonly (readonly [number, number, number, number])[] = [
  [HEAD, 0, 0.135, 0],
  [L_ANKLE, 0, -0.052, 0.167],
  [L_ANKLE, 0, -0.052, -0.077],
  [R_ANKLE, 0, -0.052, 0.167],
  [R_ANKLE, 0, -0.052, -0.077],
];

/** The extra instances after the 17 joints of each dancer, in this order. */
const EXTRA_L_HAND = 0;
const EXTRA_R_HAND = 1;
const EXTRA_L_FOOT = 2;
const EXTRA_R_FOOT = 3;
const EXTRA_NOSE = 4;
const EXTRA_VISOR = 5;
const EXTRAS = 6;

/**
 * Each shape: half extents along (primary p, secondary q, r = p × q) and the centre's offset from
 * its joint along p and q, metres. Hands: p wrist -> fingers, q the back of the hand. Feet: p heel
 * -> toe, q up. Head: p where the face looks, q up.
 */
export const SHAPES = {
  hand: { half: [0.085, 0.028, 0.05], along: 0.075, up: 0 },
  foot: { half: [0.12, 0.035, 0.05], along: 0.045, up: -0.032 },
  nose: { half: [0.055, 0.026, 0.026], along: 0.1, up: -0.02 },
  visor: { half: [0.06, 0.03, 0.092], along: 0.06, up: 0.015 },
} as const;

/** Colour of each kind of instance: the dancer's colour mixed toward white (+) or black (-). */
const SHADE = { joint: 0, hand: 0.42, foot: -0.55, face: -0.82 };

/** Lowest point of a shoe above the floor, metres (the ankle itself may go down to 6 cm). */
const SOLE_CLEARANCE = 0.004;

/** Per dancer (slot 0 of a DancerMeshes): where contact marks go and how strong they are. */
export interface ContactState {
  /** Floor point under each shoe [left x, z, right x, z]. */
  readonly feet: Float32Array;
  /** Foot contact [left, right], 0..1, as the simulation reports it. */
  readonly footContact: Float32Array;
  /** Centre of each hand [left xyz, right xyz]. */
  readonly hands: Float32Array;
  /** Hand contact [left, right], 0..1: written by whoever knows (Stage.setHandContact). */
  readonly handContact: Float32Array;
}

/** What the stage and the page need of a dancer, whichever way it is drawn. */
export interface DancerBody extends ContactState {
  readonly group: THREE.Group;
  readonly color: THREE.Color;
  setCount(count: number): void;
  setPose(index: number, positions: ArrayLike<number>, rotations?: ArrayLike<number> | null, contacts?: ArrayLike<number> | null): void;
  /** The top of the head and each shoe's toe and heel as last posed (OUTLINE), world xyz into `out`. */
  outline(out: Float32Array): Float32Array;
}

/** How the dancers are drawn: skinned characters (the default) or the capsule figures. */
export type Bodies = 'skinned' | 'sticks';

/** `?bodies=sticks` draws the capsule figures; `?skeleton=1` shows the skeleton over the bodies. */
export function readBodies(search: string): { bodies: Bodies; skeleton: boolean } {
  const query = new URLSearchParams(search);
  return { bodies: query.get('bodies') === 'sticks' ? 'sticks' : 'skinned', skeleton: query.get('skeleton') === '1' };
}

/** Several dancers of one look, drawn with two instanced meshes (joint spheres + bone cylinders):
 *  a chain of cylinders capped by spheres at the joints is a chain of capsules, and instancing
 *  keeps it at two draw calls however many ghosts are shown. Hands, feet and the face are extra
 *  sphere instances, scaled and turned into ellipsoids. */
export class DancerMeshes implements DancerBody {
  readonly group = new THREE.Group();
  readonly feet = new Float32Array(4);
  readonly footContact = new Float32Array(2);
  readonly hands = new Float32Array(6);
  readonly handContact = new Float32Array(2);
  /** The dancer's colour (its material's), also used for its contact marks. */
  readonly color: THREE.Color;
  private readonly joints: THREE.InstancedMesh;
  private readonly bones: THREE.InstancedMesh;
  private readonly boneChildren: number[];
  private readonly jointCount: number;
  private readonly perDancer: number;
  /** Per extra of a dancer: lighter (hands, > 0) or darker (feet, face, < 0) than its colour. */
  private readonly shades: number[];

  constructor(
    private readonly parents: number[],
    readonly capacity: number,
    material: THREE.Material,
    castShadow: boolean,
    /** Radii and shapes scale by this (the skeleton overlay is a thin copy); contact points do not. */
    private readonly thickness = 1,
  ) {
    // The joints' copy of the material is white: the instance colours carry the dancer's colour
    // and its lighter hands, darker feet and face (same shader, so no extra program).
    const base = (material as THREE.MeshStandardMaterial).color;
    this.color = base ? base.clone() : new THREE.Color(0xffffff);
    const jointMaterial = material.clone() as THREE.MeshStandardMaterial;
    if (base) jointMaterial.color.set(0xffffff);
    this.jointCount = parents.length;
    this.perDancer = this.jointCount + EXTRAS;
    this.boneChildren = parents.flatMap((p, j) => (p >= 0 ? [j] : []));
    const sphere = new THREE.SphereGeometry(1, 16, 10);
    // Unit cylinder from y = 0 to y = 1, so scale.y is the bone length.
    const cylinder = new THREE.CylinderGeometry(1, 1, 1, 12, 1, true).translate(0, 0.5, 0);
    this.joints = new THREE.InstancedMesh(sphere, jointMaterial, capacity * this.perDancer);
    this.bones = new THREE.InstancedMesh(cylinder, material, capacity * this.boneChildren.length);
    for (const mesh of [this.joints, this.bones]) {
      mesh.castShadow = castShadow;
      mesh.receiveShadow = castShadow;
      // Dancers move anywhere; the instanced bounding sphere would otherwise cull them.
      mesh.frustumCulled = false;
      mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
      this.group.add(mesh);
    }
    // Shades are fixed: written once here, never per frame.
    this.shades = new Array<number>(this.perDancer).fill(SHADE.joint);
    const shades = this.shades;
    shades[this.jointCount + EXTRA_L_HAND] = shades[this.jointCount + EXTRA_R_HAND] = SHADE.hand;
    shades[this.jointCount + EXTRA_L_FOOT] = shades[this.jointCount + EXTRA_R_FOOT] = SHADE.foot;
    shades[this.jointCount + EXTRA_NOSE] = shades[this.jointCount + EXTRA_VISOR] = SHADE.face;
    for (let i = 0; i < capacity; i++) this.paint(i, this.color);
    this.setCount(capacity);
  }

  /**
   * Give dancer `index` a colour of its own (the possible reactions: eight translucent partners
   * in one colour read as one blur). The bones take it as an instance colour, which multiplies
   * the material's: give such a DancerMeshes a white material.
   */
  tint(index: number, color: THREE.ColorRepresentation): void {
    _tint.set(color);
    this.paint(index, _tint);
    for (let b = 0; b < this.boneChildren.length; b++) this.bones.setColorAt(index * this.boneChildren.length + b, _tint);
    if (this.bones.instanceColor) this.bones.instanceColor.needsUpdate = true;
  }

  /** Dancer `index`'s joints in `color`, hands lighter, feet and face darker. */
  private paint(index: number, color: THREE.Color): void {
    for (let k = 0; k < this.perDancer; k++) {
      const s = this.shades[k];
      _color.copy(color).lerp(s >= 0 ? _white : _black, Math.abs(s));
      this.joints.setColorAt(index * this.perDancer + k, _color);
    }
    if (this.joints.instanceColor) this.joints.instanceColor.needsUpdate = true;
  }

  /** Dancer 0's joint positions as last posed (for outline()). */
  private readonly first = new Float32Array(3 * N_JOINTS);

  /** Dancer 0's OUTLINE points, from its joints: the head sphere's top, and each shoe's ends along
   *  the hips' facing (the shoes' own turn is not kept: the same reach either way). */
  outline(out: Float32Array): Float32Array {
    const p = this.first;
    horizontalForward(p, L_HIP, R_HIP, _r);
    for (let i = 0; i < OUTLINE.length; i++) {
      const [j, , y, z] = OUTLINE[i];
      const up = j === HEAD ? HEAD_RADIUS * this.thickness : y;
      out[3 * i] = p[3 * j] + z * _r.x;
      out[3 * i + 1] = p[3 * j + 1] + up;
      out[3 * i + 2] = p[3 * j + 2] + z * _r.z;
    }
    return out;
  }

  /** How many of the `capacity` dancers to draw. */
  setCount(count: number): void {
    const n = Math.max(0, Math.min(this.capacity, count));
    this.joints.count = n * this.perDancer;
    this.bones.count = n * this.boneChildren.length;
    this.group.visible = n > 0;
  }

  /**
   * Pose dancer `index` from 17 world joint positions, and optionally the 17 world rotations
   * (row-major 3x3 each) that orient the hands, feet and face, and the foot contacts [left, right]
   * in 0..1 for the floor rings (dancer 0 only).
   */
  setPose(index: number, positions: ArrayLike<number>, rotations?: ArrayLike<number> | null, contacts?: ArrayLike<number> | null): void {
    const m = _matrix;
    const base = index * this.perDancer;
    for (let j = 0; j < this.jointCount; j++) {
      const r = (j === HEAD ? HEAD_RADIUS : JOINT_RADIUS) * this.thickness;
      _position.set(positions[3 * j], positions[3 * j + 1], positions[3 * j + 2]);
      _scale.set(r, r, r);
      m.compose(_position, _identity, _scale);
      this.joints.setMatrixAt(base + j, m);
    }
    const bones = this.boneChildren;
    for (let b = 0; b < bones.length; b++) {
      const j = bones[b];
      const p = this.parents[j];
      _position.set(positions[3 * p], positions[3 * p + 1], positions[3 * p + 2]);
      _direction.set(positions[3 * j], positions[3 * j + 1], positions[3 * j + 2]).sub(_position);
      const length = _direction.length();
      if (length > 1e-6) _direction.divideScalar(length);
      else _direction.set(0, 1, 0);
      _rotation.setFromUnitVectors(_up, _direction);
      _scale.set(BONE_RADIUS * this.thickness, length, BONE_RADIUS * this.thickness);
      m.compose(_position, _rotation, _scale);
      this.bones.setMatrixAt(index * bones.length + b, m);
    }
    this.poseExtras(base + this.jointCount, positions, rotations ?? null, index === 0);
    if (index === 0) {
      for (let i = 0; i < this.first.length; i++) this.first[i] = positions[i];
      this.footContact[0] = contacts ? contacts[0] : 0;
      this.footContact[1] = contacts ? contacts[1] : 0;
    }
    this.joints.instanceMatrix.needsUpdate = true;
    this.bones.instanceMatrix.needsUpdate = true;
  }

  private poseExtras(at: number, positions: ArrayLike<number>, rotations: ArrayLike<number> | null, record: boolean): void {
    // Facing from the positions, the fallback for every shape: hips for the feet, shoulders for the face.
    horizontalForward(positions, L_HIP, R_HIP, _hipForward);
    horizontalForward(positions, L_SHOULDER, R_SHOULDER, _chestForward);

    // Head: face forward p, up q.
    if (!fromRotation(rotations, HEAD, 2, 1, 1, _p, _q)) {
      _p.copy(_chestForward);
      jointDelta(positions, NECK, HEAD, _q);
    }
    orthonormalize(_p, _q, _up);
    this.writeShape(at + EXTRA_NOSE, positions, HEAD, SHAPES.nose, -Infinity);
    this.writeShape(at + EXTRA_VISOR, positions, HEAD, SHAPES.visor, -Infinity);

    // Hands: p wrist -> fingers (+x of the left hand, -x of the right), q the back of the hand.
    for (let side = 0; side < 2; side++) {
      const wrist = side === 0 ? L_WRIST : R_WRIST;
      if (!fromRotation(rotations, wrist, 0, 1, side === 0 ? 1 : -1, _p, _q)) {
        jointDelta(positions, side === 0 ? L_ELBOW : R_ELBOW, wrist, _p);
        _q.copy(_up);
      }
      orthonormalize(_p, _q, _chestForward);
      this.writeShape(at + (side === 0 ? EXTRA_L_HAND : EXTRA_R_HAND), positions, wrist, SHAPES.hand, -Infinity);
      if (record) {
        this.hands[3 * side] = _centre.x;
        this.hands[3 * side + 1] = _centre.y;
        this.hands[3 * side + 2] = _centre.z;
      }
    }

    // Feet: p heel -> toe, q up.
    for (let side = 0; side < 2; side++) {
      const ankle = side === 0 ? L_ANKLE : R_ANKLE;
      if (!fromRotation(rotations, ankle, 2, 1, 1, _p, _q)) {
        _p.copy(_hipForward);
        _q.copy(_up);
      }
      orthonormalize(_p, _q, _up);
      this.writeShape(at + (side === 0 ? EXTRA_L_FOOT : EXTRA_R_FOOT), positions, ankle, SHAPES.foot, SOLE_CLEARANCE);
      if (record) {
        this.feet[2 * side] = _centre.x;
        this.feet[2 * side + 1] = _centre.z;
      }
    }
  }

  /** An ellipsoid on joint `j` in the frame (_p, _q, _p × _q); leaves its centre in _centre. */
  private writeShape(
    instance: number, positions: ArrayLike<number>, j: number,
    shape: { half: readonly number[]; along: number; up: number }, floor: number,
  ): void {
    _r.crossVectors(_p, _q);
    const [hp, hq, hr] = shape.half.map((h) => h * this.thickness);
    _centre.set(positions[3 * j], positions[3 * j + 1], positions[3 * j + 2]);
    _centre.addScaledVector(_p, shape.along).addScaledVector(_q, shape.up);
    // Keep a shoe's lowest point (of the ellipsoid, exactly) above the floor.
    const reach = Math.hypot(_p.y * hp, _q.y * hq, _r.y * hr);
    if (_centre.y - reach < floor) _centre.y = floor + reach;
    _matrix.set(
      _p.x * hp, _q.x * hq, _r.x * hr, _centre.x,
      _p.y * hp, _q.y * hq, _r.y * hr, _centre.y,
      _p.z * hp, _q.z * hq, _r.z * hr, _centre.z,
      0, 0, 0, 1,
    );
    this.joints.setMatrixAt(instance, _matrix);
  }
}

/** Bodies built so far, by skeleton offsets, kind and colour: the leader's copy in compare mode
 *  wears the same body as the leader, so it is built once (building the scene at the phone
 *  bench's 4x CPU: 405 against 428 ms, docs/measurements.md). Nothing disposes them: the page
 *  keeps its dancers. */
const figures = new WeakMap<object, Map<string, THREE.BufferGeometry>>();

function figureGeometry(offsets: readonly (readonly number[])[], parents: number[], style: FigureStyle): THREE.BufferGeometry {
  let byStyle = figures.get(offsets);
  if (!byStyle) figures.set(offsets, (byStyle = new Map()));
  const key = `${style.kind}:${style.color}`;
  let geometry = byStyle.get(key);
  if (!geometry) byStyle.set(key, (geometry = buildFigure(offsets, parents, style)));
  return geometry;
}

/**
 * One dancer as a skinned character (figure.ts): one SkinnedMesh, one draw call, its 17 bones set
 * every frame from the same joint positions and rotations the capsule figure takes. A thin capsule
 * figure rides along: it is the optional skeleton overlay (drawn through the body), and its pose
 * gives the contact marks their floor and hand points, exactly as with the capsule figures.
 */
export class SkinnedDancer implements DancerBody {
  readonly group = new THREE.Group();
  readonly color: THREE.Color;
  readonly mesh: THREE.SkinnedMesh;
  /** The thin skeleton drawn over the body when `skeleton` is on. */
  readonly overlay: DancerMeshes;
  private readonly bind: Float32Array;
  private readonly bones: THREE.Bone[];
  private readonly matrices = new Float32Array(16 * N_JOINTS);

  constructor(parents: number[], offsets: readonly (readonly number[])[], style: FigureStyle, castShadow: boolean) {
    this.color = new THREE.Color(style.color);
    this.bind = bindPositions(offsets, parents);
    const geometry = figureGeometry(offsets, parents, style);
    const material = new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.7, metalness: 0.02 });
    this.mesh = new THREE.SkinnedMesh(geometry, material);
    // The bones are not in the scene graph: their world matrices are written directly in
    // setPose(), and nothing else may recompute them.
    this.bones = Array.from({ length: N_JOINTS }, () => {
      const bone = new THREE.Bone();
      bone.matrixAutoUpdate = false;
      bone.matrixWorldAutoUpdate = false;
      return bone;
    });
    // poseBones() gives each bone's whole bind -> drawn transform, so the inverses are identities.
    const inverses = this.bones.map(() => new THREE.Matrix4());
    this.mesh.bind(new THREE.Skeleton(this.bones, inverses), new THREE.Matrix4());
    this.mesh.castShadow = castShadow;
    this.mesh.receiveShadow = castShadow;
    this.mesh.frustumCulled = false; // dancers move anywhere; the bind-pose bounds would cull them
    const overlayMaterial = new THREE.MeshBasicMaterial({ color: this.color.clone().multiplyScalar(0.45), depthTest: false, transparent: true, opacity: 0.9 });
    this.overlay = new DancerMeshes(parents, 1, overlayMaterial, false, 0.3);
    this.overlay.group.renderOrder = 8;
    for (const child of this.overlay.group.children) child.renderOrder = 8;
    this.overlay.group.visible = false;
    this.group.add(this.mesh, this.overlay.group);
  }

  get feet(): Float32Array { return this.overlay.feet; }
  get footContact(): Float32Array { return this.overlay.footContact; }
  get hands(): Float32Array { return this.overlay.hands; }
  get handContact(): Float32Array { return this.overlay.handContact; }

  /** Whether the thin skeleton shows over the body. */
  get skeleton(): boolean {
    return this.showSkeleton;
  }
  set skeleton(on: boolean) {
    this.showSkeleton = on;
    this.overlay.group.visible = on && this.group.visible;
  }
  private showSkeleton = false;

  /** 0 or 1 (one dancer per SkinnedDancer). */
  setCount(count: number): void {
    this.group.visible = count > 0;
    this.overlay.setCount(count > 0 ? 1 : 0);
    this.overlay.group.visible = this.showSkeleton && count > 0;
  }

  setPose(index: number, positions: ArrayLike<number>, rotations?: ArrayLike<number> | null, contacts?: ArrayLike<number> | null): void {
    if (index !== 0) return;
    this.overlay.setPose(0, positions, rotations, contacts);
    poseBones(this.bind, positions, rotations ?? null, this.matrices);
    for (let j = 0; j < N_JOINTS; j++) this.bones[j].matrixWorld.fromArray(this.matrices, 16 * j);
    if (this.avatar) {
      // An avatar needs the joints' rotations; a pose without them shows the dancer's own body.
      const posable = !!rotations && rotations.length >= 9 * N_JOINTS;
      this.avatar.group.visible = posable;
      this.mesh.visible = !posable;
      const now = performance.now();
      const dt = this.posedAt > 0 ? Math.min(0.1, (now - this.posedAt) / 1000) : 0;
      this.posedAt = now;
      if (posable) this.avatar.setPose(positions, rotations!, dt);
    }
  }

  /**
   * Wear `avatar` (avatar.ts) in place of this body, or the body again (null; the avatar worn
   * before is disposed). The skeleton overlay and the contact marks stay the dancer's.
   */
  dress(avatar: Avatar | null): void {
    this.avatar?.dispose();
    this.avatar = avatar;
    this.mesh.visible = avatar === null;
    if (avatar) {
      avatar.fit(this.bind);
      this.group.add(avatar.group);
    }
  }
  private avatar: Avatar | null = null;
  private posedAt = 0;

  /** Bone j's world matrix as last posed (for tests). */
  boneMatrix(j: number): THREE.Matrix4 {
    return this.bones[j].matrixWorld;
  }

  /** The OUTLINE points (head top, toes and heels) as last posed, world metres, into `out` (xyz each). */
  outline(out: Float32Array): Float32Array {
    for (let i = 0; i < OUTLINE.length; i++) {
      const [j, x, y, z] = OUTLINE[i];
      _p.set(this.bind[3 * j] + x, this.bind[3 * j + 1] + y, this.bind[3 * j + 2] + z).applyMatrix4(this.bones[j].matrixWorld);
      out[3 * i] = _p.x;
      out[3 * i + 1] = _p.y;
      out[3 * i + 2] = _p.z;
    }
    return out;
  }
}

/**
 * Floor rings under planted feet and a soft glow at hands in contact, for every dancer at once:
 * two instanced meshes, each hidden (no draw call) while nothing of its kind is in contact.
 */
export class ContactMarks {
  readonly group = new THREE.Group();
  private readonly rings: THREE.InstancedMesh;
  private readonly glows: THREE.InstancedMesh;
  private readonly ringAlpha: THREE.InstancedBufferAttribute;
  private readonly glowAlpha: THREE.InstancedBufferAttribute;

  constructor(readonly capacity: number) {
    const disc = new THREE.CircleGeometry(1, 32).rotateX(-Math.PI / 2);
    const ball = new THREE.SphereGeometry(1, 16, 10);
    this.ringAlpha = new THREE.InstancedBufferAttribute(new Float32Array(2 * capacity), 1).setUsage(THREE.DynamicDrawUsage);
    this.glowAlpha = new THREE.InstancedBufferAttribute(new Float32Array(2 * capacity), 1).setUsage(THREE.DynamicDrawUsage);
    disc.setAttribute('instanceAlpha', this.ringAlpha);
    ball.setAttribute('instanceAlpha', this.glowAlpha);
    this.rings = new THREE.InstancedMesh(disc, markMaterial(RING_FRAGMENT), 2 * capacity);
    this.glows = new THREE.InstancedMesh(ball, markMaterial(GLOW_FRAGMENT), 2 * capacity);
    this.glows.renderOrder = 5; // after the dancers' own transparent ghosts
    for (const mesh of [this.rings, this.glows]) {
      mesh.setColorAt(0, _glowColor); // instanceColor exists before the shader is first compiled
      mesh.frustumCulled = false;
      mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
      mesh.count = 0;
      mesh.visible = false;
      this.group.add(mesh);
    }
  }

  /** Rewrite every mark from the dancers' slot-0 contact state (invisible dancers skipped). */
  update(dancers: readonly DancerBody[]): void {
    let rings = 0;
    let glows = 0;
    for (let d = 0; d < dancers.length && d < this.capacity; d++) {
      const dancer = dancers[d];
      if (!dancer.group.visible) continue;
      for (let side = 0; side < 2; side++) {
        // Contact is a probability: fade the ring in between 0.3 and 0.8.
        const ring = smoothstep(0.3, 0.8, dancer.footContact[side]);
        if (ring > 0.01) {
          _matrix.makeScale(RING_RADIUS, 1, RING_RADIUS).setPosition(dancer.feet[2 * side], RING_HEIGHT, dancer.feet[2 * side + 1]);
          this.rings.setMatrixAt(rings, _matrix);
          this.rings.setColorAt(rings, dancer.color);
          this.ringAlpha.setX(rings, ring);
          rings++;
        }
        const glow = Math.min(1, Math.max(0, dancer.handContact[side]));
        if (glow > 0.01) {
          const s = GLOW_RADIUS * (0.7 + 0.3 * glow);
          _matrix.makeScale(s, s, s).setPosition(dancer.hands[3 * side], dancer.hands[3 * side + 1], dancer.hands[3 * side + 2]);
          this.glows.setMatrixAt(glows, _matrix);
          this.glows.setColorAt(glows, _glowColor);
          this.glowAlpha.setX(glows, glow);
          glows++;
        }
      }
    }
    this.finish(this.rings, this.ringAlpha, rings);
    this.finish(this.glows, this.glowAlpha, glows);
  }

  /** How many rings and glows the last update() drew (for tests). */
  get counts(): { rings: number; glows: number } {
    return { rings: this.rings.count, glows: this.glows.count };
  }

  private finish(mesh: THREE.InstancedMesh, alpha: THREE.InstancedBufferAttribute, count: number): void {
    mesh.count = count;
    mesh.visible = count > 0;
    if (count === 0) return;
    mesh.instanceMatrix.needsUpdate = true;
    if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
    alpha.needsUpdate = true;
  }
}

const RING_RADIUS = 0.14;
const RING_HEIGHT = 0.004;
const GLOW_RADIUS = 0.12;
const _glowColor = new THREE.Color(0xffc94a);

const MARK_VERTEX = /* glsl */ `
attribute float instanceAlpha;
varying float vAlpha;
varying vec3 vTint;
varying vec3 vLocal;
varying vec3 vNormalView;
varying vec3 vToCamera;
void main() {
  vAlpha = instanceAlpha;
  #ifdef USE_INSTANCING_COLOR
    vTint = instanceColor;
  #else
    vTint = vec3(1.0);
  #endif
  vLocal = position;
  vec4 world = instanceMatrix * vec4(position, 1.0);
  vec4 view = modelViewMatrix * world;
  vNormalView = normalize(normalMatrix * mat3(instanceMatrix) * normal);
  vToCamera = -view.xyz;
  gl_Position = projectionMatrix * view;
}`;

/** A thin ring with a faint fill, on a unit disc in x/z. */
const RING_FRAGMENT = /* glsl */ `
varying float vAlpha;
varying vec3 vTint;
varying vec3 vLocal;
void main() {
  float r = length(vLocal.xz);
  float ring = smoothstep(0.66, 0.8, r) * (1.0 - smoothstep(0.9, 1.0, r));
  float fill = 0.22 * (1.0 - r);
  gl_FragColor = vec4(vTint, vAlpha * 0.6 * max(ring, fill));
}`;

/** A ball that is opaque-ish in the middle and fades to nothing at its silhouette. */
const GLOW_FRAGMENT = /* glsl */ `
varying float vAlpha;
varying vec3 vTint;
varying vec3 vNormalView;
varying vec3 vToCamera;
void main() {
  float facing = abs(dot(normalize(vNormalView), normalize(vToCamera)));
  gl_FragColor = vec4(vTint, vAlpha * 0.7 * facing * facing);
}`;

function markMaterial(fragmentShader: string): THREE.ShaderMaterial {
  return new THREE.ShaderMaterial({
    vertexShader: MARK_VERTEX,
    fragmentShader,
    transparent: true,
    depthWrite: false,
    polygonOffset: true,
    polygonOffsetFactor: -1,
    polygonOffsetUnits: -1,
  });
}

function smoothstep(edge0: number, edge1: number, x: number): number {
  const t = Math.min(1, Math.max(0, (x - edge0) / (edge1 - edge0)));
  return t * t * (3 - 2 * t);
}

/** Horizontal unit vector the body faces, from the line between a left and a right joint. */
function horizontalForward(positions: ArrayLike<number>, left: number, right: number, out: THREE.Vector3): void {
  const sx = positions[3 * left] - positions[3 * right];
  const sz = positions[3 * left + 2] - positions[3 * right + 2];
  const length = Math.hypot(sx, sz);
  // (left - right) × up: facing +z when the left side is at +x.
  if (length > 1e-6) out.set(-sz / length, 0, sx / length);
  else out.set(0, 0, 1);
}

function jointDelta(positions: ArrayLike<number>, from: number, to: number, out: THREE.Vector3): void {
  out.set(positions[3 * to] - positions[3 * from], positions[3 * to + 1] - positions[3 * from + 1], positions[3 * to + 2] - positions[3 * from + 2]);
}

/** Columns `a` (times `sign`) and `b` of joint j's row-major rotation into p and q; false when
 *  there is no usable rotation. */
function fromRotation(
  rotations: ArrayLike<number> | null, j: number, a: number, b: number, sign: number, p: THREE.Vector3, q: THREE.Vector3,
): boolean {
  if (!rotations || rotations.length < 9 * (j + 1)) return false;
  const o = 9 * j;
  p.set(rotations[o + a] * sign, rotations[o + 3 + a] * sign, rotations[o + 6 + a] * sign);
  q.set(rotations[o + b], rotations[o + 3 + b], rotations[o + 6 + b]);
  return p.lengthSq() > 1e-6;
}

/** Gram-Schmidt: p unit, q unit and perpendicular to p (`fallback` when q runs along p). */
function orthonormalize(p: THREE.Vector3, q: THREE.Vector3, fallback: THREE.Vector3): void {
  if (p.lengthSq() < 1e-12) p.set(0, 0, 1);
  p.normalize();
  q.addScaledVector(p, -q.dot(p));
  if (q.lengthSq() < 1e-8) {
    q.copy(fallback).addScaledVector(p, -fallback.dot(p));
    if (q.lengthSq() < 1e-8) q.set(1, 0, 0).addScaledVector(p, -p.x);
  }
  q.normalize();
}

// Scratch objects shared by the per-frame code above.
const _matrix = new THREE.Matrix4();
const _position = new THREE.Vector3();
const _direction = new THREE.Vector3();
const _scale = new THREE.Vector3();
const _rotation = new THREE.Quaternion();
const _identity = new THREE.Quaternion();
const _up = new THREE.Vector3(0, 1, 0);
const _p = new THREE.Vector3();
const _q = new THREE.Vector3();
const _r = new THREE.Vector3();
const _centre = new THREE.Vector3();
const _hipForward = new THREE.Vector3();
const _chestForward = new THREE.Vector3();
const _color = new THREE.Color();
const _tint = new THREE.Color();
const _white = new THREE.Color(0xffffff);
const _black = new THREE.Color(0x000000);
