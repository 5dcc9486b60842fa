"""Is each frame a pose and a motion the recorded dancers make? Per-frame flags against the
recording's own range, per-seed worst seconds and collapses.

Means over frames hide the failures a viewer sees first: a dancer lying on the floor for ten
seconds in one session out of four, or a body that holds one shape while the code stays the same.
So every measure here is a share of frames (read as a ratio to the recording's own share) or a
worst case over a duet, never a mean pose error.

The range is taken from the training takes (`ranges`, stored by training.prepare as
PREPARED/plausibility.json and copied into the manifest, where soak and seeds read it) and each flag is
set where a frame leaves it:

- hips_low: hip height below the recording's 1st percentile;
- head_low: head less far above the hips than the recording's 1st percentile;
- feet_wide: ankles further apart than the recording's 99th percentile;
- angles_out: any joint bend (the angle between a bone and its parent bone) or the torso's lean
  outside the recording's 0.5th..99.5th percentile of that angle;
- frozen: every joint-to-joint distance within FROZEN_MM of the previous frame (the body shape
  did not change at all: stop-motion, not standing still, which breathes and sways);
- fast: the root (hip on the floor, over FAST_WINDOW frames) faster than the recording's 99th
  percentile.

A collapse is the hips below the recording's minimum for COLLAPSE_SECONDS or more.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..mirror.skeleton import FEET, FPS, HEAD, PARENTS

FROZEN_MM = 1.0
FAST_WINDOW = 6                  # frames (0.2 s): root speed over this span, so hip sway is not speed
PATH_SMOOTHING = 15              # frames (0.5 s) of moving average before path lengths are summed
COLLAPSE_SECONDS = 1.0
BAD_SECOND = 0.5                 # a second with more than this share of body flags is a bad second
BODY_FLAGS = ["hips_low", "head_low", "feet_wide"]
POSE_FLAGS = BODY_FLAGS + ["angles_out"]
FLAGS = POSE_FLAGS + ["frozen", "fast"]
# (joint, parent, grandparent): the bend at `parent` between bone grandparent->parent and
# parent->joint, for every joint that has a grandparent (knees, elbows, shoulders, neck, spine...).
BENDS = [(j, PARENTS[j], PARENTS[PARENTS[j]]) for j in range(len(PARENTS))
         if PARENTS[j] >= 0 and PARENTS[PARENTS[j]] >= 0]
CHEST = 2


def bend_angles(positions: np.ndarray) -> np.ndarray:
    """[T, 17, 3] world positions -> [T, len(BENDS) + 1] angles (radians): every bend, then the
    torso's lean (hip->chest against straight up)."""
    p = np.asarray(positions, float)
    j, a, g = (np.array(i) for i in zip(*BENDS))
    u = p[:, a] - p[:, g]
    v = p[:, j] - p[:, a]
    cos = (u * v).sum(-1) / np.maximum(np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1), 1e-9)
    torso = p[:, CHEST] - p[:, 0]
    lean = torso[:, 1] / np.maximum(np.linalg.norm(torso, axis=-1), 1e-9)
    return np.arccos(np.clip(np.concatenate([cos, lean[:, None]], 1), -1, 1))


def smoothed_root(positions: np.ndarray, frames: int = PATH_SMOOTHING) -> np.ndarray:
    """[T, 2]: the hip on the floor, averaged over `frames` so the sway of a step is not travel."""
    hip = np.asarray(positions, float)[:, 0, [0, 2]]
    if len(hip) <= frames:
        return hip
    kernel = np.ones(frames) / frames
    return np.stack([np.convolve(hip[:, i], kernel, "valid") for i in range(2)], -1)


def root_speed(positions: np.ndarray) -> np.ndarray:
    """[T - FAST_WINDOW] m/s of the hip on the floor over FAST_WINDOW frames."""
    hip = np.asarray(positions, float)[:, 0, [0, 2]]
    return np.linalg.norm(hip[FAST_WINDOW:] - hip[:-FAST_WINDOW], axis=-1) * FPS / FAST_WINDOW


def path_length(positions: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(smoothed_root(positions), axis=0), axis=-1).sum())


def ranges(motions: list[np.ndarray]) -> dict:
    """The recording's range from the world positions [T, 17, 3] of every recorded dancer."""
    p = np.concatenate([np.asarray(m, float) for m in motions])
    angles = np.concatenate([bend_angles(m) for m in motions])
    speed = np.concatenate([root_speed(m) for m in motions])
    return {
        "frames": int(len(p)),
        "hip_min": float(p[:, 0, 1].min()),
        "hip_low": float(np.percentile(p[:, 0, 1], 1)),
        "head_above_hip_low": float(np.percentile(p[:, HEAD, 1] - p[:, 0, 1], 1)),
        "feet_wide": float(np.percentile(np.linalg.norm(p[:, FEET[0]] - p[:, FEET[1]], axis=-1), 99)),
        "angle_low": np.percentile(angles, 0.5, axis=0).tolist(),
        "angle_high": np.percentile(angles, 99.5, axis=0).tolist(),
        "root_speed_fast": float(np.percentile(speed, 99)),
    }


def save_ranges(path: str | Path, r: dict) -> None:
    Path(path).write_text(json.dumps(r, indent=1))


def load_ranges(path: str | Path) -> dict:
    return json.loads(Path(path).read_text())


