"""The 17-joint duet skeleton: reduction from BVH, metres, resampling, root, mirroring.

A `Motion` holds one dancer as world-space joint positions and rotations per frame. Everything
downstream (features, evaluation, export of the skeleton to the page) starts from it.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .bvh import Bvh, BvhError, forward_kinematics, local_transforms

# BVH units -> metres. The shared CMU files were rescaled so that a dancer's head joint sits at
# about 1.11 units; 1.5 puts it at about 1.66 m, a plausible adult head-joint height.
SCALE = 1.5
FPS = 30

JOINT_NAMES = [
    "hip", "abdomen", "chest", "neck", "head",
    "lShldr", "lForeArm", "lHand", "rShldr", "rForeArm", "rHand",
    "lThigh", "lShin", "lFoot", "rThigh", "rShin", "rFoot",
]
PARENTS = [-1, 0, 1, 2, 3, 2, 5, 6, 2, 8, 9, 0, 11, 12, 0, 14, 15]
HEAD = JOINT_NAMES.index("head")
HANDS = [JOINT_NAMES.index("lHand"), JOINT_NAMES.index("rHand")]      # 7, 10
# The torso as a chain hip -> abdomen -> chest -> neck (the partners' bodies must not cross it).
SPINE = [JOINT_NAMES.index(n) for n in ("hip", "abdomen", "chest", "neck")]  # 0, 1, 2, 3
FEET = [JOINT_NAMES.index("lFoot"), JOINT_NAMES.index("rFoot")]       # 13, 16 (the ankles)
# Head, both hands, both feet: the paper's five key joints for trajectories and intention.
KEY_JOINTS = [HEAD, *HANDS, *FEET]                                   # 4, 7, 10, 13, 16
# Index of each joint's left/right twin (itself for the spine).
MIRROR = [JOINT_NAMES.index(("r" + n[1:]) if n[0] == "l" and n[1].isupper()
                            else ("l" + n[1:]) if n[0] == "r" and n[1].isupper() else n)
          for n in JOINT_NAMES]


@dataclass
class Motion:
    positions: np.ndarray   # [F, 17, 3] world, metres
    rotations: np.ndarray   # [F, 17, 3, 3] world
    offsets: np.ndarray     # [17, 3] metres, in the parent's frame
    fps: float

    @property
    def frames(self) -> int:
        return self.positions.shape[0]

    def local_rotations(self) -> np.ndarray:
        """[F, 17, 3, 3] rotation of each joint relative to its parent (the hip's is world)."""
        local = self.rotations.copy()
        for j, p in enumerate(PARENTS):
            if p >= 0:
                local[:, j] = np.swapaxes(self.rotations[:, p], -1, -2) @ self.rotations[:, j]
        return local


def reduce_bvh(bvh: Bvh, source: str = "<bvh>") -> Motion:
    """Full-skeleton FK, then keep the 17 moving joints.

    Dropped joints between two kept ones (collars, buttocks) must not rotate: their constant
    rotation and offset are folded into the child's offset, so FK on the reduced skeleton
    reproduces the full skeleton's positions exactly.
    """
    missing = [n for n in JOINT_NAMES if n not in bvh.names]
    if missing:
        raise BvhError(f"{source}: skeleton lacks joint(s) {', '.join(missing)}")
    local_rot, local_pos = local_transforms(bvh)
    world_rot, world_pos = forward_kinematics(bvh.parents, local_rot, local_pos)
    index = [bvh.names.index(n) for n in JOINT_NAMES]
    for j, name in enumerate(JOINT_NAMES):
        p = PARENTS[j]
        if p < 0:
            if bvh.parents[index[j]] != -1:
                raise BvhError(f"{source}: '{name}' must be the root joint")
            continue
        # Walk up the full hierarchy from the kept joint to its kept parent.
        a = bvh.parents[index[j]]
        while a != index[p]:
            if a < 0:
                raise BvhError(f"{source}: '{name}' is not below '{JOINT_NAMES[p]}'")
            if np.abs(local_rot[:, a] - local_rot[:1, a]).max() > 1e-6:
                raise BvhError(f"{source}: joint '{bvh.names[a]}' rotates; cannot reduce")
            a = bvh.parents[a]
    positions = world_pos[:, index] * SCALE
    rotations = world_rot[:, index]
    offsets = np.zeros((len(JOINT_NAMES), 3))
    for j, p in enumerate(PARENTS):
        if p >= 0:  # constant through time by the check above; take frame 0
            offsets[j] = rotations[0, p].T @ (positions[0, j] - positions[0, p])
    return Motion(positions, rotations, offsets, bvh.fps)


def resample(motion: Motion, fps: float = FPS, phase: int = 0) -> Motion:
    """Keep every n-th frame starting at `phase` (120 fps -> 30 fps gives 4 phases per take).

    The source rate must be a whole multiple of the target rate: no interpolation is needed then,
    and every phase is a real recorded frame.
    """
    step = motion.fps / fps
    if abs(step - round(step)) > 1e-3 or round(step) < 1:
        raise ValueError(f"cannot resample {motion.fps:g} fps to {fps:g} fps (not a whole multiple)")
    step = int(round(step))
    if not 0 <= phase < step:
        raise ValueError(f"phase {phase} out of range 0..{step - 1}")
    return replace(motion, positions=motion.positions[phase::step],
                   rotations=motion.rotations[phase::step], fps=fps)


def time_warp(motion: Motion, tempo: float, fps: float = FPS, phase: int = 0) -> Motion:
    """The motion played `tempo` times as fast, sampled at `fps` from source frame `phase` on.

    Tempo augmentation for training: a frame falls between two source frames, so positions
    are blended linearly and rotations blended and re-orthonormalized (nearest polar rotation).
    That rotation lies on slerp's arc, a little off its timing: between neighbouring 120 fps
    frames of the CMU takes a joint turns by up to about 40 degrees (99.9th percentile of each
    take; glitches reach 87), where the blend is at most 0.32 degrees off slerp (3.6 at 87).
    At tempo 1 with a whole-multiple rate it is `resample`, frame for frame.
    """
    if tempo <= 0:
        raise ValueError(f"tempo must be positive, got {tempo}")
    base = motion.fps / fps
    if abs(base - round(base)) < 1e-3:    # as resample: the CMU files' 120.0048 fps read as 120
        base = round(base)
    step = base * tempo                   # source frames per output frame
    t = phase + step * np.arange(int((motion.frames - 1 - phase) / step) + 1)
    i0 = np.minimum(np.floor(t).astype(int), motion.frames - 1)
    i1 = np.minimum(i0 + 1, motion.frames - 1)
    w = (t - i0)[:, None, None]
    positions = (1 - w) * motion.positions[i0] + w * motion.positions[i1]
    blend = (1 - w[..., None]) * motion.rotations[i0] + w[..., None] * motion.rotations[i1]
    u, _, vt = np.linalg.svd(blend)
    rotations = u @ vt
    return replace(motion, positions=positions, rotations=rotations, fps=fps)


def gaussian_smooth(x: np.ndarray, sigma: float) -> np.ndarray:
    """Smooth along axis 0 with edge padding (no shift, no shrinking at the ends)."""
    if sigma <= 0:
        return x.copy()
    r = int(np.ceil(3 * sigma))
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    k /= k.sum()
    pad = np.concatenate([np.repeat(x[:1], r, 0), x, np.repeat(x[-1:], r, 0)], 0)
    out = np.zeros_like(x, dtype=np.float64)
    for i, w in enumerate(k):
        out += w * pad[i:i + len(x)]
    return out


# Root smoothing in frames at 30 fps: removes the hip's side-to-side sway from the root without
# lagging turns (a 0.07 s standard deviation).
ROOT_SMOOTHING = 2.0


def facing_direction(positions: np.ndarray) -> np.ndarray:
    """[..., 17, 3] -> [..., 2] unit floor vector (x, z) the body faces (hips and shoulders)."""
    J = JOINT_NAMES.index
    across = (positions[..., J("lThigh"), :] - positions[..., J("rThigh"), :]
              + positions[..., J("lShldr"), :] - positions[..., J("rShldr"), :])
    # forward = across x up, with up = +Y: (ax, ay, az) x (0, 1, 0) = (-az, 0, ax)
    fwd = np.stack([-across[..., 2], across[..., 0]], -1)
    return fwd / np.maximum(np.linalg.norm(fwd, axis=-1, keepdims=True), 1e-9)


def root_from_motion(motion: Motion, smoothing: float = ROOT_SMOOTHING):
    """Root per frame: floor position [F, 2] (x, z) and heading [F] (radians, 0 = facing +Z)."""
    root = gaussian_smooth(motion.positions[:, 0, [0, 2]], smoothing)
    fwd = gaussian_smooth(facing_direction(motion.positions), smoothing)
    heading = np.arctan2(fwd[:, 0], fwd[:, 1])
    return root, heading


def mirror_motion(motion: Motion) -> Motion:
    """Reflect through the YZ plane (x -> -x) and swap left and right joints.

    A reflected rotation is M R M with M = diag(-1, 1, 1), which keeps it a proper rotation.
    """
    M = np.diag([-1.0, 1.0, 1.0])
    positions = motion.positions[:, MIRROR] @ M
    rotations = M @ motion.rotations[:, MIRROR] @ M
    offsets = motion.offsets[MIRROR] @ M
    return replace(motion, positions=positions, rotations=rotations, offsets=offsets)


def forward_kinematics_reduced(offsets: np.ndarray, hip_position: np.ndarray,
                               rotations: np.ndarray) -> np.ndarray:
    """World positions [..., 17, 3] from world rotations and the hip position: bone lengths exact."""
    positions = np.empty(rotations.shape[:-2] + (3,))
    positions[..., 0, :] = hip_position
    for j, p in enumerate(PARENTS):
        if p >= 0:
            positions[..., j, :] = positions[..., p, :] + np.einsum(
                "...ij,j->...i", rotations[..., p, :, :], offsets[j])
    return positions
