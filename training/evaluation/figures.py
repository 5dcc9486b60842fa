"""Salsa figures a dancer sees: turns, spins, how much the body moves and how far the couple travels.

The other metrics cannot see a turn: FID windows live in the root's own space (a spin hardly
changes them), MPJPE is teacher-forced, and the plausibility flags only catch falls. A follower
that never turns scores well on all of them. These measures read world joint positions only, so
one rule judges the recording and any generated dancer alike:

- facing: the direction the body faces, from the shoulder and hip lines (as the root heading is
  built, features.md, but unsmoothed and unwrapped, so a spin accumulates 360 degrees a turn);
- a turn: a net change of facing of at least TURN_DEGREES within TURN_SECONDS, timed at the frame
  where the TURN_DEGREES are reached; the next turn is counted from there on;
- a spin frame: one turning faster than SPIN_DEG_PER_S;
- body motion: mean speed of the joints relative to the hips (arms, legs, torso moving);
- travel: mean speed of the hips over the floor;
- recall / precision of a follower's turns against the recorded follower's, beside the same
  recorded leader: a turn matches a recorded one of the same direction within MATCH_SECONDS;
- his lead: the leader's higher hand above HAND_RAISED metres over the floor.

Measured on the CMU salsa takes (all 12): the follower turns about 20 times a minute, in both
directions, and spins in about a third of her frames; the leader turns 6-7 times a minute.
"""
from __future__ import annotations

import numpy as np

from ..mirror.skeleton import FPS, JOINT_NAMES
from .plausibility import smoothed_root

TURN_DEGREES = 300.0
TURN_SECONDS = 2.5
SPIN_DEG_PER_S = 300.0
MATCH_SECONDS = 0.75
# The recorded leader's higher hand goes above it in 84 % of her turns (1.5 s before the turn
# completes) and is above it in 17 % of all his frames (recorded_leads).
HAND_RAISED = 1.6   # m
L_SHLDR, R_SHLDR = JOINT_NAMES.index("lShldr"), JOINT_NAMES.index("rShldr")
L_THIGH, R_THIGH = JOINT_NAMES.index("lThigh"), JOINT_NAMES.index("rThigh")


def facing(positions: np.ndarray) -> np.ndarray:
    """[T, 17, 3] world positions -> [T] facing angle in radians, unwrapped (θ = 0 faces +Z, as
    the root heading: forward = normalize(cross(across, up)) with across from left to right)."""
    p = np.asarray(positions, float)
    across = (p[:, L_THIGH] - p[:, R_THIGH]) + (p[:, L_SHLDR] - p[:, R_SHLDR])
    # cross(across, up) with up = +Y is (-across_z, 0, across_x): forward on the floor.
    return np.unwrap(np.arctan2(-across[:, 2], across[:, 0]))


def turns(angle: np.ndarray, degrees: float = TURN_DEGREES, seconds: float = TURN_SECONDS,
          fps: int = FPS) -> list[tuple[int, int]]:
    """Unwrapped facing [T] -> [(frame, direction ±1)]: each frame where the facing has changed by
    `degrees` from some frame at most `seconds` before it (and after the previous turn)."""
    span, need = int(round(seconds * fps)), np.radians(degrees)
    out, anchor = [], 0
    for t in range(1, len(angle)):
        past = angle[max(anchor, t - span):t]
        if len(past) == 0:
            continue
        change = angle[t] - past
        k = int(np.argmax(np.abs(change)))
        if abs(change[k]) >= need:
            out.append((t, int(np.sign(change[k]))))
            anchor = t
    return out


def spin_frames(angle: np.ndarray, fps: int = FPS) -> np.ndarray:
    """[T] bool: turning faster than SPIN_DEG_PER_S (central difference over 3 frames, so one
    noisy frame of the shoulder line is not a spin)."""
    if len(angle) < 3:
        return np.zeros(len(angle), bool)
    rate = np.zeros(len(angle))
    rate[1:-1] = (angle[2:] - angle[:-2]) * fps / 2
    rate[0], rate[-1] = rate[1], rate[-2]
    return np.abs(np.degrees(rate)) > SPIN_DEG_PER_S


