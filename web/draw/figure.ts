// Skinned characters built in code from the skeleton's own bone offsets: one BufferGeometry per
// dancer (torso, neck, head with a face, arms, hands, legs, shoes and the clothes) skinned to the
// 17 joints, drawn as one THREE.SkinnedMesh with vertex colours, so one draw call per dancer.
//
// Bind pose: every joint rotation is the identity, so joint j sits at the sum of the offsets from
// the root to j (the BVH's rest pose: a T-pose facing +z, the left side at +x). Each frame,
// poseBones() turns the 17 world joint positions (and, when there are any, the world rotations)
// into 17 bone matrices that put every bind joint exactly on its drawn position: the rotation
// gives the twist, a small correction turns the bone onto its child's actual position (the contact
// layer moves positions, not rotations), and a stretch along the bone makes it reach that child.
//
// Limbs and the torso are tubes of elliptical rings along a chain of joints; each ring is weighted
// to the bone it lies on and, within BLEND of a joint, blended smoothly into the next (or the
// previous) bone, so elbows, knees and the waist bend without cracks.

import * as THREE from 'three';
import { JOINT_NAMES, N_JOINTS, PARENTS } from '../mirror/skeleton';

const joint = (name: (typeof JOINT_NAMES)[number]): number => JOINT_NAMES.indexOf(name);
const HIP = joint('hip');
const ABDOMEN = joint('abdomen');
const CHEST = joint('chest');
const NECK = joint('neck');
const HEAD = joint('head');
const L_SHOULDER = joint('lShldr');
const R_SHOULDER = joint('rShldr');
const L_HAND = joint('lHand');
const R_HAND = joint('rHand');
const L_THIGH = joint('lThigh');
const R_THIGH = joint('rThigh');
const L_FOOT = joint('lFoot');
const R_FOOT = joint('rFoot');

/** The child a joint's bone points at: its only child, or for the hip and the chest (three
 *  children each) the next spine joint; -1 for the head, hands and feet. */
export const PRIMARY_CHILD: number[] = JOINT_NAMES.map((_, j) => {
  if (j === HIP) return ABDOMEN;
  if (j === CHEST) return NECK;
  return PARENTS.indexOf(j);
});

export type FigureKind = 'leader' | 'follower';

export interface FigureStyle {
  kind: FigureKind;
  /** The dancer's colour: the leader's shirt, the follower's dress. */
  color: number;
}

const SKIN = 0xdcae8c;
const PALETTE = {
  leader: { lower: 0x262b3a, shoes: 0x141519, hair: 0x33251c },
  follower: { shoes: 0x3a1614, hair: 0x231611 },
};

/** Metres over which a ring's weight passes from one bone to the next at a joint. */
const BLEND = { spine: 0.07, arm: 0.05, leg: 0.06 };
const RADIAL = 12;
/** Metres from the hip joint down to the skirt's hem (just above the knee). */
const SKIRT_LENGTH = 0.4;

/** Bind positions (17 × 3) from per-joint offsets in the parent's frame, rotations all identity. */
export function bindPositions(offsets: readonly (readonly number[])[], parents: readonly number[]): Float32Array {
  const out = new Float32Array(N_JOINTS * 3);
  for (let j = 0; j < N_JOINTS; j++) {
    const p = parents[j];
    for (let k = 0; k < 3; k++) out[3 * j + k] = (p >= 0 ? out[3 * p + k] : 0) + offsets[j][k];
  }
  return out;
}

/** A geometry under construction: flat arrays, up to 4 bone weights per vertex. */
class Builder {
  readonly position: number[] = [];
  readonly normal: number[] = [];
  readonly color: number[] = [];
  readonly skinIndex: number[] = [];
  readonly skinWeight: number[] = [];
  readonly index: number[] = [];

  get count(): number {
    return this.position.length / 3;
  }

