// The three.js scene: a floor, two dancers (skinned characters, or capsule figures: body.ts) and the
// contact marks under their feet, translucent ghosts, and line + dot overlays for trajectories and
// intentions. Everything is created once; per frame we only write instance matrices and vertex
// positions (no allocation in the draw loop).

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import type { Avatar } from './avatar';
import { type Bodies, ContactMarks, type DancerBody, DancerMeshes, OUTLINE, SkinnedDancer } from './body';
import { type CameraOrbit, ORBIT_LIMITS } from './orbit';
import { type Basis, type FrameWindow, type Rect, cylinderPoints, distanceToFit, frameWindow, viewShift } from './framing';

export { DancerMeshes } from './body';

export interface StageOptions {
  /** 'skinned' (needs `offsets`) or 'sticks'. */
  bodies?: Bodies;
  /** The manifest's bone offsets per role (manifest.skeleton.offsets). */
  offsets?: { leader: number[][]; follower: number[][] };
  /** Show the thin skeleton over the skinned bodies. */
  skeleton?: boolean;
}

/** The possible reactions' colours, one each so that eight of them read as eight, not as one
 *  blur: the partner's red first, then warm and green hues, clear of your dancer's blue and the
 *  intention's purple. */
export const GHOST_TINTS = [0xe0413a, 0xf08a24, 0xc9a400, 0x3fa34d, 0x17a2a0, 0xd6408f, 0x8d5a3b, 0x7a8a00];

export const COLORS = {
  leader: 0x2f6fe4,
  follower: 0xe0413a,
  compare: 0xf0a030,
  /** The partner's guess of the leader's future (intentions): a colour of its own, so the guess
   *  never reads as part of the red dancer. */
  intention: 0x8a4fd8,
  floor: 0xe9e4dc,
  background: 0xf4f1ec,
};

const FLOOR_SIZE = 200; // metres; one grid cell per metre
const TARGET_HEIGHT = 0.9;
/** Metres around the pair's midpoint that the picture always holds, from the floor to above the
 *  heads, from any angle: however close a wheel or a pinch brings the camera (framing.ts). Partners
 *  stand about a metre apart; a dancer who steps out of it backs the camera off (Stage.frameCamera). */
export const PAIR_HALF_WIDTH = 0.8;
/** Seconds in which a camera that backed off for a dancer comes most of the way back (1 - 1/e). */
const HOLD_SECONDS = 2;

/** A polyline with a dot at every point, rewritten in place from a Float32Array of world points. */
export class PathOverlay {
  readonly group = new THREE.Group();
  private readonly positions: Float32Array;
  private readonly line: THREE.Line | THREE.LineSegments;
  private readonly dots: THREE.Points;

  /** `segments`: draw independent polylines of `pointsPerLine` points (e.g. one per key joint). */
  constructor(
    readonly points: number,
    color: number,
    readonly pointsPerLine = points,
  ) {
    this.positions = new Float32Array(points * 3);
    const geometry = new THREE.BufferGeometry();
    const attribute = new THREE.BufferAttribute(this.positions, 3).setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute('position', attribute);
    // Several polylines share one buffer: an index joins consecutive points within each line.
    const lines = points / pointsPerLine;
    const index: number[] = [];
    for (let l = 0; l < lines; l++) {
      for (let i = 0; i < pointsPerLine - 1; i++) index.push(l * pointsPerLine + i, l * pointsPerLine + i + 1);
    }
    geometry.setIndex(index);
    const lineMaterial = new THREE.LineBasicMaterial({ color, transparent: true, opacity: 0.85, depthTest: false });
    this.line = new THREE.LineSegments(geometry, lineMaterial);
    const dotMaterial = new THREE.PointsMaterial({ color, size: 7, sizeAttenuation: false, depthTest: false });
    const dotGeometry = new THREE.BufferGeometry();
    dotGeometry.setAttribute('position', attribute);
    this.dots = new THREE.Points(dotGeometry, dotMaterial);
    for (const object of [this.line, this.dots]) {
      object.frustumCulled = false;
      object.renderOrder = 10; // on top of the dancers' feet
      this.group.add(object);
    }
  }