def body_motion(positions: np.ndarray, fps: int = FPS) -> float:
    """Mean speed (m/s) of every joint relative to the hips: how much the body itself moves."""
    p = np.asarray(positions, float)
    rel = p - p[:, :1]
    return float(np.linalg.norm(np.diff(rel, axis=0), axis=-1)[:, 1:].mean() * fps)


def travel(positions: np.ndarray, fps: int = FPS) -> float:
    """Mean speed (m/s) of the hips over the floor, averaged over half a second first so the sway
    of each step is not travel (plausibility.smoothed_root)."""
    hip = smoothed_root(positions)
    return float(np.linalg.norm(np.diff(hip, axis=0), axis=-1).mean() * fps)


def dancer(positions: np.ndarray, fps: int = FPS) -> dict:
    """The figure measures of one dancer over a motion [T, 17, 3]."""
    a = facing(positions)
    t = turns(a, fps=fps)
    minutes = len(a) / fps / 60
    return {"turns": len(t), "turns_per_min": len(t) / minutes, "turns_left": sum(d > 0 for _, d in t),
            "spin_frames": float(spin_frames(a, fps).mean()), "body_motion": body_motion(positions, fps),
            "travel": travel(positions, fps), "minutes": minutes, "turn_frames": [f for f, _ in t],
            "turn_directions": [d for _, d in t]}


def match(found: list[tuple[int, int]], reference: list[tuple[int, int]],
          seconds: float = MATCH_SECONDS, fps: int = FPS, same_direction: bool = True) -> int:
    """How many turns of `found` match one of `reference` (same direction unless told otherwise,
    within `seconds`), each reference turn matched at most once, closest pairs first."""
    tol = seconds * fps
    pairs = sorted((abs(f - r), i, j) for i, (f, fd) in enumerate(found) for j, (r, rd) in enumerate(reference)
                   if (fd == rd or not same_direction) and abs(f - r) <= tol)
    used_f, used_r, n = set(), set(), 0
    for _, i, j in pairs:
        if i not in used_f and j not in used_r:
            used_f.add(i)
            used_r.add(j)
            n += 1
    return n


def against(positions: np.ndarray, recorded: np.ndarray, fps: int = FPS) -> dict:
    """A follower's turns against the recorded follower's beside the same played-back leader:
    matched counts for recall (of the recorded turns) and precision (of its own)."""
    mine, ref = turns(facing(positions), fps=fps), turns(facing(recorded), fps=fps)
    n = match(mine, ref, fps=fps)
    return {"matched": n, "matched_any_direction": match(mine, ref, fps=fps, same_direction=False),
            "found": len(mine), "recorded": len(ref)}


def summarize(items: list[dict]) -> dict:
    """Pool dancer() results (and against() counts where present) over takes or seeds: rates over
    the pooled minutes, shares over the pooled frames."""
    minutes = sum(i["minutes"] for i in items)
    out = {"minutes": minutes, "turns": sum(i["turns"] for i in items),
           "turns_per_min": sum(i["turns"] for i in items) / minutes,
           "turns_left_share": (sum(i["turns_left"] for i in items) / max(1, sum(i["turns"] for i in items))),
           **{k: sum(i[k] * i["minutes"] for i in items) / minutes for k in ("spin_frames", "body_motion", "travel")}}
    if all("matched" in i for i in items):
        m, a, f, r = (sum(i[k] for i in items) for k in ("matched", "matched_any_direction", "found", "recorded"))
        # direction: of her turns that meet a recorded one (either way, within MATCH_SECONDS), the
        # share that also go its way (turn_direction.py measures how far the leader shows it).
        out.update(recall=m / r if r else float("nan"), precision=m / f if f else float("nan"),
                   recall_any_direction=a / r if r else float("nan"),
                   direction=m / a if a else float("nan"))
    return out


def ratios(row: dict, ref: dict) -> dict:
    """Each rate of a summarized row as a ratio to the recording's."""
    return {k: row[k] / ref[k] if ref.get(k) else float("nan")
            for k in ("turns_per_min", "spin_frames", "body_motion", "travel")}