  /** Append a piece (position + normal + index) with one colour and weights per vertex. */
  addPiece(
    piece: THREE.BufferGeometry,
    colorOf: (x: number, y: number, z: number, nx: number, ny: number, nz: number) => number,
    weightsOf: (x: number, y: number, z: number) => [number, number][],
  ): void {
    const base = this.count;
    const p = piece.getAttribute('position');
    const n = piece.getAttribute('normal');
    for (let i = 0; i < p.count; i++) {
      const x = p.getX(i), y = p.getY(i), z = p.getZ(i);
      this.position.push(x, y, z);
      this.normal.push(n.getX(i), n.getY(i), n.getZ(i));
      _color.set(colorOf(x, y, z, n.getX(i), n.getY(i), n.getZ(i)));
      this.color.push(_color.r, _color.g, _color.b);
      this.pushWeights(weightsOf(x, y, z));
    }
    const index = piece.getIndex();
    if (index) for (let i = 0; i < index.count; i++) this.index.push(base + index.getX(i));
    else for (let i = 0; i < p.count; i++) this.index.push(base + i);
  }

  private pushWeights(weights: [number, number][]): void {
    // Merge duplicate bones, keep the 4 largest, normalize to sum 1.
    const merged = new Map<number, number>();
    for (const [b, w] of weights) if (w > 1e-4) merged.set(b, (merged.get(b) ?? 0) + w);
    const top = [...merged].sort((a, b) => b[1] - a[1]).slice(0, 4);
    const sum = top.reduce((s, [, w]) => s + w, 0) || 1;
    for (let k = 0; k < 4; k++) {
      this.skinIndex.push(k < top.length ? top[k][0] : 0);
      this.skinWeight.push(k < top.length ? top[k][1] / sum : 0);
    }
  }

  build(): THREE.BufferGeometry {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(this.position, 3));
    g.setAttribute('normal', new THREE.Float32BufferAttribute(this.normal, 3));
    g.setAttribute('color', new THREE.Float32BufferAttribute(this.color, 3));
    g.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(this.skinIndex, 4));
    g.setAttribute('skinWeight', new THREE.Float32BufferAttribute(this.skinWeight, 4));
    g.setIndex(this.index);
    return g;
  }
}

/** One ring of a tube: centre, axis, lateral reference, half widths, colour, bone weights. */
interface Ring {
  centre: THREE.Vector3;
  axis: THREE.Vector3;
  lateral: THREE.Vector3;
  rx: number;
  rz: number;
  color: number;
  weights: [number, number][];
}

/** A closed tube through `rings`, with a rounded cap at each end (weighted like its end ring). */
function addTube(b: Builder, rings: Ring[], radial = RADIAL, caps = [true, true]): void {
  const all: Ring[] = [];
  const cap = (end: Ring, sign: number): Ring[] => {
    const out: Ring[] = [];
    for (const phi of [0.5, 0.95, 1.35]) {
      const s = Math.cos(phi);
      const reach = Math.sin(phi) * Math.min(end.rx, end.rz);
      out.push({ ...end, centre: end.centre.clone().addScaledVector(end.axis, sign * reach), rx: end.rx * s, rz: end.rz * s });
    }
    return out;
  };
  if (caps[0]) all.push(...cap(rings[0], -1).reverse());
  all.push(...rings);
  if (caps[1]) all.push(...cap(rings[rings.length - 1], 1));
  const positions: number[] = [];
  const index: number[] = [];
  const e1 = new THREE.Vector3(), e2 = new THREE.Vector3(), v = new THREE.Vector3();
  for (const ring of all) {
    e1.copy(ring.lateral).addScaledVector(ring.axis, -ring.lateral.dot(ring.axis)).normalize();
    e2.crossVectors(ring.axis, e1);
    for (let k = 0; k < radial; k++) {
      const t = (2 * Math.PI * k) / radial;
      v.copy(ring.centre).addScaledVector(e1, ring.rx * Math.cos(t)).addScaledVector(e2, ring.rz * Math.sin(t));
      positions.push(v.x, v.y, v.z);
    }
  }
  for (let i = 0; i + 1 < all.length; i++) {
    for (let k = 0; k < radial; k++) {
      const a = i * radial + k, bb = i * radial + ((k + 1) % radial);
      const c = (i + 1) * radial + ((k + 1) % radial), d = (i + 1) * radial + k;
      index.push(a, bb, c, a, c, d);
    }
  }
  const piece = new THREE.BufferGeometry();
  piece.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  piece.setIndex(index);
  piece.computeVertexNormals();
  let vertex = 0;
  b.addPiece(
    piece,
    () => all[Math.floor(vertex / radial)].color,
    () => all[Math.floor(vertex++ / radial)].weights,
  );
}