  /** Floor trajectory: the root then keys of (x, z), drawn slightly above the floor. */
  setFloorPath(rootX: number, rootZ: number, keys: Float32Array, height = 0.02): void {
    const p = this.positions;
    p[0] = rootX;
    p[1] = height;
    p[2] = rootZ;
    for (let k = 1; k < this.points; k++) {
      p[3 * k] = keys[2 * (k - 1)];
      p[3 * k + 1] = height;
      p[3 * k + 2] = keys[2 * (k - 1) + 1];
    }
    this.touch();
  }

  /** Points stored as [key][line][xyz] (the intention layout): regroup them per line. */
  setKeyMajorPoints(points: Float32Array, keys: number, linesCount: number): void {
    const p = this.positions;
    for (let k = 0; k < keys; k++) {
      for (let l = 0; l < linesCount; l++) {
        const from = (k * linesCount + l) * 3;
        const to = (l * keys + k) * 3;
        p[to] = points[from];
        p[to + 1] = points[from + 1];
        p[to + 2] = points[from + 2];
      }
    }
    this.touch();
  }

  private touch(): void {
    const attribute = this.line.geometry.getAttribute('position') as THREE.BufferAttribute;
    attribute.needsUpdate = true;
  }
}

/** A three-quarter view from behind the leader's right shoulder: both dancers visible. */
export const DEFAULT_ORBIT: CameraOrbit = { azimuth: 35, polar: 70, distance: 5.2 };

export class Stage {
  readonly renderer: THREE.WebGLRenderer;
  readonly scene = new THREE.Scene();
  readonly camera: THREE.PerspectiveCamera;
  readonly controls: OrbitControls;
  readonly canvas: HTMLCanvasElement;

  readonly leader: DancerBody;
  /** Ours, and a second (orange) one in compare mode. */
  readonly followers: DancerBody[];
  /** How the leader and the followers are drawn (the ghosts are always capsule figures). */
  readonly bodies: Bodies;
  readonly ghosts: DancerMeshes;
  readonly trajectories: PathOverlay[];
  readonly intentions: PathOverlay[];
  /** Compare mode: a copy of the leader dancing with the second follower, beside the first pair. */
  readonly leaderCopy: DancerBody;
  /** Leader, follower, compare follower, leader copy: the indices of setHandContact. */
  readonly dancers: DancerBody[];
  readonly contacts: ContactMarks;

  private readonly sun: THREE.DirectionalLight;
  private readonly floor: THREE.Mesh;
  private readonly followTarget = new THREE.Vector3(0, TARGET_HEIGHT, 0.4);
  /** What the last render() saw: camera matrices, drawing-buffer size, and a change of look. */
  private readonly rendered = { view: new THREE.Matrix4(), projection: new THREE.Matrix4(), size: new THREE.Vector2(), stale: true };
  /** The controls were updated by needsRender() since the last render(). */
  private controlsUpdated = false;
  /** Metres around the orbit target kept in the picture from any angle (keepInView). */
  private halfWidth = PAIR_HALF_WIDTH;
  /** The part of the canvas the pair is drawn in (CSS px; setFrame), null: all of it. */
  private free: Rect | null = null;
  /** The free part's size as framing.ts reads it (applyFrame). */
  private window: FrameWindow = frameWindow({ left: 0, top: 0, right: 1, bottom: 1 }, 1, 45);
  /** The nearest a wheel or a pinch may bring the camera at its angle now (updateClosest). */
  private closest: number = ORBIT_LIMITS.distance[0];
  /** Points around the cylinder the closest distance keeps in the picture (framing.ts). */
  private cylinder = cylinderPoints(PAIR_HALF_WIDTH, TARGET_HEIGHT);
  /** The distance the visitor chose (a wheel, a pinch, a link, reset view), within ORBIT_LIMITS. */
  private chosen = DEFAULT_ORBIT.distance;
  /** The distance the camera was put at after the last update: a change since is the visitor's. */
  private placed = DEFAULT_ORBIT.distance;
  /** How far the dancers' own heads and feet need the camera, held, and let go slowly. */
  private held = 0;
  private heldAt = 0;

