"""Paired takes on disk -> training samples for both roles.

Naming rule for a folder of couples: every file is `SUBJECT_TAKE.bvh`; the folder holds exactly two
subjects and every take exists for both. The leader is the subject that sorts first (CMU: 60 leads,
61 follows) unless `leader=` names it. Partners of one take must have the same frame count and
share one world frame.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..mirror.bvh import BvhError, read_bvh
from ..mirror.features import (HISTORY, Track, figure_block, follower_input, hands_moves, hands_plan_block,
                               intention_target, leader_input, output_features, valid_frames)
from ..mirror.skeleton import FPS, HEAD, SCALE, Motion, mirror_motion, reduce_bvh, resample, time_warp
from .count import Count, find_count
from .led_figures import figure_spans

# Split by take so no validation or test frame has a near-duplicate neighbour in training.
# 12 is clean; 02 and 13 are full-length takes without the head glitches of 06/07.
VALIDATION_TAKES = ["12"]
TEST_TAKES = ["02", "13"]

# Mean height (m) of a standing adult's head joint; far outside it the units are wrong.
HEAD_HEIGHT = (1.2, 2.2)

NAME = re.compile(r"^(?P<subject>[^_]+)_(?P<take>[^.]+)\.bvh$", re.IGNORECASE)


class DataError(ValueError):
    """Bad input data; the message is one line for a user."""


@dataclass
class Take:
    name: str
    leader_path: Path
    follower_path: Path


def discover_takes(data: str | Path, leader: str | None = None) -> list[Take]:
    data = Path(data)
    if not data.is_dir():
        raise DataError(f"data folder {data} does not exist: put the CMU salsa takes there (README, \"Data\") "
                        f"or name the folder with --data DIR or DUET_DATA=DIR")
    files = sorted(p for p in data.iterdir() if p.suffix.lower() == ".bvh")
    if not files:
        raise DataError(f"{data}: no .bvh files (expected SUBJECT_TAKE.bvh pairs such as 60_01.bvh and "
                        f"61_01.bvh; README, \"Data\")")
    by_subject: dict[str, dict[str, Path]] = {}
    for p in files:
        m = NAME.match(p.name)
        if not m:
            raise DataError(f"{p}: name does not follow SUBJECT_TAKE.bvh")
        by_subject.setdefault(m["subject"], {})[m["take"]] = p
    subjects = sorted(by_subject)
    if len(subjects) != 2:
        raise DataError(f"{data}: expected exactly two subjects (leader and follower), "
                        f"found {len(subjects)}: {', '.join(subjects)}")
    lead = leader if leader is not None else subjects[0]
    if lead not in by_subject:
        raise DataError(f"{data}: leader subject {lead!r} not among {', '.join(subjects)}")
    follow = subjects[1] if lead == subjects[0] else subjects[0]
    for a, b in ((lead, follow), (follow, lead)):
        alone = sorted(set(by_subject[a]) - set(by_subject[b]))
        if alone:
            raise DataError(f"{data}: take {a}_{alone[0]} has no partner {b}_{alone[0]}.bvh")
    return [Take(t, by_subject[lead][t], by_subject[follow][t]) for t in sorted(by_subject[lead])]


def select_takes(takes: list[Take], names: list[str] | None) -> list[Take]:
    if not names:
        return takes
    known = {t.name: t for t in takes}
    missing = [n for n in names if n not in known]
    if missing:
        raise DataError(f"unknown take(s) {', '.join(missing)}; have {', '.join(known)}")
    return [known[n] for n in names]


def load_pair(take: Take) -> tuple[Motion, Motion]:
    """Leader and follower of one take, 17 joints, metres, at the file's frame rate."""
    try:
        lead_bvh, follow_bvh = read_bvh(take.leader_path), read_bvh(take.follower_path)
    except BvhError as e:
        raise DataError(str(e)) from None
    if lead_bvh.frames != follow_bvh.frames:
        raise DataError(f"take {take.name}: partners have different frame counts "
                        f"({take.leader_path.name} {lead_bvh.frames}, "
                        f"{take.follower_path.name} {follow_bvh.frames})")
    if abs(lead_bvh.frame_time - follow_bvh.frame_time) > 1e-6:
        raise DataError(f"take {take.name}: partners have different frame times")
    # A sample needs 1 s of past, the next frame and 1 s of future after it.
    min_seconds = (2 * HISTORY + 2) / FPS
    if lead_bvh.frames * lead_bvh.frame_time < min_seconds:
        raise DataError(f"take {take.name}: {lead_bvh.frames * lead_bvh.frame_time:.2f} s is too short "
                        f"(a sample needs {min_seconds:.2f} s)")
    try:
        pair = (reduce_bvh(lead_bvh, str(take.leader_path)), reduce_bvh(follow_bvh, str(take.follower_path)))
    except BvhError as e:
        raise DataError(str(e)) from None
    for path, motion in zip((take.leader_path, take.follower_path), pair):
        head = float(motion.positions[:, HEAD, 1].mean())
        if not HEAD_HEIGHT[0] <= head <= HEAD_HEIGHT[1]:
            raise DataError(f"{path}: the head joint is {head:.2f} m above the floor on average, not "
                            f"{HEAD_HEIGHT[0]}-{HEAD_HEIGHT[1]} m: other units than the CMU copy this "
                            f"project reads (1 unit = {SCALE} m, training/mirror/skeleton.py SCALE), or not Y-up")
    return pair