const smooth = (x: number): number => {
  const t = Math.min(1, Math.max(0, 0.5 * (x + 1)));
  return t * t * (3 - 2 * t);
};

/**
 * Rings along a chain of joints (bind positions), at arc lengths `stations` (negative: before the
 * first joint; beyond the total: after the last). Ring at arc s on the segment of bone k takes that
 * bone's weight, blended over ±blend into the next joint's bone near its end and into the previous
 * bone (or `before`, the chain's parent) near its start: at a joint exactly half each.
 */
function chainRings(
  bind: Float32Array, chain: number[], before: number, blend: number, lateral: THREE.Vector3,
  stations: { s: number; rx: number; rz?: number; color: number }[],
): Ring[] {
  const points = chain.map((j) => new THREE.Vector3(bind[3 * j], bind[3 * j + 1], bind[3 * j + 2]));
  const lengths = points.slice(1).map((p, i) => p.distanceTo(points[i]));
  const starts = lengths.map((_, i) => lengths.slice(0, i).reduce((a, l) => a + l, 0));
  const dirs = points.slice(1).map((p, i) => p.clone().sub(points[i]).normalize());
  return stations.map(({ s, rx, rz, color }) => {
    let k = 0;
    while (k + 1 < lengths.length && s >= starts[k + 1]) k++;
    const u = s - starts[k];
    const centre = points[k].clone().addScaledVector(dirs[k], u);
    // Near an inner joint the ring leans halfway between the two segments, so rings do not cross.
    let axis = dirs[k].clone();
    if (k + 1 < dirs.length && u > lengths[k] - blend) axis.lerp(dirs[k + 1], 0.5 * smooth((u - lengths[k]) / blend)).normalize();
    if (k > 0 && u < blend) axis.lerp(dirs[k - 1], 0.5 * (1 - smooth(u / blend))).normalize();
    const next = chain[k + 1];
    const previous = k > 0 ? chain[k - 1] : before;
    const wNext = next !== undefined ? smooth((u - lengths[k]) / blend) : 0;
    const wPrevious = previous >= 0 ? 1 - smooth(u / blend) : 0;
    const weights: [number, number][] = [[chain[k], Math.max(0, 1 - wNext - wPrevious)]];
    if (wNext > 0) weights.push([next, wNext]);
    if (wPrevious > 0) weights.push([previous, wPrevious]);
    axis = axis.normalize();
    return { centre, axis, lateral, rx, rz: rz ?? rx, color, weights };
  });
}

/** An ellipsoid piece centred at `centre` with half axes (ax, ay, az) in bind (world) axes. */
function ellipsoid(centre: THREE.Vector3, ax: number, ay: number, az: number, widthSegments = 12, heightSegments = 8): THREE.BufferGeometry {
  const g = new THREE.SphereGeometry(1, widthSegments, heightSegments);
  g.scale(ax, ay, az).translate(centre.x, centre.y, centre.z);
  g.deleteAttribute('uv');
  // Normals of the scaled sphere: the gradient of the ellipsoid.
  const p = g.getAttribute('position'), n = g.getAttribute('normal');
  for (let i = 0; i < p.count; i++) {
    _v.set((p.getX(i) - centre.x) / (ax * ax), (p.getY(i) - centre.y) / (ay * ay), (p.getZ(i) - centre.z) / (az * az)).normalize();
    n.setXYZ(i, _v.x, _v.y, _v.z);
  }
  return g;
}

const at = (bind: Float32Array, j: number, dx = 0, dy = 0, dz = 0): THREE.Vector3 =>
  new THREE.Vector3(bind[3 * j] + dx, bind[3 * j + 1] + dy, bind[3 * j + 2] + dz);

/**
 * The dancer's geometry in bind pose (skin indices/weights into the 17 joints, vertex colours).
 * Leader: shirt in its colour, dark trousers and shoes, short hair. Follower: a dress in its
 * colour with a flared skirt, bare arms and legs, hair in a bun at the back of the head.
 */
