"""Procedural dancers, and synthetic BVH couples in the data layout: `python -m training.data.synthetic`.

    python -m training.data.synthetic --data data/synthetic          # 12 couples, the CMU take names
    python -m training.data.prepare --data data/synthetic            # ... then the usual pipeline

The couples stand in for the CMU salsa takes where those are absent (a fresh clone, CI without the
data): the tests and the whole pipeline (prepare -> train -> export -> evaluate -> soak) run on
them. They are not dance: each dancer circles a drifting centre facing its partner, stepping
(a leg swings half a cycle and stands planted the other half) and swinging its joints sinusoidally
with seeded random amplitudes and phases. The follower repeats the leader's path around the
centre a moment later (FOLLOW_LAG), so there is something for a follower model to learn. Every few
seconds (TURN_EVERY) he leads her turn: his left hand goes up over her (LEAD_SECONDS before) and she
spins once round (TURN_SPIN seconds), either way, so the turn and lead measures have turns of both
ways to find. Their hips sway a little on each step, so that the hips' step turns back now and then
as a recorded dancer's does.

Files look like the CMU ones to the loader: SUBJECT_TAKE.bvh, subjects 60 (lead) and 61 (follow),
the take names and frame counts of the CMU takes (CMU_TAKES), 120 fps, CMU joint names, the
17 moving joints plus constant collars and buttocks (which training/mirror/skeleton.py folds away), Y up,
1 unit = 1 / skeleton.SCALE m. Nothing here is recorded motion.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from ..mirror.bvh import axis_rotation
from ..mirror.rollout import rotation_y
from ..mirror.skeleton import FPS, JOINT_NAMES, PARENTS, SCALE, Motion, forward_kinematics_reduced

# The CMU salsa takes of subjects 60 (lead) and 61 (follow): name -> frames at 120 fps.
CMU_TAKES = {"01": 2242, "02": 2101, "03": 1830, "04": 1871, "06": 1772, "07": 2071,
             "09": 2575, "10": 1197, "11": 2108, "12": 1690, "13": 2271, "15": 2140}
CMU_SUBJECTS = ("60", "61")
CMU_FPS = 120
FOLLOW_LAG = 0.25          # s the follower's path around the centre trails the leader's
FOLLOWER_SIZE = 0.93       # her bones as a share of his
TURN_EVERY = (2.0, 4.0)    # s between the starts of her led turns (uniform)
TURN_SPIN = 1.0            # s her turn takes: 360 degrees
LEAD_SECONDS = 1.0         # s his hand is up before her turn starts (and stays up through it)
HIP_SWAY = 0.08            # m of the hips' side-to-side sway on each step
HIP_SHAKE = 0.005          # m (standard deviation) the hips are shaken in each frame

# Offsets (metres) of a plausible 17-joint dancer: arms out along x (a T pose at rest), legs down.
OFFSETS = np.array([
    [0, 0, 0], [0, 0.10, 0], [0, 0.18, 0.01], [0, 0.25, -0.01], [0, 0.12, 0.02],
    [0.18, 0.20, 0], [0.28, 0, 0], [0.25, 0, 0],
    [-0.18, 0.20, 0], [-0.28, 0, 0], [-0.25, 0, 0],
    [0.09, -0.06, 0], [0, -0.44, 0.01], [0, -0.42, -0.02],
    [-0.09, -0.06, 0], [0, -0.44, 0.01], [0, -0.42, -0.02],
], dtype=np.float64)


def euler(angles_deg: np.ndarray) -> np.ndarray:
    """[F, 3] (x, y, z) degrees -> [F, 3, 3] as Rz Rx Ry (the CMU channel order)."""
    return (axis_rotation("Z", angles_deg[:, 2]) @ axis_rotation("X", angles_deg[:, 0])
            @ axis_rotation("Y", angles_deg[:, 1]))


def euler_zxy(rotations: np.ndarray) -> np.ndarray:
    """[..., 3, 3] -> [..., 3] (z, x, y) degrees with R = Rz Rx Ry: the inverse of `euler`."""
    r = rotations
    x = np.arcsin(np.clip(r[..., 2, 1], -1, 1))
    z = np.arctan2(-r[..., 0, 1], r[..., 1, 1])
    y = np.arctan2(-r[..., 2, 0], r[..., 2, 2])
    return np.degrees(np.stack([z, x, y], -1))


def procedural_dancer(rng: np.random.Generator, frames: int, centre_angle: np.ndarray,
                      offsets: np.ndarray, scale: float, fps: float = FPS,
                      centre: np.ndarray | None = None) -> Motion:
    """A dancer on a circle around a drifting centre, facing the centre, stepping and swinging.
    `centre` [frames, 2] is the circle's centre (x, z) per frame (default: a slow straight drift)."""
    t = np.arange(frames) / fps
    J = len(PARENTS)
    local = np.empty((frames, J, 3, 3))
    # Sinusoidal joint angles with random amplitudes and phases, plus seeded random jitter.
    amp = rng.uniform(3, 25, (J, 3))
    freq = rng.uniform(0.5, 2.5, (J, 3))
    phase = rng.uniform(0, 2 * np.pi, (J, 3))
    angles = amp * np.sin(2 * np.pi * freq * t[:, None, None] + phase) + rng.normal(0, 0.3, (frames, J, 3))
    angles[:, 5, 2] -= 70    # left arm down from the T pose
    angles[:, 8, 2] += 70    # right arm down
    # Legs step in turn: each swings through half a cycle and stands still (planted) the other half.
    step = np.sin(2 * np.pi * 1.2 * t)
    angles[:, 11:17] = 0
    angles[:, 11, 0] = 30 * np.maximum(0, step)
    angles[:, 14, 0] = 30 * np.maximum(0, -step)
    angles[:, 12, 0] = -25 * np.maximum(0, step)
    angles[:, 15, 0] = -25 * np.maximum(0, -step)
    angles[:, 0] *= 0.1
    for j in range(J):
        local[:, j] = euler(angles[:, j])
    # Circle around a drifting centre, facing it (heading = atan2 of the direction to the centre).
    if centre is None:
        centre = np.stack([0.12 * t - 0.3, 0.05 * t + 0.2], -1)
    pos = centre + scale * np.stack([np.cos(centre_angle), np.sin(centre_angle)], -1)
    to_centre = centre - pos
    facing = np.arctan2(to_centre[:, 0], to_centre[:, 1]) + 0.1 * np.sin(2 * np.pi * 0.7 * t)
    local[:, 0] = np.stack([rotation_y(h) for h in facing]) @ local[:, 0]
    world = np.empty_like(local)
    for j, p in enumerate(PARENTS):
        world[:, j] = local[:, j] if p < 0 else world[:, p] @ local[:, j]
    hip = np.stack([pos[:, 0], 1.0 + 0.02 * np.sin(2 * np.pi * 2.4 * t), pos[:, 1]], -1)
    positions = forward_kinematics_reduced(offsets, hip, world)
    return Motion(np.round(positions, 6), np.round(world, 6), offsets, float(fps))


