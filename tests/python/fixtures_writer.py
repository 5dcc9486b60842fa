"""Fixtures that pin web/mirror/*.ts to the Python reference: `.venv/bin/python tests/python/fixtures_writer.py`.

Writes tests/fixtures/{bvh,features,rollout,contact}.json: inputs, and what training/mirror/bvh.py,
skeleton.py, features.py, rollout.py and contact.py compute from them. tests/web/*.test.ts run the
TypeScript mirror on the same inputs and compare every number (1e-5, relative for large values);
tests/python/test_fixtures.py checks that the files still match this code.

And tests/fixtures/runtime.json: inputs for each shipped model (public/models) and what Python's
onnxruntime computes from them, which tests/e2e/runtime.test.mjs asks of the page's onnxruntime-web
(another version, compiled to WebAssembly). Re-export the models, then rerun this script (on a VNNI
CPU, docs/testing.md; `--only runtime` writes that file alone, `--only bvh features rollout contact`
all but it).

All motion here is procedural (sinusoidal joint rotations, seeded random rotations, two dancers
circling each other) and every BVH is generated text: no recorded motion is ever written out.
Inputs are rounded BEFORE the expected outputs are computed from them, so the TypeScript side reads
exactly the numbers Python used; only the outputs are rounded (7 significant digits).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:      # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from training.mirror import features as feat  # noqa: E402
from training.mirror import guard as G  # noqa: E402
from training.mirror import music  # noqa: E402
from training.mirror import on_count as OC  # noqa: E402
from training.mirror import rollout as ro  # noqa: E402
from training.mirror.contact import ContactLayer  # noqa: E402
from training.mirror.policy import open_session  # noqa: E402
from training.mirror.bvh import BvhError, forward_kinematics, local_transforms, parse_bvh  # noqa: E402
from training.mirror.features import Track  # noqa: E402
from training.data.synthetic import OFFSETS, procedural_dancer  # noqa: E402
from training.learning.stamp import PAGE_MODELS  # noqa: E402
from training.mirror.skeleton import (FPS, JOINT_NAMES, MIRROR, PARENTS, Motion, facing_direction,  # noqa: E402
                               forward_kinematics_reduced, gaussian_smooth, mirror_motion, reduce_bvh,
                               resample, root_from_motion)

OUT_DIR = REPO / "tests" / "fixtures"
FRAMES = 63            # 30 past + 2 frames t + 31 future: valid_frames(63) == [30, 31]
SEED = 20240611
CONTACT_STEPS = 40     # frames of the contact layer fixture (<= FRAMES)


# ---------------------------------------------------------------- number formatting

def out7(x):
    """Expected outputs: 7 significant digits, flattened (TypeScript stores everything flat)."""
    a = np.asarray(x, dtype=np.float64).ravel()
    return [float(f"{v:.7g}") if np.isfinite(v) else None for v in a]


def exact(x):
    """Inputs: written as they are (already rounded by the caller), flattened."""
    return [float(v) for v in np.asarray(x, dtype=np.float64).ravel()]


# ---------------------------------------------------------------- BVH text

TINY_BVH = """HIERARCHY
ROOT Hips
{
  OFFSET 0.0 0.0 0.0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0.0 5.0 0.5
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0.0 3.0 0.0
    }
  }
  JOINT Leg
  {
    OFFSET 1.0 -1.0 0.0
    CHANNELS 3 Yrotation Zrotation Xrotation
    End Site
    {
      OFFSET 0.0 -4.0 0.0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
1.0 2.0 3.0 10.0 20.0 30.0 5.0 -15.0 45.0 -30.0 12.5 60.0
1.5 2.0 2.5 -10.0 0.0 90.0 0.0 0.0 0.0 0.0 0.0 0.0
-2.0 0.5 1.0 170.0 -45.0 5.0 90.0 90.0 -90.0 33.0 -66.0 99.0
"""

# The 17 kept joints plus joints the reduction must fold away (collars, buttocks) and End Sites.
# (name, parent name, offset in BVH units, channel order or None)
ZXY, XYZ, YZX = "Zrotation Xrotation Yrotation", "Xrotation Yrotation Zrotation", "Yrotation Zrotation Xrotation"
FULL_JOINTS = [
    ("hip", None, (0.0, 0.0, 0.0), "Xposition Yposition Zposition " + ZXY),
    ("abdomen", "hip", (0.0, 0.07, 0.0), ZXY),
    ("chest", "abdomen", (0.0, 0.12, 0.01), XYZ),
    ("neck", "chest", (0.0, 0.16, -0.01), ZXY),
    ("head", "neck", (0.0, 0.08, 0.01), YZX),
    ("lCollar", "chest", (0.03, 0.12, 0.0), ZXY),      # dropped: constant rotation
    ("lShldr", "lCollar", (0.09, 0.0, 0.0), ZXY),
    ("lForeArm", "lShldr", (0.19, 0.0, 0.0), XYZ),
    ("lHand", "lForeArm", (0.17, 0.0, 0.0), ZXY),
    ("rCollar", "chest", (-0.03, 0.12, 0.0), ZXY),     # dropped: constant rotation
    ("rShldr", "rCollar", (-0.09, 0.0, 0.0), ZXY),
    ("rForeArm", "rShldr", (-0.19, 0.0, 0.0), YZX),
    ("rHand", "rForeArm", (-0.17, 0.0, 0.0), ZXY),
    ("lButtock", "hip", (0.04, -0.02, 0.0), None),     # dropped: no channels at all
    ("lThigh", "lButtock", (0.02, -0.02, 0.0), ZXY),
    ("lShin", "lThigh", (0.0, -0.29, 0.0), XYZ),
    ("lFoot", "lShin", (0.0, -0.28, 0.0), ZXY),
    ("rButtock", "hip", (-0.04, -0.02, 0.0), None),
    ("rThigh", "rButtock", (-0.02, -0.02, 0.0), ZXY),
    ("rShin", "rThigh", (0.0, -0.29, 0.0), ZXY),
    ("rFoot", "rShin", (0.0, -0.28, 0.0), YZX),
]
LEAVES = {"head", "lHand", "rHand", "lFoot", "rFoot"}
FULL_FRAMES = 9      # at 120 fps: 3 frames at 30 fps for phase 0, 2 for phase 1


def full_bvh_text(rng: np.random.Generator, rotating_collar: bool = False) -> str:
    children: dict[str | None, list[int]] = {}
    for i, (_, parent, _, _) in enumerate(FULL_JOINTS):
        children.setdefault(parent, []).append(i)
    lines = ["HIERARCHY"]
    columns: list[str] = []   # (joint, channel) per motion column, to generate values

    def emit(i: int, depth: int) -> None:
        name, parent, off, chans = FULL_JOINTS[i]
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {off[0]:.4f} {off[1]:.4f} {off[2]:.4f}")
        if chans:
            lines.append(f"{pad}  CHANNELS {len(chans.split())} {chans}")
            columns.extend(f"{name}:{c}" for c in chans.split())
        for c in children.get(name, []):
            emit(c, depth + 1)
        if name in LEAVES:
            lines.append(f"{pad}  End Site")
            lines.append(f"{pad}  {{")
            lines.append(f"{pad}    OFFSET 0.0000 {0.05 if name == 'head' else -0.03:.4f} 0.0300")
            lines.append(f"{pad}  }}")
        lines.append(f"{pad}}}")

    emit(0, 0)
    lines += ["MOTION", f"Frames: {FULL_FRAMES}", "Frame Time: 0.0083333"]
    phase = rng.uniform(0, 2 * np.pi, len(columns))
    amp = rng.uniform(5, 40, len(columns))
    for f in range(FULL_FRAMES):
        row = []
        for c, col in enumerate(columns):
            joint, chan = col.split(":")
            if chan.endswith("position"):
                v = {"X": 0.3 + 0.01 * f, "Y": 0.62 + 0.005 * math.sin(f), "Z": -0.2 + 0.02 * f}[chan[0]]
            elif joint.endswith("Collar"):
                v = 7.5 if not rotating_collar else 7.5 + f   # constant: foldable into the offsets
            else:
                v = amp[c] * math.sin(0.4 * f + phase[c])
            row.append(f"{v:.4f}")
        lines.append(" ".join(row))
    return "\n".join(lines) + "\n"


def bvh_fixture(rng: np.random.Generator) -> dict:
    tiny = parse_bvh(TINY_BVH, "tiny.bvh")
    tiny_rot, tiny_pos = local_transforms(tiny)
    world_rot, world_pos = forward_kinematics(tiny.parents, tiny_rot, tiny_pos)

    text = full_bvh_text(rng)
    full = parse_bvh(text, "full.bvh")
    motion = reduce_bvh(full, "full.bvh")
    full_rot, full_pos = local_transforms(full)
    _, full_world = forward_kinematics(full.parents, full_rot, full_pos)
    resampled = resample(motion, 30, 1)
    root, heading = root_from_motion(motion)
    mirrored = mirror_motion(motion)
    fk = forward_kinematics_reduced(motion.offsets, motion.positions[:, 0], motion.rotations)

    smooth_in = np.round(rng.normal(size=(7, 3)), 6)

    # Broken files: the phrase each message must contain (in Python and TypeScript alike).
    no_lfoot = text.replace("JOINT lFoot", "JOINT lToe")
    errors = [
        ("", None),
        ("hello world", "not a BVH file"),
        ("HIERARCHY ROOT a { OFFSET 0 0 0 CHANNELS 1 Xrotation }", "malformed BVH"),
        ("HIERARCHY ROOT a { OFFSET 0 zero 0 } MOTION Frames: 1 Frame Time: 0.1", "malformed BVH"),
        ("HIERARCHY ROOT a { OFFSET 0 0 0 CHANNELS 1 Xrotation } MOTION Frames: 2 Frame Time: 0.1 5", "but holds 1 numbers"),
        ("HIERARCHY ROOT a { OFFSET 0 0 0 CHANNELS 1 Xrotation } MOTION Frames: 1 Frame Time: 0 5", "Frame Time must be positive"),
        ("HIERARCHY ROOT a { OFFSET 0 0 0 CHANNELS 1 Xrotation } MOTION Frames 1 Frame Time: 0.1 5", "lacks 'Frames:'"),
        ("HIERARCHY ROOT a { WHAT 0 0 0 } MOTION Frames: 1 Frame Time: 0.1", "unexpected token"),
    ]
    parse_errors = []
    for bad, phrase in errors:
        if phrase is None:   # empty: Python says "not a BVH file", TypeScript names the emptiness
            parse_errors.append({"text": bad, "phrase": "empty"})
            continue
        try:
            parse_bvh(bad, "bad.bvh")
        except BvhError as e:
            assert phrase in str(e), (phrase, str(e))
        else:
            raise AssertionError(f"no error for {bad!r}")
        parse_errors.append({"text": bad, "phrase": phrase})
    reduce_errors = []
    for bad, phrase in [(no_lfoot, "lacks joint(s) lFoot"),
                        (full_bvh_text(np.random.default_rng(1), rotating_collar=True), "rotates; cannot reduce")]:
        try:
            reduce_bvh(parse_bvh(bad, "bad.bvh"), "bad.bvh")
        except BvhError as e:
            assert phrase in str(e), (phrase, str(e))
        else:
            raise AssertionError("no reduce error")
        reduce_errors.append({"text": bad, "phrase": phrase})

    return {
        "tiny": {
            "text": TINY_BVH, "names": tiny.names, "parents": tiny.parents,
            "offsets": exact(tiny.offsets), "channels": tiny.channels, "frameTime": tiny.frame_time,
            "frames": tiny.frames, "motion": exact(tiny.motion),
            "localRotations": out7(tiny_rot), "localPositions": out7(tiny_pos),
            "worldRotations": out7(world_rot), "worldPositions": out7(world_pos),
        },
        "full": {
            "text": text, "names": full.names, "parents": full.parents, "frames": full.frames,
            "fullWorldPositions": out7(full_world),
            "reduced": {"positions": out7(motion.positions), "rotations": out7(motion.rotations),
                        "offsets": out7(motion.offsets), "fps": motion.fps},
            "resampledPhase1": {"frames": resampled.frames, "positions": out7(resampled.positions)},
            "root": out7(root), "heading": out7(heading),
            "facing": out7(facing_direction(motion.positions)),
            "mirrored": {"positions": out7(mirrored.positions), "rotations": out7(mirrored.rotations),
                         "offsets": out7(mirrored.offsets)},
            "fkReduced": out7(fk),
        },
        "smooth": {"input": exact(smooth_in), "width": 3,
                   "sigma2": out7(gaussian_smooth(smooth_in, 2.0)),
                   "sigma0_7": out7(gaussian_smooth(smooth_in, 0.7)),
                   "sigma0": out7(gaussian_smooth(smooth_in, 0.0))},
        "constants": {"names": JOINT_NAMES, "parents": PARENTS, "mirror": MIRROR},
        "parseErrors": parse_errors,
        "reduceErrors": reduce_errors,
    }


# ---------------------------------------------------------------- procedural dancers

def procedural_pair(rng: np.random.Generator) -> tuple[Motion, Motion]:
    t = np.arange(FRAMES) / FPS
    angle = 1.3 + 0.5 * t    # the pair turns slowly; the leader's heading crosses ±pi
    lead_offsets = OFFSETS.copy()
    follow_offsets = np.round(OFFSETS * 0.94, 6)
    leader = procedural_dancer(rng, FRAMES, angle, lead_offsets, 0.45)
    follower = procedural_dancer(rng, FRAMES, angle + np.pi, follow_offsets, 0.45)
    return leader, follower


# Rotations are read only at the frames t and t+1 (pose blocks) and, in the rollout, at NOW = 30.
# The others are zero: the fixture stays small, and a read from a wrong frame shows.
ROTATION_FRAMES = (28, 35)


def rounded_track(motion: Motion) -> Track:
    root, heading = root_from_motion(motion)
    rotations = np.zeros_like(motion.rotations)
    a, b = ROTATION_FRAMES
    rotations[a:b] = motion.rotations[a:b]
    # A count at 175.8 beats a minute, its first frame between beats (both dancers hear one music).
    beat = np.round(0.37 + np.arange(motion.frames) * 2.93 / 30, 6)
    return Track(motion.positions, rotations, np.round(root, 6), np.round(heading, 6), beat)


def features_fixture(rng: np.random.Generator, lead: Track, follow: Track) -> dict:
    frames = feat.valid_frames(FRAMES)
    assert list(frames) == [30, 31]
    # Stand-alone block inputs: random but shaped like the real thing.
    pts = np.round(rng.normal(0, 2, (4, 3)), 6)
    root = np.round(rng.normal(0, 1, 2), 6)
    heading = np.round(rng.uniform(-np.pi, np.pi), 6)
    key_roots = np.round(rng.normal(0, 1, (feat.KEYS, 2)), 6)
    key_headings = np.round(rng.uniform(-4, 4, feat.KEYS), 6)
    key_pos = np.round(rng.normal(0, 1, (feat.KEYS, 5, 3)), 6)
    t = 30
    pose_args = (lead.positions[t], lead.positions[t - 1], lead.rotations[t])
    updates = [  # root, heading, next root, next heading (the last two wrap across ±pi)
        ([0.1, 0.2], 0.3, [0.15, 0.18], 0.35),
        ([1.0, -2.0], 3.1, [1.02, -2.01], -3.12),
        ([-0.5, 0.5], -3.1, [-0.52, 0.49], 3.05),
    ]
    contacts_cases = []
    for f in range(1, FRAMES):
        contacts_cases.append(feat.foot_contacts(lead.positions[f], lead.positions[f - 1]))
    contacts_cases = np.array(contacts_cases)
    assert 0 < contacts_cases.mean() < 1, "the fixture should hold both planted and moving feet"
    # Hand-made feet around the thresholds (far from the origin, so x or z cannot stand in for y):
    # (left foot now, left before, right now, right before)
    feet = [
        ([2.0, 0.10, -3.0], [2.0, 0.10, -3.01], [2.5, 0.20, -3.0], [2.5, 0.20, -3.0]),    # low+slow | high
        ([2.0, 0.14, -3.0], [2.03, 0.14, -3.0], [2.5, 0.08, -3.0], [2.5, 0.06, -3.0]),     # fast x | slow
        ([-4.0, 0.12, 5.0], [-4.0, 0.10, 5.0], [-4.0, 0.05, 5.0], [-4.0, 0.05, 5.02]),   # fast y | fast z
        ([0.3, 0.149, 0.3], [0.3, 0.149, 0.3], [0.3, 0.151, 0.3], [0.3, 0.151, 0.3]),     # just below | above
    ]
    foot_pairs = []
    for l_now, l_before, r_now, r_before in feet:
        now, before = np.full((17, 3), 1.0), np.full((17, 3), 1.0)
        now[13], before[13], now[16], before[16] = l_now, l_before, r_now, r_before
        foot_pairs.append((now, before))

    h = np.asarray(heading)
    return {
        "frames": FRAMES, "t": [int(f) for f in frames],
        "rotationFrames": list(ROTATION_FRAMES),
        "leader": {"positions": exact(lead.positions), "root": exact(lead.root), "heading": exact(lead.heading),
                   "rotations": exact(lead.rotations[slice(*ROTATION_FRAMES)]), "beat": exact(lead.beat)},
        "follower": {"positions": exact(follow.positions), "root": exact(follow.root), "heading": exact(follow.heading),
                     "rotations": exact(follow.rotations[slice(*ROTATION_FRAMES)]), "beat": exact(follow.beat)},
        # What the dancers hear (training/mirror/music.py): the block for a few counts and tempos
        # (a count below 0, one far on), and the block the tracks' own count gives at each t.
        "music": {
            "MUSIC_OFFSETS": music.MUSIC_OFFSETS.tolist(), "MUSIC_SIZE": music.MUSIC_SIZE,
            "DEFAULT_TEMPO": music.DEFAULT_TEMPO, "TEMPO_RANGE": list(music.TEMPO_RANGE),
            "blocks": [{"beat": b, "bps": q, "expected": out7(music.music_block(np.array(b), np.array(q)))}
                       for b, q in ((0.0, 2.5), (-0.73, 3.1), (1234.56, 2.833333), (7.5, 3.3333333))],
            "at": out7(music.music_at(lead.beat, frames)),
            "beatsPerStep": [{"bpm": b, "expected": music.beats_per_step(b)} for b in (150.0, 170.0, 200.0)],
        },
        "constants": {
            "KEYS": feat.KEYS, "KEY_STEP": feat.KEY_STEP, "PAST_OFFSETS": feat.PAST_OFFSETS.tolist(),
            "FUTURE_OFFSETS": feat.FUTURE_OFFSETS.tolist(), "HISTORY": feat.HISTORY,
            "INPUT_SIZE": feat.INPUT_SIZE, "OUTPUT_SIZE": feat.OUTPUT_SIZE, "INTENTION_SIZE": feat.INTENTION_SIZE,
            "FOLLOWER_INPUT_LAYOUT": feat.FOLLOWER_INPUT_LAYOUT, "LEADER_INPUT_LAYOUT": feat.LEADER_INPUT_LAYOUT,
            "OUTPUT_LAYOUT": feat.OUTPUT_LAYOUT, "INTENTION_LAYOUT": feat.INTENTION_LAYOUT,
            "CONTACT_HEIGHT": feat.CONTACT_HEIGHT, "CONTACT_SPEED": feat.CONTACT_SPEED,
            "LEADER_INPUT_SIZE": feat.LEADER_INPUT_SIZE, "FIGURE_SIZE": feat.FIGURE_SIZE,
            "FIGURE_KINDS": [list(k) for k in feat.FIGURE_KINDS], "FIGURE_OFFSETS": feat.FIGURE_OFFSETS.tolist(),
            "followerSlices": {k: [v.start, v.stop] for k, v in feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT).items()},
        },
        "rootSpace": {
            "points": exact(pts), "root": exact(root), "heading": float(heading),
            "toPoints": out7(feat.to_root_space_points(pts, root, h)),
            "toDirections": out7(feat.to_root_space_directions(pts, h)),
            "fromPoints": out7(feat.from_root_space_points(pts, root, h)),
            "fromDirections": out7(feat.from_root_space_directions(pts, h)),
        },
        "blocks": {
            "root": exact(root), "heading": float(heading),
            "keyRoots": exact(key_roots), "keyHeadings": exact(key_headings),
            "trajectory": out7(feat.trajectory_block(key_roots, key_headings, root, h)),
            "keyPositions": exact(key_pos),
            "keyJoints": out7(feat.key_joints_block(key_pos, root, h)),
            "poseFrame": t,
            "pose": out7(feat.pose_block(*pose_args, root, h)),
            "rootUpdates": [{"args": [r[0], r[1], hd, n[0], n[1], nh],
                             "expected": out7(feat.root_update(np.array(r), np.array(hd), np.array(n), np.array(nh)))}
                            for r, hd, n, nh in updates],
            "footContacts": out7(contacts_cases),
            "footCases": [{"positions": exact(n), "previous": exact(b), "expected": out7(feat.foot_contacts(n, b))}
                          for n, b in foot_pairs],
        },
        "followerInput": out7(feat.follower_input(lead, follow, frames)),
        "leaderInput": out7(feat.leader_input(follow, lead, frames)),
        # The figure block (features.figure_block) for spans around the fixture's frames.
        "figureBlocks": figure_block_cases(frames),
        # Both inputs with a figure being led (the figure block of LED_SPANS, in the tracks' frames)
        # and the leader's with the hands plan of his samples: his own hands' moves over the next second.
        "ledSpans": exact(LED_SPANS),
        "handsMoves": out7(feat.hands_moves(lead, frames)),
        "followerInputLed": out7(feat.follower_input(lead, follow, frames, feat.figure_block(LED_SPANS, frames))),
        "leaderInputLed": out7(feat.leader_input(follow, lead, frames, feat.figure_block(LED_SPANS, frames),
                                                 feat.hands_plan_block(feat.hands_moves(lead, frames), len(frames)))),
        "followerOutput": out7(feat.output_features(follow, frames)),
        "leaderOutput": out7(feat.output_features(lead, frames)),
        "followerIntention": out7(feat.intention_target(lead, follow, frames)),
        "leaderIntention": out7(feat.intention_target(follow, lead, frames)),
    }


# The figure kinds (features.FIGURE_KINDS): her turn to her left, to her right, his turn to his
# left, to his right.
HER_LEFT, HER_RIGHT, HIS_LEFT, HIS_RIGHT = (feat.FIGURE_KINDS.index(k) for k in (
    ("her_turn", 1), ("her_turn", -1), ("his_turn", 1), ("his_turn", -1)))

# Figures of every kind in the features fixture's frames (t = 30, 31): her turn to her left ended
# 10 frames ago, his to his right running, her turn to her right beginning 12 frames on and his to
# his left within it, ending at the last key of t = 31.
LED_SPANS = np.array([(HER_LEFT, -5, 20), (HIS_RIGHT, 14, 40), (HER_RIGHT, 43, 70), (HIS_LEFT, 50, 61)])


def figure_block_cases(frames: np.ndarray) -> list[dict]:
    """features.figure_block at the fixture's frames: no figure, and spans of each kind that start
    or end on a key, overlap (the same kind: the later one's progress; other kinds: each its own),
    last one frame or none (start == end), or lie beyond the block's reach (t-30, t+30)."""
    cases = [
        None,
        [],
        [(HER_LEFT, 30, 60)],                      # begins now at t = 30, a frame ago at t = 31
        [(HER_RIGHT, 0, 30)],                      # began at the block's first key, ends now
        [(HIS_LEFT, 30, 50)],
        [(HIS_RIGHT, 12, 33)],
        [(HER_LEFT, 10, 40), (HER_LEFT, 35, 50)],  # the same kind, overlapping: the later one's progress
        [(HIS_RIGHT, 10, 40), (HIS_RIGHT, 35, 50)],
        [(HER_LEFT, 10, 40), (HER_RIGHT, 35, 50)],  # both ways of her turn at once
        [(HER_LEFT, 10, 40), (HIS_LEFT, 20, 40), (HER_RIGHT, 35, 50), (HIS_RIGHT, 38, 58)],  # every kind at once
        [(HER_RIGHT, 45, 45), (HIS_LEFT, 20, 21)],   # a one-frame figure, and one of two frames
        [(HER_LEFT, -40, -1), (HIS_RIGHT, 62, 90)],  # out of reach at t = 30 (the past key -1 is t-31)
        [(HIS_RIGHT, 5, 61), (HER_LEFT, 61, 95), (HER_RIGHT, 70, 80)],  # the last key's edge at t = 31
    ]
    return [{"figures": None if c is None else [list(map(int, f)) for f in c],
             "expected": out7(feat.figure_block(None if c is None else np.array(c).reshape(-1, 3), frames))}
            for c in cases]


# ---------------------------------------------------------------- rollout

def start_pose_of(track: Track, t: int, fps: float = 30.0) -> dict:
    """A start pose like training/learning/export.py's: a pose block (own root space), 4 decimals."""
    pose = feat.pose_block(track.positions[t], track.positions[t - 1], track.rotations[t],
                           track.root[t], track.heading[t], fps).reshape(feat.N_JOINTS, 12)
    return {"hip": np.round(pose[0, :3], 4).tolist(), "forward": np.round(pose[:, 6:9], 4).tolist(),
            "up": np.round(pose[:, 9:12], 4).tolist()}


def dancer_state(d: ro.Dancer) -> dict:
    """What a step changes: the current frame, the frame before and the oldest (the shift), the
    root path with its plan, contacts, intention."""
    t, now = d.track, ro.NOW
    return {"positionsNow": out7(t.positions[now]), "positionsBefore": out7(t.positions[now - 1]),
            "positionsFirst": out7(t.positions[0]), "rotationsNow": out7(t.rotations[now]),
            "root": out7(t.root), "heading": out7(t.heading), "contacts": out7(d.contacts),
            "resets": d.resets, "intention": None if d.intention is None else out7(d.intention)}


def hip_slack_cases() -> list[dict]:
    """guard.hip_slack_for with and without a hip margin."""
    return [{"margin": margin, "hipMargin": hip_margin, "slack": G.hip_slack_for(margin, hip_margin)}
            for margin, hip_margin in ((0.05, 0.2), (0.05, 0.15), (0.07, 0.1), (0.05, None))]


_CONTACTS_OUT = feat.block_slices(feat.OUTPUT_LAYOUT)["contacts"]


def on_count_cases(rng: np.random.Generator, outputs: np.ndarray, ranges: dict, offsets) -> dict:
    """training/mirror/on_count.py on inputs of each role whose music block is a count (random
    otherwise), three steps of each dancer's chooser, and the choice among the upright fixture's
    outputs at margins where all, some and none of them stand."""
    cases = {}
    for role, size in (("leader", feat.LEADER_INPUT_SIZE), ("follower", feat.INPUT_SIZE)):
        chooser = OC.OnCount(role, 4, 0.8)
        steps = []
        # facing 5 frames ago, turned by 0.05 rad (a step), 0.2 rad (a slow walk round) and 1.2 rad (a
        # spin); each step taken plants its left foot, its right, then neither (the next footwork now
        # counts a planted foot still: OnCount.took)
        for beat, turned, contacts in ((3.37, 0.05, (0.9, 0.1)), (3.39, 0.2, (0.2, 0.7)), (3.41, 1.2, (0.5, 0.3))):
            x = rng.normal(0, 0.7, size)
            x[OC.LAST_FACING[role]:OC.LAST_FACING[role] + 2] = np.sin(turned), np.cos(turned)
            x[-music.MUSIC_SIZE:] = music.music_block(np.array(beat), np.array(2.9))
            target = chooser.target(x)
            took = outputs[0].copy()
            took[_CONTACTS_OUT] = contacts
            chooser.took(took)
            steps.append({"input": exact(x), "footwork": out7(OC.footwork_now(x, role)), "took": exact(took),
                          "count": out7(OC.count_next(x)), "turnRate": out7(OC.turn_rate(x, role)),
                          "turnNow": out7(OC.turn_now(x, role)),
                          "target": None if target is None else out7(target), "mean": out7(chooser.mean)})
        cases[role] = steps
    # The choice among the upright fixture's bodies, from a follower's input whose own hips and
    # ankles stand where the first body draws them, her hips having come in against the first's
    # step and along the second's: the first turns them back, the second goes on.
    x = rng.normal(0, 0.7, feat.INPUT_SIZE)
    joints = G.drawn_joints(outputs, offsets)
    x[OC.POSITION_IN["follower"]] = joints[0, OC.STEPPED]
    x[OC.HIP_VELOCITY_IN["follower"]] = 0
    steps = OC.drawn_steps(outputs, joints, x, "follower")
    s0, s1 = steps[0, 0], steps[1, 0]
    x[OC.HIP_VELOCITY_IN["follower"]] = (s1 / np.linalg.norm(s1) - s0 / np.linalg.norm(s0)) * 0.01 * FPS
    footwork, back = OC.drawn_footwork(steps), OC.hips_turn_back(steps, x, "follower")
    # the same steps, each body planting its left foot, its right, both, neither
    planting = outputs.copy()
    planting[:, _CONTACTS_OUT] = np.resize(np.array([[0.8, 0.2], [0.4, 0.9], [0.6, 0.7], [0.5, 0.1]]), (len(outputs), 2))
    standing = G.upright_margin(outputs, ranges, offsets)
    target = float(0.55 * footwork[0] + 0.45 * footwork[1])   # nearer the first, unless its hips count
    # Her turn starts: the same bodies, their planned paths turning 300 degrees to her left (the
    # first), 90 (the second), 200 to her right (the third) and not at all (the fourth): from 180
    # degrees the first and third start a turn, from 60 all but the fourth, from 400 none.
    turned = outputs.copy()
    future = feat.block_slices(feat.OUTPUT_LAYOUT)["trajectory_future"]
    for i, degrees in enumerate((300.0, 90.0, -200.0, 0.0)):
        keys = turned[i, future].reshape(feat.KEYS, 4)
        h = np.radians(degrees) * np.arange(1, feat.KEYS + 1) / feat.KEYS
        keys[:, 2], keys[:, 3] = 0.8 * np.sin(h), 0.8 * np.cos(h)
        turned[i, future] = keys.ravel()
    starts = {f"{d}": OC.starts_turn(turned, d).tolist() for d in (60.0, 180.0, 400.0)}
    return {"roles": cases, "outputs": exact(outputs), "input": exact(x),
            "turned": exact(turned), "plannedTurn": out7(OC.planned_turn(turned)), "starts": starts,
            "bestPreferred": {f"{m}/{d}": OC.nearest_count(footwork, back, target, standing, m, 1.0, np.array(starts[f"{d}"]))
                              for m in (-9.0, 0.0, 0.05, 9.0) for d in (60.0, 180.0, 400.0)},
            "steps": out7(steps.reshape(len(outputs), -1)),
            "footwork": out7(footwork), "turnBack": back.tolist(), "planting": exact(planting),
            "planted": OC.planted(planting).tolist(), "footworkStill": out7(OC.drawn_footwork(steps, OC.planted(planting))), "standing": out7(standing), "target": out7(target),
            "best": {f"{m}/{h}": OC.nearest_count(footwork, back, target, standing, m, h)
                     for m in (-9.0, 0.0, 0.05, 9.0) for h in (0.0, 1.0)},
            **figure_choice_cases(outputs)}


# The figures figure_choice_cases reads, at frame FIGURE_T: (name, spans) where a span of each kind
# runs now, begins at the first and the last key within FIGURE_AHEAD, begins a key beyond it, ended
# just before now; her turn and his at once; both ways of her turn at once.
FIGURE_T = 30
_AHEAD = OC.FIGURE_AHEAD * feat.KEY_STEP
FIGURE_LABELS = {"her_left": HER_LEFT, "her_right": HER_RIGHT, "his_left": HIS_LEFT, "his_right": HIS_RIGHT}


def _figure_spans() -> list[tuple[str, list[tuple[int, int, int]]]]:
    spans: list[tuple[str, list[tuple[int, int, int]]]] = [("none", [])]
    for label, kind in FIGURE_LABELS.items():
        t = FIGURE_T
        spans += [(f"{label}/now", [(kind, t - 10, t + 20)]), (f"{label}/next", [(kind, t + feat.KEY_STEP, t + 40)]),
                  (f"{label}/ahead", [(kind, t + _AHEAD, t + 40)]),
                  (f"{label}/beyond", [(kind, t + _AHEAD + 1, t + 40)]), (f"{label}/past", [(kind, t - 25, t - 1)])]
    return spans + [("her and his", [(HER_RIGHT, FIGURE_T - 5, FIGURE_T + 20), (HIS_LEFT, FIGURE_T + 3, FIGURE_T + 30)]),
                    ("her both ways", [(HER_RIGHT, FIGURE_T - 5, FIGURE_T + 20), (HER_LEFT, FIGURE_T + 8, FIGURE_T + 30)])]


def figure_choice_cases(outputs: np.ndarray) -> dict:
    """on_count.figure_way on inputs of each role (zeros but for the figure block, at FIGURE_IN: the
    fixture holds the block alone) whose figure block holds each kind now, coming within and beyond
    FIGURE_AHEAD, past, none, and two at once; and OnCount.prefers with figure_turn on 8 candidates
    whose planned paths turn various amounts, from inputs with and without a figure, turning or not,
    and without figure_turn."""
    ways = {}
    inputs = {}
    for role, size in (("leader", feat.LEADER_INPUT_SIZE), ("follower", feat.INPUT_SIZE)):
        rows = []
        inputs[role] = {}
        for name, spans in _figure_spans():
            block = np.round(feat.figure_block(np.array(spans, np.int64).reshape(-1, 3), np.array([FIGURE_T]))[0], 6)
            x = np.zeros(size)
            x[OC.FIGURE_IN[role]:OC.FIGURE_IN[role] + feat.FIGURE_SIZE] = block
            inputs[role][name] = x
            rows.append({"name": name, "figure": exact(block), "way": OC.figure_way(x, role)})
        ways[role] = rows
    # 8 candidates (the upright fixture's bodies twice), their planned paths turning these degrees.
    degrees = (300.0, 185.0, 90.0, 0.0, -60.0, -179.0, -200.0, -400.0)
    figured = np.tile(outputs, (2, 1))
    future = feat.block_slices(feat.OUTPUT_LAYOUT)["trajectory_future"]
    for i, d in enumerate(degrees):
        keys = figured[i, future].reshape(feat.KEYS, 4)
        h = np.radians(d) * np.arange(1, feat.KEYS + 1) / feat.KEYS
        keys[:, 2], keys[:, 3] = 0.8 * np.sin(h), 0.8 * np.cos(h)
        figured[i, future] = keys.ravel()
    figured = np.round(figured, 6)
    chosen = []
    for role in ("leader", "follower"):
        for figure_turn in (OC.FIGURE_TURN, 90.0, None):
            for name in ("none", "her_left/now", "her_right/ahead", "his_left/next", "his_right/now",
                         "her_left/beyond", "her and his", None):
                for turning in (False, True):
                    chooser = OC.OnCount(role, 8, 1.0, figure_turn=figure_turn)
                    chooser.turning = turning
                    got = chooser.prefers(figured, None if name is None else inputs[role][name])
                    chosen.append({"role": role, "figureTurn": figure_turn, "figure": name,
                                   "turning": turning, "prefers": None if got is None else got.tolist()})
    return {"figureIn": OC.FIGURE_IN, "figureAhead": OC.FIGURE_AHEAD, "figureTurn": OC.FIGURE_TURN,
            "figureWays": ways, "figured": exact(figured), "figuredTurn": out7(OC.planned_turn(figured)),
            "figurePrefers": chosen}


class Draws:
    """A stand-in for Figures.rng: .random() gives these numbers in order (the TypeScript tests feed
    the same list to their Figures), so both sides plan the same own figures."""

    def __init__(self, numbers):
        self.numbers = [float(v) for v in numbers]
        self.used = 0

    def random(self) -> float:
        self.used += 1
        return self.numbers[self.used - 1]


def led_state(figures: ro.Figures) -> list[list]:
    """Every figure of a duet as [name, way, start, end, asked]."""
    return [[x.name, x.way, x.start, x.end, x.asked] for x in figures.led]


# The schedule fixture: a duet's clock alone (no models), the visitor's asks at some frames, his
# own figures switched off for a while; (frame, direction) before that frame's step. His own, drawn
# from SCHEDULE_DRAWS (a seed whose draws give every kind): his turn to his left (44-64), to his
# right (191-211, taken over by an ask; 408-428), her turn to her right (250-284).
SCHEDULE_FRAMES = 420
SCHEDULE_DRAWS = SEED + 39
SCHEDULE_ASKS = [
    (50, -1),     # his own turn runs (44-64): the ask follows it, on the next beat (73)
    (51, 1),      # asked again before that began: the second takes the place of the first
    (80, -1),     # the asked figure runs (73-107): this one follows it (113)
    (180, 1),     # his own turn is planned (191), not begun: the ask takes its place, on the next beat (181)
    (300, -1),    # his own are off: on the next beat (309)
    (301, -1),    # and again before it began
]
SCHEDULE_OWN_OFF = (260, 330)   # frames [from, to) with Figures.own off


def figures_fixture(manifest: dict) -> dict:
    """The figures of a duet (rollout.Figures) over SCHEDULE_FRAMES steps of its clock at a tempo
    between beats, his own drawn from a fixed list: each step the visitor's asks, then plan_figures
    (as step() and the page run it), then what is danced; and the count helpers on their own."""
    draws = Draws(np.round(np.random.default_rng(SCHEDULE_DRAWS).random(40), 6))
    duet = ro.start_duet(manifest, tempo=183.0)
    duet.beat = 0.61
    duet.figures = ro.Figures(own=True, rng=draws)
    asks = dict(SCHEDULE_ASKS)
    steps = []
    for frame in range(SCHEDULE_FRAMES):
        assert duet.frame == frame
        duet.figures.own = not (SCHEDULE_OWN_OFF[0] <= frame < SCHEDULE_OWN_OFF[1])
        if frame in asks:
            ro.ask_turn(duet, asks[frame])
        ro.plan_figures(duet)
        at = duet.figures.at(frame)
        steps.append({"led": led_state(duet.figures), "at": None if at is None else duet.figures.led.index(at),
                      "spans": duet.figures.spans(frame).ravel().tolist()})
        duet.frame += 1
        duet.beat += music.beats_per_step(duet.tempo)
    # The helpers on a clock at frame 7, beat 2.95 (0.05 before the 3).
    clock = ro.start_duet(manifest, tempo=171.0)
    clock.frame, clock.beat = 7, 2.95
    to_beat = [{"frame": f, "beat": b, "expected": ro.frames_to_beat(clock, f, b)}
               for f, b in ((7, 3.0), (7, 2.9), (7, 2.95), (7, 4.0), (12, 4.0), (3, 3.0))]
    figure_from = [{"frame": f, "name": n, "way": w, "asked": a,
                    "expected": led_state(ro.Figures(led=[ro.figure_from(clock, f, n, w, a)]))[0]}
                   for f, n, w, a in ((7, "her_turn", 1, True), (8, "her_turn", -1, False), (10, "her_turn", 0, True),
                                      (40, "her_turn", -3, False), (7, "his_turn", 1, False), (12, "his_turn", -1, False),
                                      (40, "his_turn", 2, True))]
    led = ro.Led("her_turn", -1, 20, 56)
    share = [{"frame": f, "share": ro.figure_share(led, f), "raised": ro.raised(led, f)}
             for f in (0, 19, 20, 21, 26, 32, 38, 50, 56, 57, 64, 71, 72, 100)]
    # leading and leader_variety: a figure asked for from frame 40 to 76 and one of his own from 100
    # to 136, the leader at 0.6, leading at 0.9
    lead_in = ro.start_duet(manifest)
    lead_in.figures.led = [ro.Led("her_turn", 1, 40, 76, True), ro.Led("her_turn", -1, 100, 136, False)]
    lead_in.leading_temperature = 0.9
    leading = []
    for f in (0, 9, 10, 40, 76, 77, 90, 110):
        lead_in.frame = f
        leading.append({"frame": f, "leading": ro.leading(lead_in), "variety": ro.leader_variety(lead_in, 0.6)})
    return {"tempo": 183.0, "beat": 0.61, "draws": draws.numbers, "drawn": draws.used, "asks": SCHEDULE_ASKS,
            "LEAD_IN": ro.LEAD_IN, "leading": {"led": led_state(lead_in.figures), "frames": leading},
            "ownOff": list(SCHEDULE_OWN_OFF), "steps": steps,
            "FIGURE_BEATS": ro.FIGURE_BEATS, "OWN_GAP_BEATS": list(ro.OWN_GAP_BEATS), "HIS_SHARE": ro.HIS_SHARE,
            "RAISE": list(ro.RAISE),
            "clock": {"tempo": 171.0, "frame": 7, "beat": 2.95, "framesToBeat": to_beat, "figureFrom": figure_from},
            "led": [led.name, led.way, led.start, led.end], "share": share}


def rollout_fixture(rng: np.random.Generator, lead: Track, follow: Track, lead_offsets, follow_offsets) -> dict:
    vectors_f = np.round(rng.normal(size=(5, 3)), 6)
    vectors_u = np.round(rng.normal(size=(5, 3)), 6)
    start_pose = {"leader": start_pose_of(lead, 30), "follower": start_pose_of(follow, 32)}  # rotations exist there
    manifest = {"skeleton": {"offsets": {"leader": lead_offsets.tolist(), "follower": follow_offsets.tolist()}},
                "startPose": start_pose}
    started = ro.start_duet(manifest)
    request_hands = np.round(np.random.default_rng(30).normal([0.0, 1.3, 0.25], 0.15, size=(2, 2, 3)), 5)

    def window(track: Track) -> Track:   # frames 0..60 of a procedural track: NOW is its frame 30
        n = ro.TRACK_FRAMES
        return Track(track.positions[:n].copy(), track.rotations[:n].copy(), track.root[:n].copy(),
                     track.heading[:n].copy())

    def plausible(track: Track, t: int) -> np.ndarray:
        """An output a model could give: the true next frame, a little noisy, in float32."""
        o = feat.output_features(track, np.array([t]))[0]
        o = o + rng.normal(0, 0.01, o.shape)
        o[feat.block_slices(feat.OUTPUT_LAYOUT)["contacts"]] = rng.uniform(0, 1, 2)
        return o.astype(np.float32).astype(np.float64)

    # The music at another tempo than the default, its count between beats: each step reads both.
    # His own figure is planned at the first step (his turn to his left, 1.25 beats on: the draws are
    # the wait, whose turn and its way), and taken over by the visitor's ask before the second (her
    # turn to her right, on the next beat).
    step_draws = Draws([0.1, 0.2, 0.3])
    duet = ro.Duet(ro.Dancer(lead_offsets, window(lead)), ro.Dancer(follow_offsets, window(follow)), start_pose,
                   tempo=176.5, beat=0.3, figures=ro.Figures(own=True, rng=step_draws))
    duet.steering.velocity = np.array([0.3, -0.2])
    steps = []
    scenarios = [
        # (stick, what to do to the leader output, ... to the follower output)
        ([0.6, -0.5], None, None),
        ([0.0, 0.0], "nan", None),
        ([0.2, 0.9], None, "jump"),
        ([1.0, 1.0], "far", None),
    ]
    ask = {1: -1}   # before step 1 the visitor asks for a clockwise turn
    for i, (stick, lead_bad, follow_bad) in enumerate(scenarios):
        if i in ask:
            ro.ask_turn(duet, ask[i])
        before_velocity = duet.steering.velocity.copy()
        ro.plan_figures(duet)   # as step(): first
        ro.steer_plan(duet.leader, duet.steering, np.array(stick, float))
        ro.lead_plan(duet)   # a figure is near from the first step: the plan bent his way, then hers
        planned_root, planned_heading = duet.leader.track.root.copy(), duet.leader.track.heading.copy()
        xl, xf = ro.step_inputs(duet)
        ol, of = plausible(lead, 30 + i % 2), plausible(follow, 30 + i % 2)
        fi = feat.intention_target(lead, follow, np.array([30]))[0].astype(np.float32).astype(np.float64)
        spoil = {"nan": (50, float("nan")), "far": (117 + 12 * 7, 3.5), "jump": (0, 1.2)}  # lHand x
        lead_out, follow_out = ol.copy(), of.copy()
        for out, bad in ((lead_out, lead_bad), (follow_out, follow_bad)):
            if bad:
                k, v = spoil[bad]
                out[k] = v
        absurd = [ro.output_is_absurd(lead_out), ro.output_is_absurd(follow_out)]
        ro.finish_step(duet, lead_out, follow_out, fi)
        steps.append({
            "stick": stick, "steeringBefore": exact(before_velocity),
            "steeringAfter": out7(duet.steering.velocity), "plannedLeaderRoot": out7(planned_root),
            "plannedLeaderHeading": out7(planned_heading),
            "leaderInput": out7(xl), "followerInput": out7(xf),
            "leaderOutput": [None if not np.isfinite(v) else float(v) for v in lead_out],
            "followerOutput": [float(v) for v in follow_out],
            "followerIntention": exact(fi), "absurd": absurd, "ask": ask.get(i), "led": led_state(duet.figures),
            "leader": dancer_state(duet.leader), "follower": dancer_state(duet.follower),
        })
    # The guards: the leader drawn toward its anchor; a follower 3.3 m away leashed.
    apart = ro.start_duet(manifest)
    shift = np.array([2.1, 2.5])
    apart.follower.track.root += shift
    apart.follower.track.positions[..., [0, 2]] += shift
    apart.steering.anchor = np.array([-1.4, 0.8])
    apart.steering.velocity = np.array([0.2, 0.0])     # steered a little: a smaller free circle
    ro.follow_anchor(apart.leader, apart.steering)
    leashed = ro.keep_close(apart.follower, apart.leader)
    guards = {"shift": exact(shift), "anchor": exact(apart.steering.anchor),
              "velocity": exact(apart.steering.velocity), "leashed": leashed,
              "leader": dancer_state(apart.leader), "follower": dancer_state(apart.follower)}
    # The upright guard (training/mirror/guard.py): plausible follower outputs, one tipped over by its
    # rotations alone (positions standing), one sunk by its hip (its ankles below the floor, so the
    # drawn body is lifted part of the way back); margins judged on the drawn body.
    pose = feat.block_slices(feat.OUTPUT_LAYOUT)["pose"]
    upright = [plausible(follow, 30), plausible(follow, 31)]
    tipped = upright[0].copy()
    vectors = tipped[pose].reshape(feat.N_JOINTS, 12)
    vectors[:, 6:12] = np.stack([vectors[:, 6], -vectors[:, 8], vectors[:, 7],
                                 vectors[:, 9], -vectors[:, 11], vectors[:, 10]], -1)   # 90 degrees about x
    tipped[pose] = vectors.ravel()
    sunk = upright[1].copy()
    sunk[pose.start + 1] -= 0.5
    outputs = np.stack(upright + [tipped, sunk])
    ranges = {"hip_low": 0.95, "head_above_hip_low": 0.5, "feet_wide": 1.07, "angle_high": [2.5, 0.59]}  # this body's
    # The leader's head margin: the head over the hips let off 0.04 m, under a range whose head part
    # binds for the upright bodies (so the slack shows).
    tight = {**ranges, "head_above_hip_low": 0.75}
    plan_input = np.zeros(feat.LEADER_INPUT_SIZE)
    plan_input[G.HANDS_PLAN_SHOWN] = 1.0
    plan_input[G.HAND_HEIGHTS] = 0.8, 0.7
    plan_input[G.HAND_PLAN_FIRST] = 0.05, 0.4
    uprightness = {"outputs": exact(outputs), "ranges": ranges,
                   "margins": out7(G.upright_margin(outputs, ranges, follow_offsets)),
                   "best": G.most_upright(outputs, ranges, follow_offsets),
                   "tight": tight, "tightMargins": out7(G.upright_margin(outputs, tight, follow_offsets)),
                   "slackMargins": out7(G.upright_margin(outputs, tight, follow_offsets, 0.04)),
                   # The follower's hip margin: her hips judged 0.1 m further from the edge.
                   "hipSlackMargins": out7(G.upright_margin(outputs, ranges, follow_offsets, 0.0, -0.1)),
                   "hipSlackBest": G.most_upright(outputs, ranges, follow_offsets, 0.0, -0.1),
                   "handsPlanShown": G.HANDS_PLAN_SHOWN,
                   # The hips' slack from a guard's hip margin (guard.hip_slack_for).
                   "hipSlack": hip_slack_cases(),
                   # The leader's lead hand kept to a request's plan (guard.lead_hand_miss, nearest_plan),
                   # on the same bodies: the plan raises his right hand 0.4 m by the first key. At margin 0
                   # the second body's hand is nearest; at 0.05 it does not stand, and the first is taken.
                   "handHeights": G.HAND_HEIGHTS, "handPlanFirst": G.HAND_PLAN_FIRST,
                   "planInput": exact(plan_input), "planMiss": out7(G.lead_hand_miss(outputs, plan_input, follow_offsets)),
                   "planBest": G.nearest_plan(outputs, plan_input, ranges, follow_offsets, 0.0),
                   "planBestStanding": G.nearest_plan(outputs, plan_input, ranges, follow_offsets, 0.05),
                   # The n standing bodies nearest the plan (guard.near_plan), n = 1..4, at margin 0 and 0.05.
                   "nearPlan": {str(margin): [G.near_plan(G.drawn_joints(outputs, follow_offsets), plan_input,
                                                          G.upright_margin(outputs, ranges, follow_offsets), margin, n).tolist()
                                              for n in range(1, 5)] for margin in (0.0, 0.05)}}
    return {
        "NOW": ro.NOW, "TRACK_FRAMES": ro.TRACK_FRAMES, "guards": guards, "upright": uprightness,
        "onCount": on_count_cases(np.random.default_rng(SEED + 3), outputs, ranges, follow_offsets),
        "rotationsFromVectors": {"forward": exact(vectors_f), "up": exact(vectors_u),
                                 "expected": out7(ro.rotations_from_vectors(vectors_f, vectors_u))},
        "offsets": {"leader": exact(lead_offsets), "follower": exact(follow_offsets)},
        "startPose": start_pose, "tempo": 176.5, "beat": 0.3, "beatAfter": duet.beat,
        "startDuet": {"leader": dancer_state(started.leader), "follower": dancer_state(started.follower),
                      "tempo": started.tempo, "beat": started.beat},
        "steps": steps,
        "stepDraws": step_draws.numbers, "stepDrawn": step_draws.used,
        "figures": figures_fixture(manifest),
        "handsInputs": hands_input_cases(lead_offsets, window(lead), request_hands),
        "leadPlans": lead_plan_cases(lead_offsets, window(lead)),
    }


# A figure at duet frames 40-76 for the hands plan and the bent path, read at frames around it.
HANDS_FIGURE = (40, 76)
HANDS_FRAMES = (5, 10, 11, 25, 40, 46, 52, 70, 76, 80, 91, 92)


def hands_input_cases(offsets, track: Track, hands: np.ndarray) -> list[dict]:
    """rollout.hands_input for the leader standing at frame 30 of the procedural track, a figure of
    each kind (his hands when its plan began given, or taken now: None; his own turn has no plan)
    at HANDS_FRAMES, and two figures at once (the plan is for the first near her turn)."""
    out = []
    for name, way, given in (("her_turn", 1, hands[0]), ("her_turn", -1, hands[1]), ("her_turn", -1, None),
                             ("his_turn", 1, None), ("his_turn", -1, hands[1])):
        for frame in HANDS_FRAMES:
            duet = ro.Duet(ro.Dancer(offsets, track), ro.Dancer(offsets, track), {}, frame=frame)
            led = ro.Led(name, way, *HANDS_FIGURE, hands=None if given is None else given.copy())
            duet.figures.led = [led]
            moves = ro.hands_input(duet)
            out.append({"name": name, "way": way, "frame": frame, "hands": None if given is None else exact(given),
                        "moves": None if moves is None else out7(moves),
                        "handsAfter": None if led.hands is None else out7(led.hands)})
    for two in ([("her_turn", 1, 20, 56), ("her_turn", -1, 60, 96)],
                [("his_turn", 1, 50, 70), ("her_turn", -1, 60, 96)],   # his own turn first: the plan is for hers
                [("her_turn", 1, 20, 56), ("his_turn", -1, 60, 96)]):  # hers lowering while his runs
        duet = ro.Duet(ro.Dancer(offsets, track), ro.Dancer(offsets, track), {}, frame=70)
        duet.figures.led = [ro.Led(n, w, a, b, hands=h.copy()) for (n, w, a, b), h in zip(two, hands)]
        out.append({"two": [list(x) for x in two], "hands": [exact(hands[0]), exact(hands[1])], "frame": 70,
                    "moves": out7(ro.hands_input(duet))})
    return out


def lead_plan_cases(offsets, track: Track) -> list[dict]:
    """rollout.lead_plan on the leader's planned path (the procedural track's frames 31-60) for a
    figure of each kind and for two at once (her turn and his), at frames before, in and after them."""
    out = []
    for spans in ([("her_turn", 1, *HANDS_FIGURE)], [("her_turn", -1, *HANDS_FIGURE)],
                  [("his_turn", 1, *HANDS_FIGURE)], [("his_turn", -1, 40, 60)],
                  [("her_turn", 1, 20, 56), ("her_turn", -1, 60, 96)],
                  [("his_turn", -1, 20, 40), ("her_turn", 1, 50, 86)]):
        for frame in (0, 15, 30, 45, 58, 70, 76, 90):
            leader = ro.Dancer(offsets, Track(track.positions, track.rotations, track.root.copy(), track.heading.copy()))
            duet = ro.Duet(leader, leader, {}, frame=frame)
            duet.figures.led = [ro.Led(n, w, a, b) for n, w, a, b in spans]
            ro.lead_plan(duet)
            out.append({"figures": [list(x) for x in spans], "frame": frame,
                        "root": out7(leader.track.root), "heading": out7(leader.track.heading)})
    return out


def contact_fixture(rng: np.random.Generator, leader: Motion, follower: Motion) -> dict:
    """The contact layer (training/mirror/contact.py) over CONTACT_STEPS frames of the procedural pair,
    pushed together so the spines overlap, the hands come within reach and drift apart again, and
    the feet touch down and lift: every branch of separation, hold and foot lock runs."""
    steps = CONTACT_STEPS
    lead = np.round(leader.positions[:steps], 5)
    follow = follower.positions[:steps].copy()
    # Walk the follower into the leader and out again: centre distance 0.6 -> 0.1 -> 0.6 m.
    gap = np.concatenate([np.linspace(0.6, 0.1, steps // 2), np.linspace(0.1, 0.6, steps - steps // 2)])
    toward = lead[:, :1, [0, 2]] - follow[:, :1, [0, 2]]
    toward /= np.linalg.norm(toward, axis=-1, keepdims=True)
    shift = toward * (np.linalg.norm(lead[:, :1, [0, 2]] - follow[:, :1, [0, 2]], axis=-1, keepdims=True)
                      - gap[:, None, None])
    follow[:, :, [0, 2]] += shift
    follow = np.round(follow, 5)
    # Foot contacts: on/off runs, with values around the 0.5 threshold.
    lead_c = np.round(rng.uniform(0, 1, (steps, 2)) ** 0.5, 3)
    follow_c = np.round(np.where((np.arange(steps)[:, None] // 5 + np.arange(2)) % 2 == 0, 0.9, 0.1), 3)
    lead_h = np.round(1.3 + 0.5 * np.arange(steps) / FPS, 6)
    follow_h = np.round(lead_h + np.pi, 6)
    layer = ContactLayer()
    shown_l, shown_f, hold, hands, pushed = [], [], [], [], []
    for t in range(steps):
        a, b = lead[t].copy(), follow[t].copy()
        if t == steps - 5:
            layer.clear()     # as after a reset: locks and hold start over
        layer.apply(a, b, lead_c[t], follow_c[t], float(lead_h[t]), float(follow_h[t]))
        shown_l.append(a); shown_f.append(b)
        hold.append(layer.hold); hands.append(layer.hands); pushed.append(layer.pushed)
    return {"steps": steps, "clearAt": steps - 5,
            "leader": exact(lead), "follower": exact(follow),
            "leaderContacts": exact(lead_c), "followerContacts": exact(follow_c),
            "leaderHeading": exact(lead_h), "followerHeading": exact(follow_h),
            "shownLeader": out7(shown_l), "shownFollower": out7(shown_f), "hold": out7(hold),
            "hands": [int(v) for v in np.ravel(hands)], "pushed": out7(pushed)}


# ---------------------------------------------------------------- the models' runtime

RUNTIME_BATCH = 2      # samples per model: every output channel and code of two steps


def runtime_fixture(rng) -> dict:
    """Per shipped model: a batch of inputs near the model's own input statistics (features of
    no recording: its normalization mean plus 0.7 of a standard deviation of seeded noise, so
    every layer works in its usual range), Gumbel noise and a temperature, and the outputs that
    onnxruntime computes from them, with the manifest's fingerprint of the files they came from."""
    import onnx
    from onnx import numpy_helper

    manifest = json.loads((PAGE_MODELS / "manifest.json").read_text())
    out = {"temperature": 1.0, "models": {}}
    for name, entry in sorted(manifest["models"].items()):
        path = PAGE_MODELS / entry["file"]
        inits = {i.name: numpy_helper.to_array(i) for i in onnx.load(str(path)).graph.initializer}
        mean, std = inits["input_mean"].astype(np.float64), inits["input_std"].astype(np.float64)
        x = np.round(mean + 0.7 * std * rng.standard_normal((RUNTIME_BATCH, mean.size)), 5).astype(np.float32)
        width = entry["channels"] * entry["classes"]
        noise = np.round(rng.uniform(0.001, 0.999, (RUNTIME_BATCH, width)), 6).astype(np.float32)
        session = open_session(path)
        names = [o.name for o in session.get_outputs()]
        results = session.run(None, {"input": x, "temperature": np.array([out["temperature"]], np.float32), "noise": noise})
        out["models"][name] = {
            "fingerprint": entry["fingerprint"], "batch": RUNTIME_BATCH,
            "input": exact(x), "noise": exact(noise),
            "outputs": {n: ([int(v) for v in np.ravel(r)] if n == "code" else out7(r)) for n, r in zip(names, results)},
        }
    return out


FIXTURES = ("bvh", "features", "rollout", "contact", "runtime")


def build(names=FIXTURES) -> dict[str, dict]:
    """The fixtures named (bvh, features and rollout draw from one generator in turn: all three are
    always made, and only the named returned)."""
    rng = np.random.default_rng(SEED)
    bvh = bvh_fixture(rng)
    leader, follower = procedural_pair(rng)
    lead, follow = rounded_track(leader), rounded_track(follower)
    made = {
        "bvh": bvh,
        "features": features_fixture(rng, lead, follow),
        "rollout": rollout_fixture(rng, lead, follow, leader.offsets, follower.offsets),
    }
    if "contact" in names:
        made["contact"] = contact_fixture(np.random.default_rng(SEED + 1), leader, follower)
    if "runtime" in names:
        made["runtime"] = runtime_fixture(np.random.default_rng(SEED + 2))
    return {name: made[name] for name in names}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(OUT_DIR))
    ap.add_argument("--only", nargs="+", choices=FIXTURES, default=list(FIXTURES),
                    help="write these fixtures alone (runtime needs the shipped models, and a VNNI CPU "
                         "for outputs the other CPUs reproduce: docs/testing.md)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, data in build(args.only).items():
        path = out / f"{name}.json"
        path.write_text(json.dumps(data, separators=(",", ":"), allow_nan=False) + "\n")
        print(f"{path}: {path.stat().st_size / 1024:.0f} KiB")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