export function buildFigure(offsets: readonly (readonly number[])[], parents: readonly number[], style: FigureStyle): THREE.BufferGeometry {
  const bind = bindPositions(offsets, parents);
  const b = new Builder();
  const leader = style.kind === 'leader';
  const cloth = style.color;
  const lower = leader ? PALETTE.leader.lower : SKIN;
  const shoes = leader ? PALETTE.leader.shoes : PALETTE.follower.shoes;
  const hair = leader ? PALETTE.leader.hair : PALETTE.follower.hair;
  const X = new THREE.Vector3(1, 0, 0);
  const Z = new THREE.Vector3(0, 0, 1);

  // Torso: hip -> abdomen -> chest -> neck, elliptical rings (wide across, shallow front to back).
  const spine = [HIP, ABDOMEN, CHEST, NECK];
  const spineLength = bind[3 * NECK + 1] - bind[3 * HIP + 1];
  const f = spineLength / 0.64; // the profile below is for a 64 cm spine
  const torso = leader
    ? [[-0.1, 0.1, 0.075, lower], [-0.065, 0.148, 0.1, lower], [0, 0.162, 0.108, lower], [0.07, 0.152, 0.104, lower],
      [0.075, 0.152, 0.104, cloth], [0.2, 0.142, 0.1, cloth], [0.33, 0.152, 0.108, cloth], [0.44, 0.168, 0.112, cloth],
      [0.53, 0.178, 0.104, cloth], [0.59, 0.16, 0.088, cloth], [0.625, 0.1, 0.065, cloth], [0.64, 0.055, 0.05, SKIN]]
    : [[-0.09, 0.1, 0.075, cloth], [-0.06, 0.145, 0.1, cloth], [0, 0.158, 0.108, cloth], [0.1, 0.14, 0.098, cloth],
      [0.21, 0.118, 0.09, cloth], [0.33, 0.135, 0.1, cloth], [0.43, 0.148, 0.112, cloth], [0.5, 0.15, 0.1, cloth],
      [0.52, 0.15, 0.095, SKIN], [0.58, 0.148, 0.08, SKIN], [0.62, 0.09, 0.06, SKIN], [0.64, 0.05, 0.045, SKIN]];
  addTube(b, chainRings(bind, spine, -1, BLEND.spine, X, torso.map(([s, rx, rz, color]) => ({ s: s * f, rx, rz, color }))), 14);

  // Neck and head: the head is an ellipsoid with hair over the top and back, a nose and two eyes
  // in front, so it shows where the dancer looks; the follower wears a bun at the back.
  const neckLength = Math.hypot(offsets[HEAD][0], offsets[HEAD][1], offsets[HEAD][2]);
  addTube(b, chainRings(bind, [NECK, HEAD], CHEST, 0.04, X,
    [{ s: -0.03, rx: 0.05, color: SKIN }, { s: 0.02, rx: 0.048, color: SKIN }, { s: neckLength, rx: 0.045, color: SKIN }]), 10);
  const headCentre = at(bind, HEAD, 0, 0.025, 0.005);
  b.addPiece(
    ellipsoid(headCentre, 0.08, 0.108, 0.098, 14, 10),
    (_x, y, z, _nx, ny, nz) => {
      const hairline = leader ? 0.35 : 0.2;
      return ny > hairline || nz < -0.15 || (nz < 0.35 && y - headCentre.y > 0.03) || (z - headCentre.z < -0.02 && y - headCentre.y > -0.06) ? hair : SKIN;
    },
    () => [[HEAD, 1]],
  );
  const nose = new THREE.ConeGeometry(0.017, 0.032, 6).rotateX(Math.PI / 2);
  nose.deleteAttribute('uv');
  nose.translate(headCentre.x, headCentre.y - 0.012, headCentre.z + 0.098);
  b.addPiece(nose, () => SKIN, () => [[HEAD, 1]]);
  for (const side of [-1, 1]) {
    b.addPiece(ellipsoid(at(bind, HEAD, side * 0.032, 0.035, 0.088), 0.014, 0.012, 0.01, 6, 4), () => 0x1a1a1a, () => [[HEAD, 1]]);
  }
  if (!leader) b.addPiece(ellipsoid(at(bind, HEAD, 0, 0.075, -0.095), 0.05, 0.048, 0.045, 10, 6), () => hair, () => [[HEAD, 1]]);

  // Arms: shoulder -> elbow -> wrist, blended into the chest at the shoulder; then a mitten hand.
  for (const [shoulder, hand, sign] of [[L_SHOULDER, L_HAND, 1], [R_SHOULDER, R_HAND, -1]] as const) {
    const chain = [shoulder, shoulder + 1, hand];
    const upper = Math.hypot(...offsets[shoulder + 1]);
    const forearm = Math.hypot(...offsets[hand]);
    const sleeve = (s: number) => (leader ? (s < upper + forearm - 0.035 ? cloth : SKIN) : SKIN);
    const arm = [
      [0, 0.056], [0.06, 0.052], [0.16, 0.047], [upper - 0.06, 0.042], [upper, 0.039],
      [upper + 0.06, 0.04], [upper + 0.16, 0.035], [upper + forearm - 0.04, 0.029], [upper + forearm - 0.03, leader ? 0.026 : 0.028], [upper + forearm, 0.026],
    ].map(([s, r]) => ({ s, rx: r * (leader ? 1.08 : 1), rz: r * (leader ? 1.08 : 0.95), color: sleeve(s) }));
    addTube(b, chainRings(bind, chain, CHEST, BLEND.arm, Z, arm), 10);
    // Hand: a flat mitten from the wrist along ±x, the back of the hand up (+y) in bind pose.
    b.addPiece(ellipsoid(at(bind, hand, sign * 0.075, 0, 0), 0.08, 0.024, 0.045, 10, 6), () => SKIN, () => [[hand, 1]]);
  }

  // Legs: hip joint -> knee -> ankle, blended into the pelvis at the top; a shoe on each foot.
  for (const [thigh, foot] of [[L_THIGH, L_FOOT], [R_THIGH, R_FOOT]] as const) {
    const chain = [thigh, thigh + 1, foot];
    const upper = Math.hypot(...offsets[thigh + 1]);
    const shin = Math.hypot(...offsets[foot]);
    const profile = leader
      ? [[-0.02, 0.088], [0.08, 0.084], [0.22, 0.072], [upper - 0.05, 0.062], [upper, 0.06], [upper + 0.1, 0.06], [upper + 0.3, 0.056], [upper + shin - 0.05, 0.053], [upper + shin, 0.05]]
      : [[-0.02, 0.082], [0.08, 0.078], [0.22, 0.064], [upper - 0.05, 0.05], [upper, 0.047], [upper + 0.1, 0.052], [upper + 0.22, 0.05], [upper + shin - 0.1, 0.036], [upper + shin, 0.03]];
    // Under the skirt the follower's thighs wear the dress colour: a thigh that swings through the
    // skirt then reads as the skirt's fold, not as a hole in it.
    const legColor = (s: number) => (leader || s > SKIRT_LENGTH - 0.04 ? lower : cloth);
    addTube(b, chainRings(bind, chain, HIP, BLEND.leg, X, profile.map(([s, r]) => ({ s, rx: r, rz: r, color: legColor(s) }))), 12);
    // Shoe: heel behind the ankle, toe in front (+z), a flat sole.
    const shoe = ellipsoid(at(bind, foot, 0, -0.022, 0.045), 0.048, 0.04, 0.122, 12, 8);
    const p = shoe.getAttribute('position');
    const sole = bind[3 * foot + 1] - 0.052;
    for (let i = 0; i < p.count; i++) if (p.getY(i) < sole) p.setY(i, sole);
    b.addPiece(shoe, () => shoes, () => [[foot, 1]]);
  }

  // The follower's skirt: a flared cone from the waist to above the knee, inside and out, on the
  // pelvis with its hem pulled by each thigh on its own side (and both at front and back), so it
  // swings with the steps.
  if (!leader) {
    const top = bind[3 * HIP + 1] + 0.1 * f;
    const hem = bind[3 * HIP + 1] - SKIRT_LENGTH;
    const rings = 7, radial = 20;
    for (const inside of [false, true]) {
      const positions: number[] = [];
      const index: number[] = [];
      const meta: { v: number; c: number }[] = [];
      for (let i = 0; i < rings; i++) {
        const v = i / (rings - 1);
        const y = top + (hem - top) * v;
        const flare = Math.pow(v, 1.3);
        const rx = (0.135 + 0.15 * flare) * (inside ? 0.97 : 1);
        const rz = (0.105 + 0.15 * flare) * (inside ? 0.97 : 1);
        for (let k = 0; k < radial; k++) {
          const t = (2 * Math.PI * k) / radial;
          // Soft folds toward the hem.
          const fold = 1 + 0.05 * v * Math.sin(6 * t);
          positions.push(bind[3 * HIP] + rx * fold * Math.cos(t), y, bind[3 * HIP + 2] + rz * fold * Math.sin(t));
          meta.push({ v, c: Math.cos(t) });
        }
      }
      for (let i = 0; i + 1 < rings; i++) {
        for (let k = 0; k < radial; k++) {
          const a = i * radial + k, bb = i * radial + ((k + 1) % radial);
          const c = (i + 1) * radial + ((k + 1) % radial), d = (i + 1) * radial + k;
          // Rings go down (-y) and around from +x to +z: (a, bb, c) faces outward, as in addTube.
          if (inside) index.push(a, c, bb, a, d, c);
          else index.push(a, bb, c, a, c, d);
        }
      }
      const piece = new THREE.BufferGeometry();
      piece.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
      piece.setIndex(index);
      piece.computeVertexNormals();
      let vertex = 0;
      const dark = new THREE.Color(cloth).multiplyScalar(0.6).getHex();
      b.addPiece(piece, () => (inside ? dark : cloth), () => {
        const { v, c } = meta[vertex++];
        const pull = 0.7 * Math.pow(v, 1.3);
        const left = pull * (0.5 + 0.5 * c), right = pull * (0.5 - 0.5 * c);
        const waist = 0.5 * (1 - smooth(v * 6 - 1));
        return [[HIP, Math.max(0, 1 - left - right - waist)], [ABDOMEN, waist], [L_THIGH, left], [R_THIGH, right]];
      });
    }
  }
  return b.build();
}