def wander(rng: np.random.Generator, size: float):
    """A smooth wandering value as a function of time in seconds: the mean of three sinusoids of
    amplitude `size`, random period (4-20 s) and phase."""
    period, phase = rng.uniform(4, 20, 3), rng.uniform(0, 2 * np.pi, 3)
    return lambda t: size * np.sin(2 * np.pi * np.asarray(t)[..., None] / period + phase).mean(-1)


def synthetic_couple(rng: np.random.Generator, frames: int, fps: float = CMU_FPS) -> tuple[Motion, Motion]:
    """(leader, follower) of one take: both on one circle around a wandering centre, facing each
    other; the follower's place on the circle and the centre trail the leader's by FOLLOW_LAG."""
    t = np.arange(frames) / fps
    cx, cz, turn = wander(rng, 1.5), wander(rng, 1.5), wander(rng, 2.0)
    centre = lambda s: np.stack([cx(s), cz(s)], -1)            # noqa: E731  (x, z) of the circle's centre
    angle = lambda s: 0.6 * s + turn(s)                        # noqa: E731  the leader's place on it
    radius = rng.uniform(0.35, 0.5)
    # The same two dancers in every take, as the CMU subjects 60 and 61 are (training reads one
    # skeleton per dancer): he at OFFSETS, she a little smaller.
    lead_offsets, follow_offsets = OFFSETS, np.round(OFFSETS * FOLLOWER_SIZE, 6)
    leader = procedural_dancer(rng, frames, angle(t), lead_offsets, radius, fps, centre(t))
    lag = t - FOLLOW_LAG
    follower = procedural_dancer(rng, frames, angle(lag) + np.pi, follow_offsets, radius, fps, centre(lag))
    spin, lift = led_turns(rng, t)
    return sway(rng, raise_hand(leader, lift), t), sway(rng, spun(follower, spin), t + 0.3)