  constructor(container: HTMLElement, parents: number[], maxGhosts: number, options: StageOptions = {}) {
    this.renderer = new THREE.WebGLRenderer({ antialias: true });
    // Phones report devicePixelRatio 3; 2 looks the same and costs less than half the pixels.
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.renderer.shadowMap.enabled = true;
    this.renderer.shadowMap.type = THREE.PCFShadowMap;
    this.canvas = this.renderer.domElement;
    this.canvas.className = 'stage';
    container.appendChild(this.canvas);

    this.scene.background = new THREE.Color(COLORS.background);
    this.scene.fog = new THREE.Fog(COLORS.background, 14, 32);

    this.camera = new THREE.PerspectiveCamera(45, 1, 0.05, 100);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.enableDamping = true;
    this.controls.enablePan = false; // the camera follows the dancers; panning would fight that
    // Limits a drag cannot pass (the same a shared link's camera is clamped to): never straight
    // overhead nor under the floor. How near and how far a wheel or a pinch may bring it is
    // frameCamera()'s: never farther than where the fog begins (14 m), never closer than the pair
    // fits in the free part of the screen, and farther while a dancer needs it.
    this.controls.minDistance = 0;
    this.controls.maxDistance = Infinity;
    this.controls.minPolarAngle = THREE.MathUtils.degToRad(ORBIT_LIMITS.polar[0]);
    this.controls.maxPolarAngle = THREE.MathUtils.degToRad(ORBIT_LIMITS.polar[1]);
    // One finger steers (the joystick in controls.ts); two fingers orbit and zoom.
    this.controls.touches = { ONE: -1 as THREE.TOUCH, TWO: THREE.TOUCH.DOLLY_ROTATE };
    this.controls.target.copy(this.followTarget);
    this.setOrbit(DEFAULT_ORBIT);

    // Light: a soft sky/ground fill plus one shadow-casting sun that travels with the dancers.
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0xb8a898, 1.6));
    this.sun = new THREE.DirectionalLight(0xffffff, 2.2);
    this.sun.castShadow = true;
    this.sun.shadow.mapSize.set(1024, 1024);
    this.sun.shadow.radius = 4;
    this.sun.shadow.bias = -0.0005;
    const s = this.sun.shadow.camera;
    [s.left, s.right, s.top, s.bottom, s.near, s.far] = [-4, 4, 4, -4, 0.5, 20];
    this.scene.add(this.sun, this.sun.target);

    // Grid lines are computed in the floor's fragment shader (see gridFloorMaterial): no line
    // geometry (lines that pass behind the camera are dropped by some software rasterizers) and
    // no texture fetches; fwidth() keeps them one pixel wide and free of shimmer at any distance.
    const floorMaterial = gridFloorMaterial();
    this.floor = new THREE.Mesh(new THREE.PlaneGeometry(FLOOR_SIZE, FLOOR_SIZE).rotateX(-Math.PI / 2), floorMaterial);
    this.floor.receiveShadow = true;
    this.scene.add(this.floor);

    const solid = (color: number) => new THREE.MeshStandardMaterial({ color, roughness: 0.55, metalness: 0.05 });
    const offsets = options.offsets;
    this.bodies = options.bodies === 'sticks' || !offsets ? 'sticks' : 'skinned';
    const dancer = (color: number, kind: 'leader' | 'follower'): DancerBody =>
      offsets && this.bodies === 'skinned'
        ? new SkinnedDancer(parents, offsets[kind], { kind, color }, true)
        : new DancerMeshes(parents, 1, solid(color), true);
    this.leader = dancer(COLORS.leader, 'leader');
    this.followers = [dancer(COLORS.follower, 'follower'), dancer(COLORS.compare, 'follower')];
    this.leaderCopy = dancer(COLORS.leader, 'leader');
    this.leaderCopy.setCount(0);
    this.dancers = [this.leader, ...this.followers, this.leaderCopy];
    this.skeleton = options.skeleton ?? false;
    this.contacts = new ContactMarks(this.dancers.length);
    // White: each ghost takes its own tint (GHOST_TINTS) as instance colours.
    const ghostMaterial = new THREE.MeshStandardMaterial({
      color: 0xffffff,
      transparent: true,
      opacity: 0.24,
      depthWrite: false, // overlapping translucent ghosts should blend, not hide each other
    });
    this.ghosts = new DancerMeshes(parents, Math.max(1, maxGhosts), ghostMaterial, false);
    for (let i = 0; i < this.ghosts.capacity; i++) this.ghosts.tint(i, GHOST_TINTS[i % GHOST_TINTS.length]);
    this.ghosts.setCount(0);
    this.scene.add(this.leader.group, this.ghosts.group, ...this.followers.map((f) => f.group), this.leaderCopy.group, this.contacts.group);

    // Trajectories: root + 6 future keys. Intentions: 5 key joints × 6 keys.
    this.trajectories = [COLORS.leader, COLORS.follower, COLORS.compare].map((c) => new PathOverlay(7, c));
    this.intentions = [COLORS.intention, COLORS.intention].map((c) => new PathOverlay(30, c, 6));
    for (const overlay of [...this.trajectories, ...this.intentions]) this.scene.add(overlay.group);

    this.resize();
    window.addEventListener('resize', () => this.resize());
    // Layout changes that are not window resizes (mobile URL bar, panels) also change the size.
    new ResizeObserver(() => this.resize()).observe(container);
  }

  /** The thin skeleton over the skinned bodies (nothing to change with capsule figures). */
  get skeleton(): boolean {
    return this.dancers.some((d) => d instanceof SkinnedDancer && d.skeleton);
  }
  set skeleton(on: boolean) {
    for (const d of this.dancers) if (d instanceof SkinnedDancer) d.skeleton = on;
    this.rendered.stale = true;
  }

  /**
   * Whether a render now would differ from the last one, for a scene in which nothing else moves
   * (the standing pair while the models load): the camera moved (a drag, the controls' damping,
   * a view offset), the canvas changed size, or the look changed. Advances the controls' damping
   * itself; the render() that follows does not advance it a second time.
   */
  needsRender(): boolean {
    this.controls.update();
    this.frameCamera();
    this.controlsUpdated = true;
    const { rendered } = this;
    return rendered.stale || !rendered.view.equals(this.camera.matrixWorld) || !rendered.projection.equals(this.camera.projectionMatrix) ||
      !rendered.size.equals(this.renderer.getDrawingBufferSize(_size));
  }

  resize(): void {
    const parent = this.canvas.parentElement ?? document.body;
    const width = Math.max(1, parent.clientWidth);
    const height = Math.max(1, parent.clientHeight);
    // Setting a canvas's size, even to the one it has, reallocates its drawing buffer: the resize
    // observer's first call (same size, right after the constructor's) would pay for it again.
    const now = this.renderer.getSize(_size);
    if (now.x === width && now.y === height) return;
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.applyFrame();
  }

  /**
   * Draw the pair in `free`, the part of the canvas (CSS px from its top-left) that the title card
   * and the panel leave (web/ui/layout.ts): the picture's centre moves to its middle (a view
   * offset: the orbit, the steering and the follow target are unchanged), and the camera comes no
   * closer than the pair fits in it. On a phone with the settings sheet open the pair stood in the
   * middle of the whole screen, heads under the title card and legs under the sheet.
   */
  setFrame(free: Rect): void {
    if (free === this.free) return;
    this.free = free;
    this.applyFrame();
  }

  /** The free part's view offset and closest distance, for this canvas size and halfWidth. */
  private applyFrame(): void {
    const width = this.renderer.getSize(_size).x, height = _size.y;
    const free = this.free ?? { left: 0, top: 0, right: width, bottom: height };
    const [x, y] = viewShift(free, width, height);
    if (x !== 0 || y !== 0) this.camera.setViewOffset(width, height, x, y, width, height);
    else this.camera.clearViewOffset();
    this.camera.updateProjectionMatrix();
    this.window = frameWindow(free, height, this.camera.fov);
    this.held = 0; // what the dancers needed in the old frame says nothing about the new one
    this.cylinder = cylinderPoints(this.halfWidth, TARGET_HEIGHT);
    this.updateClosest();
  }

  /** The closest distance for the camera's angle now: the cylinder fits (framing.ts). */
  private updateClosest(): void {
    this.camera.updateMatrixWorld();
    cameraBasis(this.camera, _basis);
    this.closest = Math.max(ORBIT_LIMITS.distance[0], distanceToFit(this.cylinder, this.cylinder.length / 3, _basis, this.window));
  }

  /**
   * Keep `halfWidth` metres around the orbit target (the pair's midpoint; in compare mode both
   * pairs), from the floor to above the heads, in the picture: the camera may come no closer than
   * that allows in the free part of this screen, at the angle it looks from (a drag to a low
   * angle backs it off in the same frame). Returns that distance, for the angle now.
   */
  keepInView(halfWidth: number): number {
    this.halfWidth = halfWidth;
    this.applyFrame();
    return this.closest;
  }

  /**
   * After each update of the controls: the camera at the distance the visitor chose, within the
   * limits (ORBIT_LIMITS.distance, and no closer than the pair fits: keepInView), or farther while a
   * dancer's head or feet need it (a step out of the cylinder, a turn at arm's length). The
   * camera backs off at once (the frame on screen holds them whole) and comes back slowly.
   */
  private frameCamera(): void {
    const target = this.controls.target;
    _offset.copy(this.camera.position).sub(target);
    const radius = _offset.length() || 1;
    this.updateClosest();
    // Within the limits of this layout (kept apart from the choice itself: when the sheet folds
    // again the camera comes back to where the visitor had it).
    const within = (d: number) => Math.min(Math.max(ORBIT_LIMITS.distance[1], this.closest), Math.max(this.closest, d));
    // A change since the last frame is the visitor's zoom (a wheel turn, a pinch), by a factor of
    // the distance they chose; within this layout's limits, so that no turn of the wheel is lost
    // beyond them.
    if (Math.abs(radius - this.placed) > 1e-6) this.chosen = clampDistance(within((this.chosen * radius) / this.placed));
    const chosen = within(this.chosen);
    const need = this.outlineNeed();
    const now = performance.now();
    const dt = this.heldAt > 0 ? Math.min(1, (now - this.heldAt) / 1000) : 0;
    this.heldAt = now;
    this.held = need >= this.held ? need : need + (this.held - need) * Math.exp(-dt / HOLD_SECONDS);
    const distance = Math.max(chosen, this.held);
    if (Math.abs(distance - radius) > 1e-9) {
      this.camera.position.copy(target).addScaledVector(_offset, distance / radius);
      this.camera.updateMatrixWorld();
    }
    this.placed = distance;
  }

  /** The distance the drawn dancers' heads and feet need (framing.ts), looking as the camera looks
   *  (_basis, as updateClosest() just set it). */
  private outlineNeed(): number {
    const target = this.controls.target;
    let need = 0;
    for (const dancer of this.dancers) {
      if (!dancer.group.visible) continue;
      const points = dancer.outline(_outline);
      for (let i = 0; i < points.length; i += 3) {
        points[i] -= target.x;
        points[i + 1] -= target.y;
        points[i + 2] -= target.z;
      }
      need = Math.max(need, distanceToFit(points, OUTLINE.length, _basis, this.window));
    }
    return need;
  }

  /** Keep the pair in view: move the orbit target (and the camera with it) toward their midpoint. */
  follow(midX: number, midZ: number, dt: number, snap = false): void {
    const blend = snap ? 1 : 1 - Math.exp(-4 * dt);
    _delta.set(midX, TARGET_HEIGHT, midZ).sub(this.followTarget).multiplyScalar(blend);
    this.followTarget.add(_delta);
    this.camera.position.add(_delta);
    // The camera turns around the pair, and around nothing else, whatever a gesture did.
    this.controls.target.copy(this.followTarget);
    // The floor jumps by whole grid cells so it looks infinite without visibly moving.
    this.floor.position.x = Math.round(this.followTarget.x);
    this.floor.position.z = Math.round(this.followTarget.z);
    this.sun.target.position.set(this.followTarget.x, 0, this.followTarget.z);
    this.sun.position.set(this.followTarget.x + 3, 8, this.followTarget.z + 2);
  }

  /** Where the camera is; `distance` is the one the visitor chose (it may stand farther while a
   *  dancer needs it, or the sheet is open: frameCamera), which a link keeps. */
  getOrbit(): CameraOrbit {
    _offset.copy(this.camera.position).sub(this.controls.target);
    _spherical.setFromVector3(_offset);
    const moved = Math.abs(_spherical.radius - this.placed) > 1e-6;
    return {
      azimuth: THREE.MathUtils.radToDeg(_spherical.theta) + 180,
      polar: THREE.MathUtils.radToDeg(_spherical.phi),
      distance: moved ? clampDistance((this.chosen * _spherical.radius) / this.placed) : this.chosen,
    };
  }

  /** The first view again (DEFAULT_ORBIT), the glide left from a drag stopped. */
  resetView(): void {
    // Without damping, update() spends what is left of a drag's glide at once, and zeroes it.
    this.controls.enableDamping = false;
    this.controls.update();
    this.controls.enableDamping = true;
    this.setOrbit(DEFAULT_ORBIT);
  }

  /** azimuth 0 puts the camera at -z of the target, looking along +z. */
  setOrbit(orbit: CameraOrbit): void {
    _spherical.set(orbit.distance, THREE.MathUtils.degToRad(orbit.polar), THREE.MathUtils.degToRad(orbit.azimuth - 180));
    _offset.setFromSpherical(_spherical);
    this.camera.position.copy(this.controls.target).add(_offset);
    this.camera.lookAt(this.controls.target);
    this.controls.update();
    // The visitor's distance now (frameCamera puts the camera farther if the pair needs it).
    this.chosen = clampDistance(orbit.distance);
    this.placed = this.camera.position.distanceTo(this.controls.target);
  }

  /** The camera's viewing direction projected on the floor, normalized: "forward" for steering. */
  viewForward(out: { x: number; z: number }): void {
    this.camera.getWorldDirection(_offset);
    const length = Math.hypot(_offset.x, _offset.z) || 1;
    out.x = _offset.x / length;
    out.z = _offset.z / length;
  }

  /**
   * The dancer ('leader' or the first 'follower') drawn nearest to a point of the page (client
   * pixels): the one a file dropped there is for. Measured from each dancer's hips.
   */
  nearestDancer(clientX: number, clientY: number): 'leader' | 'follower' {
    const distance = (dancer: 'leader' | 'follower') => {
      const at = this.screenPoint(dancer);
      return at ? Math.hypot(at[0] - clientX, at[1] - clientY) : Infinity;
    };
    return distance('follower') < distance('leader') ? 'follower' : 'leader';
  }

  /** Where a dancer's hips were last drawn, in client pixels (null for capsule figures). */
  screenPoint(dancer: 'leader' | 'follower'): [number, number] | null {
    const body = dancer === 'leader' ? this.leader : this.followers[0];
    if (!(body instanceof SkinnedDancer)) return null;
    const rect = this.canvas.getBoundingClientRect();
    _offset.setFromMatrixPosition(body.boneMatrix(0)).project(this.camera);
    return [rect.left + ((_offset.x + 1) / 2) * rect.width, rect.top + ((1 - _offset.y) / 2) * rect.height];
  }

  /**
   * Where a dancer's head top, toes and heels (body.ts OUTLINE) were last drawn, client pixels, or
   * null for capsule figures: what the framing keeps clear of the title card and the panel.
   */
  outline(dancer: 'leader' | 'follower'): [number, number][] | null {
    const body = dancer === 'leader' ? this.leader : this.followers[0];
    if (!(body instanceof SkinnedDancer)) return null;
    const rect = this.canvas.getBoundingClientRect();
    const world = body.outline(_outline);
    const points: [number, number][] = [];
    for (let i = 0; i < OUTLINE.length; i++) {
      _offset.fromArray(world, 3 * i).project(this.camera);
      points.push([rect.left + ((_offset.x + 1) / 2) * rect.width, rect.top + ((1 - _offset.y) / 2) * rect.height]);
    }
    return points;
  }

  /** Dress a dancer in `avatar` (null: its own body again); false when the bodies are sticks. */
  dress(dancer: 'leader' | 'follower', avatar: Avatar | null): boolean {
    const body = dancer === 'leader' ? this.leader : this.followers[0];
    if (!(body instanceof SkinnedDancer)) return false;
    body.dress(avatar);
    this.rendered.stale = true;
    return true;
  }

  /**
   * How much hand `hand` (0 left, 1 right) of dancer `dancer` (0 leader, 1 follower, 2 compare
   * follower) is in contact, 0..1: above 0 a soft glow shows at that hand. Holds until set again;
   * call it every frame (or whenever the contact layer's weights change), before render().
   */
  setHandContact(dancer: number, hand: number, weight: number): void {
    const d = this.dancers[dancer];
    if (d && (hand === 0 || hand === 1)) d.handContact[hand] = Number.isFinite(weight) ? Math.min(1, Math.max(0, weight)) : 0;
  }

  /**
   * Draw everything the scene can show once, hidden things included (the paths, intentions,
   * ghosts, contact marks, the skeleton and the compare pair are hidden while the models load),
   * then the scene as it is. Why a real draw and not only compiling the shaders: GPU drivers
   * finish a pipeline only when it first draws (the phone bench's software GPU compiles each
   * one then), and the first dancing frame waited about 0.2 s longer for that. Done while the models
   * download, this costs nothing anyone waits for; the second draw leaves the picture unchanged.
   */
  warmUp(): void {
    const restore: (() => void)[] = [];
    this.scene.traverse((object) => {
      if (!object.visible) {
        object.visible = true;
        restore.push(() => (object.visible = false));
      }
      if (object instanceof THREE.InstancedMesh && object.count === 0) {
        object.count = 1;
        restore.push(() => (object.count = 0));
      }
    });
    this.renderer.render(this.scene, this.camera);
    for (const undo of restore) undo();
    this.renderer.render(this.scene, this.camera);
  }

  render(): void {
    this.contacts.update(this.dancers);
    if (!this.controlsUpdated) this.controls.update();
    this.controlsUpdated = false;
    this.frameCamera();
    this.renderer.render(this.scene, this.camera);
    const { rendered } = this;
    rendered.view.copy(this.camera.matrixWorld);
    rendered.projection.copy(this.camera.projectionMatrix);
    this.renderer.getDrawingBufferSize(rendered.size);
    rendered.stale = false;
  }
}