def frozen_frames(positions: np.ndarray, mm: float = FROZEN_MM) -> np.ndarray:
    """[T] bool: every joint-to-joint distance within `mm` of the previous frame (frame 0: False)."""
    p = np.asarray(positions, float)
    d = np.linalg.norm(p[:, :, None] - p[:, None, :], axis=-1)          # [T, 17, 17]
    still = np.zeros(len(p), bool)
    still[1:] = (np.abs(np.diff(d, axis=0)).max(axis=(1, 2)) < mm / 1000)
    return still


def frame_flags(positions: np.ndarray, r: dict) -> dict[str, np.ndarray]:
    """{flag: [T] bool} for one dancer's world positions [T, 17, 3]."""
    p = np.asarray(positions, float)
    angles = bend_angles(p)
    fast = np.zeros(len(p), bool)
    fast[FAST_WINDOW:] = root_speed(p) > r["root_speed_fast"]
    return {
        "hips_low": p[:, 0, 1] < r["hip_low"],
        "head_low": p[:, HEAD, 1] - p[:, 0, 1] < r["head_above_hip_low"],
        "feet_wide": np.linalg.norm(p[:, FEET[0]] - p[:, FEET[1]], axis=-1) > r["feet_wide"],
        "angles_out": ((angles < np.asarray(r["angle_low"])) | (angles > np.asarray(r["angle_high"]))).any(1),
        "frozen": frozen_frames(p),
        "fast": fast,
    }


def longest_run(flags: np.ndarray) -> int:
    """Length of the longest run of True in a [T] bool array."""
    best = run = 0
    for f in np.asarray(flags, bool):
        run = run + 1 if f else 0
        best = max(best, run)
    return best


def collapsed(positions: np.ndarray, r: dict) -> bool:
    """Hips below the recording's minimum for COLLAPSE_SECONDS or more."""
    return longest_run(np.asarray(positions)[:, 0, 1] < r["hip_min"]) >= COLLAPSE_SECONDS * FPS


def body_flagged(flags: dict[str, np.ndarray]) -> np.ndarray:
    """[T] bool: the body low, folded or split (any of BODY_FLAGS; the joint angles have their own
    share, as one bent wrist is no fallen dancer)."""
    return np.any([flags[k] for k in BODY_FLAGS], axis=0)


def second_shares(flags: dict[str, np.ndarray]) -> np.ndarray:
    """[T - FPS + 1] the share of frames with the body low, folded or split in the second starting
    at each frame (one share over all frames when there is less than a second)."""
    bad = body_flagged(flags).astype(float)
    if len(bad) < FPS:
        return np.array([bad.mean() if len(bad) else 0.0])
    return np.convolve(bad, np.ones(FPS) / FPS, "valid")


def worst_second(flags: dict[str, np.ndarray]) -> float:
    """The largest share of frames in any one second with the body low, folded or split."""
    return float(second_shares(flags).max())


def first_bad_second(flags: dict[str, np.ndarray]) -> int | None:
    """The frame where the first bad second (a share over BAD_SECOND) starts; None without one."""
    shares = second_shares(flags)
    return int(np.argmax(shares > BAD_SECOND)) if shares.max() > BAD_SECOND else None


def dancer(positions: np.ndarray, r: dict) -> dict:
    """Shares of flagged frames and worst cases of one dancer's world positions [T, 17, 3]."""
    flags = frame_flags(positions, r)
    return {**{k: float(v.mean()) for k, v in flags.items()},
            "root_speed_p99": float(np.percentile(root_speed(positions), 99)),
            "worst_second": worst_second(flags),
            "collapse": collapsed(positions, r),
            "longest_frozen_s": longest_run(flags["frozen"]) / FPS}


def duet(leader: np.ndarray, follower: np.ndarray, r: dict) -> dict:
    """One duet (or one recorded take): each dancer's measures and the follower's path length per
    leader path length."""
    lead_path = path_length(leader)
    return {"leader": dancer(leader, r), "follower": dancer(follower, r),
            "path_ratio": path_length(follower) / max(lead_path, 1e-6)}


def summarize(duets: list[dict], frames: list[int]) -> dict:
    """Many duets (seeds) -> frame-weighted shares, worst cases over seeds and counts.

    For each dancer: every flag's share over all frames, the root speed's p99 (the largest of the
    seeds' p99s too: `root_speed_p99_worst`), the worst second over seeds, how many seeds have a
    second mostly in implausible poses (`bad_seconds`: worst second > BAD_SECOND) and how many collapse.
    """
    w = np.asarray(frames, float) / np.sum(frames)
    out: dict = {"seeds": len(duets)}
    for who in ("leader", "follower"):
        rows = [d[who] for d in duets]
        s = {k: float(np.sum([r[k] * wi for r, wi in zip(rows, w)])) for k in FLAGS}
        s["root_speed_p99"] = float(np.median([r["root_speed_p99"] for r in rows]))
        s["root_speed_p99_worst"] = float(np.max([r["root_speed_p99"] for r in rows]))
        s["worst_second"] = float(np.max([r["worst_second"] for r in rows]))
        s["bad_seconds"] = int(np.sum([r["worst_second"] > BAD_SECOND for r in rows]))
        s["collapses"] = int(np.sum([r["collapse"] for r in rows]))
        s["longest_frozen_s"] = float(np.max([r["longest_frozen_s"] for r in rows]))
        for k in FLAGS:   # the worst seed's share too: a mean over seeds can hide one bad session
            s[f"{k}_worst_seed"] = float(np.max([r[k] for r in rows]))
        out[who] = s
    ratios = [d["path_ratio"] for d in duets]
    out["path_ratio"] = float(np.median(ratios))
    out["path_ratio_worst"] = float(np.max(ratios))
    return out