def led_turns(rng: np.random.Generator, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Her extra facing [F] (radians: one full turn, either way, every TURN_EVERY seconds) and how
    far his left hand is raised for it [F] (0 down, 1 over her head)."""
    spin, lift = np.zeros(len(t)), np.zeros(len(t))
    start = rng.uniform(*TURN_EVERY)
    while start + TURN_SPIN < t[-1]:
        way = rng.choice([-1.0, 1.0])
        u = np.clip((t - start) / TURN_SPIN, 0, 1)
        spin += way * 2 * np.pi * (3 * u ** 2 - 2 * u ** 3)           # eased in and out
        up = np.clip((t - (start - LEAD_SECONDS)) / (0.4 * LEAD_SECONDS), 0, 1)
        down = np.clip((start + TURN_SPIN + 0.3 - t) / 0.3, 0, 1)
        lift = np.maximum(lift, np.minimum(up, down))
        start += TURN_SPIN + rng.uniform(*TURN_EVERY)
    return spin, lift


def rebuilt(motion: Motion, hip: np.ndarray, world: np.ndarray) -> Motion:
    """The motion with these hips and world rotations. The rotations are made orthonormal again
    (procedural_dancer rounds them to 6 decimals, and a product of rounded matrices drifts), so
    that the BVH text, which stores angles, reads back as this motion."""
    u, _, vt = np.linalg.svd(world)
    world = u @ vt
    positions = forward_kinematics_reduced(motion.offsets, hip, world)
    return Motion(np.round(positions, 6), world, motion.offsets, motion.fps)


def spun(motion: Motion, spin: np.ndarray) -> Motion:
    """The dancer turned about the vertical through her hips by `spin` [F] radians."""
    world = np.stack([rotation_y(a) for a in spin])[:, None] @ motion.rotations
    return rebuilt(motion, motion.positions[:, 0], world)


ARM_UP = 150.0   # degrees the raised upper arm turns up from hanging down


def raise_hand(motion: Motion, lift: np.ndarray) -> Motion:
    """His left upper arm turned up by lift * ARM_UP degrees (about his forward axis, in the
    shoulder's frame), the rest of the body as it was."""
    local = motion.local_rotations()
    arm = JOINT_NAMES.index("lShldr")
    local[:, arm] = euler(np.stack([np.zeros_like(lift), np.zeros_like(lift), -ARM_UP * lift], -1)) @ local[:, arm]
    world = np.empty_like(local)
    for j, p in enumerate(PARENTS):
        world[:, j] = local[:, j] if p < 0 else world[:, p] @ local[:, j]
    return rebuilt(motion, motion.positions[:, 0], world)


def sway(rng: np.random.Generator, motion: Motion, t: np.ndarray) -> Motion:
    """The whole body moved side to side (along its hip line) by HIP_SWAY on each step, and the
    hips shaken by HIP_SHAKE (a capture's hips are never smooth: they turn back now and then)."""
    p = motion.positions
    across = p[:, JOINT_NAMES.index("lThigh")] - p[:, JOINT_NAMES.index("rThigh")]
    across[:, 1] = 0
    across /= np.linalg.norm(across, axis=-1, keepdims=True)
    shift = HIP_SWAY * np.sin(2 * np.pi * 1.2 * t)[:, None] * across + rng.normal(0, HIP_SHAKE, p[:, 0].shape)
    return rebuilt(motion, p[:, 0] + shift, motion.rotations)


# ---------------------------------------------------------------- BVH text

# Joints of the written hierarchy beyond the 17: (name, parent, share of the child's offset it
# takes, child). Collars and buttocks never rotate, as in the CMU files.
CONSTANT_JOINTS = {"lShldr": "lCollar", "rShldr": "rCollar", "lThigh": "lButtock", "rThigh": "rButtock"}
CONSTANT_SHARE = 0.4
LEAVES = {"head": (0.0, 0.1, 0.02), "lHand": (0.08, 0.0, 0.0), "rHand": (-0.08, 0.0, 0.0),
          "lFoot": (0.0, -0.05, 0.12), "rFoot": (0.0, -0.05, 0.12)}     # End Site offsets, metres
ROTATION_CHANNELS = "Zrotation Xrotation Yrotation"


def bvh_text(motion: Motion) -> str:
    """A Motion (17 joints, world rotations, metres) as BVH text the loader reads back exactly
    (to the 6 decimals written)."""
    local = motion.local_rotations()
    angles = euler_zxy(local)                                  # [F, 17, 3]
    children = {j: [c for c, p in enumerate(PARENTS) if p == j] for j in range(len(PARENTS))}
    lines = ["HIERARCHY"]
    order: list[int] = []                                      # joints in file order (channels)

    def offset(pad: str, v) -> None:
        lines.append(f"{pad}OFFSET {v[0]:.6f} {v[1]:.6f} {v[2]:.6f}")

    def emit(j: int, depth: int, off: np.ndarray) -> None:
        pad = "\t" * depth
        name = JOINT_NAMES[j]
        lines.append(f"{pad}{'ROOT' if j == 0 else 'JOINT'} {name}")
        lines.append(pad + "{")
        offset(pad + "\t", off / SCALE)
        lines.append(f"{pad}\tCHANNELS {6 if j == 0 else 3} "
                     f"{'Xposition Yposition Zposition ' if j == 0 else ''}{ROTATION_CHANNELS}")
        order.append(j)
        for c in children[j]:
            if JOINT_NAMES[c] in CONSTANT_JOINTS:              # a still joint in between
                inner = "\t" * (depth + 1)
                lines.append(f"{inner}JOINT {CONSTANT_JOINTS[JOINT_NAMES[c]]}")
                lines.append(inner + "{")
                offset(inner + "\t", CONSTANT_SHARE * motion.offsets[c] / SCALE)
                lines.append(f"{inner}\tCHANNELS 3 {ROTATION_CHANNELS}")
                order.append(-1)
                emit(c, depth + 2, (1 - CONSTANT_SHARE) * motion.offsets[c])
                lines.append(inner + "}")
            else:
                emit(c, depth + 1, motion.offsets[c])
        if name in LEAVES:
            lines.extend([f"{pad}\tEnd Site", pad + "\t{"])
            offset(pad + "\t\t", np.asarray(LEAVES[name]) / SCALE)
            lines.append(pad + "\t}")
        lines.append(pad + "}")

    emit(0, 0, np.zeros(3))
    lines += ["MOTION", f"Frames: {motion.frames}", f"Frame Time: {1 / motion.fps:.6f}"]
    hip = motion.positions[:, 0] / SCALE
    zero = np.zeros((motion.frames, 3))
    columns = [np.concatenate([hip, angles[:, 0]], -1)] + [zero if j < 0 else angles[:, j] for j in order[1:]]
    rows = np.concatenate(columns, -1)
    lines += [" ".join(f"{v:.6f}" for v in row) for row in rows]
    return "\n".join(lines) + "\n"


def write_couples(folder: str | Path, takes: dict[str, int] | None = None, seed: int = 0,
                  subjects: tuple[str, str] = CMU_SUBJECTS, fps: float = CMU_FPS) -> Path:
    """Write LEAD_TAKE.bvh and FOLLOW_TAKE.bvh for every take (name -> frames); returns the folder."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for i, (take, frames) in enumerate(sorted((takes or CMU_TAKES).items())):
        rng = np.random.default_rng([seed, i])
        for subject, motion in zip(subjects, synthetic_couple(rng, frames, fps)):
            (folder / f"{subject}_{take}.bvh").write_text(bvh_text(motion))
    return folder


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.data.synthetic", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", required=True, metavar="DIR", help="folder to write the BVH couples into")
    ap.add_argument("--takes", default=",".join(CMU_TAKES),
                    help="comma-separated take names (CMU names get the CMU frame counts)")
    ap.add_argument("--frames", type=int, default=2000, help="frames at 120 fps of a take without a CMU name")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--force", action="store_true", help="overwrite BVH files already in --data")
    args = ap.parse_args(argv)
    takes = {t: CMU_TAKES.get(t, args.frames) for t in args.takes.split(",") if t}
    folder = Path(args.data)
    clash = [f"{s}_{t}.bvh" for t in takes for s in CMU_SUBJECTS if (folder / f"{s}_{t}.bvh").exists()]
    if clash and not args.force:
        print(f"error: {folder / clash[0]} exists (real takes?); choose another --data or pass --force",
              file=sys.stderr)
        return 2
    write_couples(folder, takes, args.seed)
    print(f"wrote {2 * len(takes)} synthetic BVH files ({len(takes)} couples) to {folder}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