def phases(motion: Motion) -> int:
    return max(1, int(round(motion.fps / FPS)))


def take_count(leader: Motion, follower: Motion) -> Count:
    """The count of a take as recorded (training/data/count.py), from both dancers at 30 fps."""
    return find_count(resample(leader, FPS, 0).positions, resample(follower, FPS, 0).positions)


def pair_tracks(leader: Motion, follower: Motion, phase: int = 0, mirror: bool = False, tempo: float = 1.0):
    """Both dancers at 30 fps for one phase offset, optionally mirrored left/right, and at
    another tempo (both partners warped together, so the couple stays in step). Both carry the
    take's count (Track.beat), warped with them: at tempo 1.1 the music is 1.1x as fast."""
    count = take_count(leader, follower)
    base = leader.fps / FPS
    if abs(base - round(base)) < 1e-3:    # as resample and time_warp: 120.0048 fps read as 120
        base = round(base)
    if tempo == 1.0:
        lead, follow = resample(leader, FPS, phase), resample(follower, FPS, phase)
    else:
        lead, follow = time_warp(leader, tempo, FPS, phase), time_warp(follower, tempo, FPS, phase)
    if mirror:
        lead, follow = mirror_motion(lead), mirror_motion(follow)
    # Frame i is source frame phase + base * tempo * i, at (that) / the source rate seconds.
    seconds = (phase + base * tempo * np.arange(lead.frames)) / (FPS * base)
    beat = count.beats(seconds)
    return Track.from_motion(lead, beat), Track.from_motion(follow, beat)


def samples(lead: Track, follow: Track) -> dict[str, np.ndarray]:
    """Every valid frame of one take as samples for both roles (float32)."""
    frames = valid_frames(lead.frames)
    # Both dancers read the figure being led, as the recorded couple danced it (led_figures).
    figure = figure_block(figure_spans(lead.positions, follow.positions), frames)
    out = {
        "follower_input": follower_input(lead, follow, frames, figure),
        "follower_output": output_features(follow, frames),
        "follower_intention": intention_target(lead, follow, frames),
        # His hands plan: where his recorded hands went (train.py hides it in a share of them).
        "leader_input": leader_input(follow, lead, frames, figure,
                                     hands_plan_block(hands_moves(lead, frames), len(frames))),
        "leader_output": output_features(lead, frames),
        "leader_intention": intention_target(follow, lead, frames),
    }
    out = {k: v.astype(np.float32) for k, v in out.items()}
    out["frame"] = frames.astype(np.int32)
    return out
