"""One duet of the exported models as the page dances it, steered by a random stick script or by
nobody, checked frame by frame (soak_one): what the soak, rhythm, seeds, jitter and interaction
each run many of.
"""
from __future__ import annotations

import numpy as np

from ..mirror.rollout import NOW, start_duet, step
from ..mirror.skeleton import FEET, FPS, PARENTS

FROZEN_SPEED = 0.1        # m/s mean joint speed over the last second counts as frozen


def steering_script(rng: np.random.Generator, frames: int) -> np.ndarray:
    """[frames, 2] stick positions: segments of 0.5-3 s, each idle, a hold, a new random
    direction, or a sharp reversal of the previous one."""
    out = np.zeros((frames, 2))
    t, stick = 0, np.zeros(2)
    while t < frames:
        n = int(rng.uniform(0.5, 3.0) * FPS)
        kind = rng.choice(["idle", "hold", "turn", "reverse"], p=[0.25, 0.2, 0.35, 0.2])
        if kind == "idle":
            stick = np.zeros(2)
        elif kind == "turn" or not stick.any():
            a = rng.uniform(-np.pi, np.pi)
            stick = np.array([np.sin(a), np.cos(a)]) * rng.uniform(0.5, 1.0)
        elif kind == "reverse":
            stick = -stick
        if kind == "hold":
            n *= 3   # long holds: up to 9 s in one direction
        out[t:t + n] = stick
        t += n
    return out


def bone_error(positions: np.ndarray, offsets: np.ndarray) -> float:
    lengths = np.linalg.norm(positions[1:] - positions[PARENTS[1:]], axis=-1)
    return float(np.abs(lengths - np.linalg.norm(offsets[1:], axis=-1)).max())


def soak_one(manifest, leader, follower, seed: int, frames: int, temperature: float,
             record: dict | None = None, tempo: float | None = None, steer: bool = True) -> dict:
    """One steered duet, the music at `tempo` beats a minute (None: the manifest's); with
    steer=False nobody steers (the same seed's noise). With `record` (a dict), every frame's world
    positions and foot contacts of both dancers are stored there: `leader`, `follower` [frames, 17, 3]
    as the networks left them, `leader_shown`, `follower_shown` after the contact layer,
    `leader_contacts`, `follower_contacts` [frames, 2], and `beat` [frames], the count each frame's
    step danced on (beats since the music started)."""
    rng = np.random.default_rng(seed)
    sticks = steering_script(rng, frames)
    if not steer:
        sticks[:] = 0.0
    duet = start_duet(manifest, tempo=tempo, seed=seed)
    worst = {"nonfinite": 0, "max_distance": 0.0, "bone_error": 0.0, "min_foot": np.inf}
    speeds = np.zeros((frames, 2))
    if record is not None:
        for k in ("leader", "follower"):
            record[k] = np.zeros((frames, 17, 3))
            record[f"{k}_shown"] = np.zeros((frames, 17, 3))
            record[f"{k}_contacts"] = np.zeros((frames, 2))
        record["beat"] = np.zeros(frames)
    for f in range(frames):
        if record is not None:
            record["beat"][f] = duet.beat   # the count this step dances on
        step(duet, leader, follower, sticks[f], temperature, rng)
        if record is not None:
            for i, (k, d) in enumerate((("leader", duet.leader), ("follower", duet.follower))):
                record[k][f] = d.track.positions[NOW]
                record[f"{k}_shown"][f] = duet.shown[i]
                record[f"{k}_contacts"][f] = d.contacts
        for i, d in enumerate((duet.leader, duet.follower)):
            p = d.track.positions
            if not np.all(np.isfinite(p[NOW])):
                worst["nonfinite"] += 1
                continue
            worst["bone_error"] = max(worst["bone_error"], bone_error(p[NOW], d.offsets))
            worst["min_foot"] = min(worst["min_foot"], float(p[NOW][FEET, 1].min()))
            speeds[f, i] = np.linalg.norm(p[NOW] - p[NOW - FPS], axis=-1).mean()  # m over the last 1 s
        worst["max_distance"] = max(worst["max_distance"],
                                    float(np.linalg.norm(duet.leader.root - duet.follower.root)))
    frozen = (speeds[FPS:] < FROZEN_SPEED).mean(0)
    return {"seed": seed, **worst, "frozen_leader": float(frozen[0]), "frozen_follower": float(frozen[1]),
            "resets": duet.leader.resets + duet.follower.resets}