/**
 * Bone matrices (17 column-major 4x4, as THREE.Matrix4.elements) that carry the bind pose onto
 * the drawn pose: joint j's bind position lands exactly on positions[j], and the bone toward its
 * primary child ends exactly on that child. `rotations`: world 3x3 per joint, row-major (may be
 * interpolated, so not quite orthonormal); null: orientation from the positions alone.
 */
export function poseBones(bind: Float32Array, positions: ArrayLike<number>, rotations: ArrayLike<number> | null, out: Float32Array): void {
  facing(positions, L_THIGH, R_THIGH, _hipForward);
  facing(positions, L_SHOULDER, R_SHOULDER, _chestForward);
  for (let j = 0; j < N_JOINTS; j++) {
    const child = PRIMARY_CHILD[j];
    if (rotations && rotations.length >= 9 * (j + 1)) {
      jointRotation(rotations, j, _rotation);
    } else if (child >= 0) {
      // Without rotations: the bind bone direction onto the actual one, bind forward (+z) onto the
      // body's facing.
      _d.set(bind[3 * child] - bind[3 * j], bind[3 * child + 1] - bind[3 * j + 1], bind[3 * child + 2] - bind[3 * j + 2]).normalize();
      _z.set(0, 0, 1);
      orthonormalFrame(_d, _z);
      _bindFrame.makeBasis(_x.crossVectors(_d, _z), _d, _z);
      _d.set(positions[3 * child] - positions[3 * j], positions[3 * child + 1] - positions[3 * j + 1], positions[3 * child + 2] - positions[3 * j + 2]);
      _z.copy(j === HIP || j >= L_THIGH ? _hipForward : _chestForward);
      orthonormalFrame(_d, _z);
      _rotation.makeBasis(_x.crossVectors(_d, _z), _d, _z).multiply(_bindFrame.transpose());
    } else if (j === L_FOOT || j === R_FOOT) {
      _rotation.lookAt(_zero, _hipForward, _up).multiply(_flip); // +z onto the hips' facing
    } else {
      _rotation.extractRotation(_bones[j - 1]); // hands follow the forearm, the head the neck
    }
    if (child >= 0) {
      // Turn the bone onto the child's drawn position and stretch it to reach.
      _d.set(bind[3 * child] - bind[3 * j], bind[3 * child + 1] - bind[3 * j + 1], bind[3 * child + 2] - bind[3 * j + 2]);
      const bindLength = _d.length();
      _u.copy(_d).transformDirection(_rotation);
      _v.set(positions[3 * child] - positions[3 * j], positions[3 * child + 1] - positions[3 * j + 1], positions[3 * child + 2] - positions[3 * j + 2]);
      const length = _v.length();
      if (bindLength > 1e-6 && length > 1e-6) {
        _q.setFromUnitVectors(_u, _v.divideScalar(length));
        _rotation.premultiply(_turn.makeRotationFromQuaternion(_q));
        // Scale by length / bindLength along the bind bone direction: I + (s - 1) d dᵀ.
        const s = length / bindLength - 1;
        _d.divideScalar(bindLength);
        _stretch.set(
          1 + s * _d.x * _d.x, s * _d.x * _d.y, s * _d.x * _d.z, 0,
          s * _d.y * _d.x, 1 + s * _d.y * _d.y, s * _d.y * _d.z, 0,
          s * _d.z * _d.x, s * _d.z * _d.y, 1 + s * _d.z * _d.z, 0,
          0, 0, 0, 1,
        );
        _rotation.multiply(_stretch);
      }
    }
    // M = T(p_j) · L · T(-bind_j)
    const m = _bones[j].copy(_rotation);
    _v.set(bind[3 * j], bind[3 * j + 1], bind[3 * j + 2]).applyMatrix4(_rotation);
    m.setPosition(positions[3 * j] - _v.x, positions[3 * j + 1] - _v.y, positions[3 * j + 2] - _v.z);
    out.set(m.elements, 16 * j);
  }
}