/** A distance within the limits a link and the visitor's zoom keep to (ORBIT_LIMITS.distance). */
function clampDistance(distance: number): number {
  return Math.min(ORBIT_LIMITS.distance[1], Math.max(ORBIT_LIMITS.distance[0], distance));
}

/** The camera's right, up and forward axes (world) from its matrix (after updateMatrixWorld). */
function cameraBasis(camera: THREE.Camera, out: { right: number[]; up: number[]; forward: number[] }): void {
  const e = camera.matrixWorld.elements;
  out.right[0] = e[0]; out.right[1] = e[1]; out.right[2] = e[2];
  out.up[0] = e[4]; out.up[1] = e[5]; out.up[2] = e[6];
  out.forward[0] = -e[8]; out.forward[1] = -e[9]; out.forward[2] = -e[10];
}

/** A Lambert floor with 1 m grid lines (and darker lines every 5 m) drawn by its shader. */
function gridFloorMaterial(): THREE.MeshLambertMaterial {
  const material = new THREE.MeshLambertMaterial({ color: COLORS.floor });
  material.onBeforeCompile = (shader) => {
    shader.vertexShader = shader.vertexShader
      .replace('#include <common>', '#include <common>\nvarying vec2 vFloor;')
      .replace('#include <begin_vertex>', '#include <begin_vertex>\nvFloor = (modelMatrix * vec4(position, 1.0)).xz;');
    shader.fragmentShader = shader.fragmentShader
      .replace('#include <common>', '#include <common>\nvarying vec2 vFloor;\nfloat gridLine(vec2 p) { vec2 d = abs(fract(p - 0.5) - 0.5) / fwidth(p); return 1.0 - min(min(d.x, d.y), 1.0); }')
      .replace(
        '#include <color_fragment>',
        '#include <color_fragment>\ndiffuseColor.rgb *= 1.0 - 0.16 * gridLine(vFloor) - 0.14 * gridLine(vFloor / 5.0);',
      );
  };
  return material;
}

// Scratch objects shared by the per-frame code above.
const _delta = new THREE.Vector3();
const _offset = new THREE.Vector3();
const _spherical = new THREE.Spherical();
const _size = new THREE.Vector2();
const _outline = new Float32Array(3 * OUTLINE.length);
const _basis: Basis & { right: number[]; up: number[]; forward: number[] } = { right: [1, 0, 0], up: [0, 1, 0], forward: [0, 0, -1] };
