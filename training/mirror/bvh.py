"""BVH reading and forward kinematics.

A BVH file is a joint hierarchy (offsets + channel orders) followed by one line of channel
values per frame. We keep every joint, End Sites included, because a dropped joint's offset still
places its children. Rotations are returned as 3x3 matrices; positions in the file's own units.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


VALID_CHANNELS = {a + kind for a in "XYZ" for kind in ("position", "rotation")}


class BvhError(ValueError):
    """The file is not a BVH we can read. The message is meant for a user, one line."""


@dataclass
class Bvh:
    names: list[str]                 # joint names, End Sites named "<parent>_end"
    parents: list[int]               # -1 for the root
    offsets: np.ndarray              # [J, 3] in file units
    channels: list[list[str]]        # per joint, e.g. ["Zrotation", "Xrotation", "Yrotation"]
    frame_time: float                # seconds
    motion: np.ndarray = field(repr=False)  # [F, total channels] raw values (degrees, file units)

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    @property
    def frames(self) -> int:
        return self.motion.shape[0]


def parse_bvh(text: str, source: str = "<string>") -> Bvh:
    tokens = text.split()
    if not tokens or tokens[0] != "HIERARCHY":
        raise BvhError(f"{source}: not a BVH file (it does not start with HIERARCHY)")
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[list[str]] = []
    stack: list[int] = []
    if "MOTION" not in tokens:
        raise BvhError(f"{source}: malformed BVH (no MOTION section)")
    i = 1
    try:
        while tokens[i] != "MOTION":
            tok = tokens[i]
            if tok in ("ROOT", "JOINT"):
                names.append(tokens[i + 1])
                parents.append(stack[-1] if stack else -1)
                offsets.append([0.0, 0.0, 0.0])
                channels.append([])
                i += 2
            elif tok == "End":  # "End Site"
                parent = stack[-1]
                names.append(names[parent] + "_end")
                parents.append(parent)
                offsets.append([0.0, 0.0, 0.0])
                channels.append([])
                i += 2
            elif tok == "{":
                stack.append(len(names) - 1)
                i += 1
            elif tok == "}":
                stack.pop()
                i += 1
            elif tok == "OFFSET":
                offsets[stack[-1]] = [float(v) for v in tokens[i + 1:i + 4]]
                i += 4
            elif tok == "CHANNELS":
                n = int(tokens[i + 1])
                channels[stack[-1]] = tokens[i + 2:i + 2 + n]
                bad = [c for c in channels[stack[-1]] if c not in VALID_CHANNELS]
                if bad:
                    raise BvhError(f"{source}: joint '{names[stack[-1]]}' has unknown channel {bad[0]!r}")
                i += 2 + n
            else:
                raise BvhError(f"{source}: unexpected token {tok!r} in HIERARCHY")
        if tokens[i + 1] != "Frames:" or tokens[i + 3:i + 5] != ["Frame", "Time:"]:
            raise BvhError(f"{source}: MOTION section lacks 'Frames:' / 'Frame Time:'")
        frames = int(tokens[i + 2])
        frame_time = float(tokens[i + 5])
        values = np.array(tokens[i + 6:], dtype=np.float64)
    except (IndexError, ValueError) as e:
        if isinstance(e, BvhError):
            raise
        raise BvhError(f"{source}: malformed BVH ({e.__class__.__name__}: {e})") from None
    if not names:
        raise BvhError(f"{source}: BVH has no joints")
    n_channels = sum(len(c) for c in channels)
    if frames <= 0 or values.size != frames * n_channels:
        raise BvhError(f"{source}: BVH says {frames} frames of {n_channels} channels "
                       f"but holds {values.size} numbers")
    if frame_time <= 0:
        raise BvhError(f"{source}: Frame Time must be positive, got {frame_time}")
    return Bvh(names, parents, np.array(offsets), channels, frame_time,
               values.reshape(frames, n_channels))


def read_bvh(path: str | Path) -> Bvh:
    path = Path(path)
    try:
        text = path.read_text(errors="replace")
    except OSError as e:
        raise BvhError(f"{path}: cannot read ({e.strerror})") from None
    return parse_bvh(text, str(path))


def axis_rotation(axis: str, degrees: np.ndarray) -> np.ndarray:
    """[F] angles -> [F, 3, 3] right-handed rotation matrices about X, Y or Z."""
    a = np.radians(degrees)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    if axis == "X":
        m = [[o, z, z], [z, c, -s], [z, s, c]]
    elif axis == "Y":
        m = [[c, z, s], [z, o, z], [-s, z, c]]
    else:
        m = [[c, -s, z], [s, c, z], [z, z, o]]
    return np.stack([np.stack(row, -1) for row in m], -2)


def local_transforms(bvh: Bvh) -> tuple[np.ndarray, np.ndarray]:
    """Per frame and joint: local rotation [F, J, 3, 3] and local translation [F, J, 3].

    Channels apply in the order written (the first channel is the outermost rotation), which is
    the BVH convention: "Zrotation Xrotation Yrotation" means R = Rz @ Rx @ Ry.
    """
    F, J = bvh.frames, len(bvh.names)
    rot = np.tile(np.eye(3), (F, J, 1, 1))
    pos = np.tile(bvh.offsets[None], (F, 1, 1)).astype(np.float64)
    col = 0
    for j, chans in enumerate(bvh.channels):
        for name in chans:
            values = bvh.motion[:, col]
            col += 1
            if name.endswith("position"):
                pos[:, j, "XYZ".index(name[0])] = values
            else:
                rot[:, j] = rot[:, j] @ axis_rotation(name[0], values)
    return rot, pos


def forward_kinematics(parents: list[int], local_rot: np.ndarray, local_pos: np.ndarray):
    """World rotations [F, J, 3, 3] and positions [F, J, 3]; parents must precede children."""
    world_rot = np.empty_like(local_rot)
    world_pos = np.empty_like(local_pos)
    for j, p in enumerate(parents):
        if p < 0:
            world_rot[:, j] = local_rot[:, j]
            world_pos[:, j] = local_pos[:, j]
        else:
            world_rot[:, j] = world_rot[:, p] @ local_rot[:, j]
            world_pos[:, j] = world_pos[:, p] + np.einsum("fij,fj->fi", world_rot[:, p], local_pos[:, j])
    return world_rot, world_pos