/**
 * Joint j's world rotation from the simulation's row-major 3×3 matrices, made orthonormal
 * (interpolated rotations are not quite): Gram-Schmidt on the columns, y first (the bone's up),
 * then z, x = y × z. Shared with the avatars (avatar.ts).
 */
export function jointRotation(rotations: ArrayLike<number>, j: number, out: THREE.Matrix4): THREE.Matrix4 {
  const o = 9 * j;
  _y.set(rotations[o + 1], rotations[o + 4], rotations[o + 7]);
  _z.set(rotations[o + 2], rotations[o + 5], rotations[o + 8]);
  orthonormalFrame(_y, _z);
  return out.makeBasis(_x.crossVectors(_y, _z), _y, _z);
}

/** p unit, q unit and perpendicular to p (q becomes any perpendicular when it runs along p). */
function orthonormalFrame(p: THREE.Vector3, q: THREE.Vector3): void {
  if (p.lengthSq() < 1e-12) p.set(0, 1, 0);
  p.normalize();
  q.addScaledVector(p, -q.dot(p));
  if (q.lengthSq() < 1e-8) {
    q.set(0, 0, 1).addScaledVector(p, -p.z);
    if (q.lengthSq() < 1e-8) q.set(1, 0, 0).addScaledVector(p, -p.x);
  }
  q.normalize();
}

/** Horizontal unit vector the body faces, from a left and a right joint: (left - right) × up. */
function facing(positions: ArrayLike<number>, left: number, right: number, out: THREE.Vector3): void {
  const sx = positions[3 * left] - positions[3 * right];
  const sz = positions[3 * left + 2] - positions[3 * right + 2];
  const length = Math.hypot(sx, sz);
  if (length > 1e-6) out.set(-sz / length, 0, sx / length);
  else out.set(0, 0, 1);
}

const _color = new THREE.Color();
const _v = new THREE.Vector3();
const _u = new THREE.Vector3();
const _d = new THREE.Vector3();
const _x = new THREE.Vector3();
const _y = new THREE.Vector3();
const _z = new THREE.Vector3();
const _q = new THREE.Quaternion();
const _zero = new THREE.Vector3();
const _up = new THREE.Vector3(0, 1, 0);
const _hipForward = new THREE.Vector3();
const _chestForward = new THREE.Vector3();
const _rotation = new THREE.Matrix4();
const _bindFrame = new THREE.Matrix4();
const _turn = new THREE.Matrix4();
const _stretch = new THREE.Matrix4();
// lookAt points -z at the target; this turns it so +z does.
const _flip = new THREE.Matrix4().makeRotationY(Math.PI);
const _bones = Array.from({ length: N_JOINTS }, () => new THREE.Matrix4());
