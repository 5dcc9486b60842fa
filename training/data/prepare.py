"""python -m training.data.prepare: paired BVH takes -> feature arrays for training (git-ignored).

Reads the BVH couples in --data; writes PREPARED/{train,validation,test}.npz (both roles, all phase
offsets, mirrored copies in train), PREPARED/train_tracks.npz (the training couples at 30 fps, phase
0, as recorded and mirrored: what training's own rollouts dance beside), PREPARED/plausibility.json (the training dancers' range of
poses and speeds: training.evaluation.plausibility) and PREPARED/stats.npz (normalization, from
the recorded tempo: recipes with and without tempo copies normalize alike), then prints frames
per split and feature sizes. With --tempos it also writes PREPARED/train_tempo.npz, the training couples time-warped to
those tempos (0.85,0.92,1.08,1.16 when the flag comes alone): the shipped recipes read it, so the
default is those tempos (--tempos '' writes none).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..evaluation import plausibility as P
from ..mirror import features as F
from ..mirror.music import TEMPO_MEAN, TEMPO_STD
from .dataset import (TEST_TAKES, VALIDATION_TAKES, DataError, discover_takes, load_pair, pair_tracks,
                      phases, samples)
from .folders import add_folder

# Tempo copies: the couple danced slower and faster, the music with them (training/mirror/music.py):
# the recorded 163-187 beats a minute become 139-218, so the page's 150-200 is inside what the
# networks heard. Shipped recipes train on them (TrainConfig.tempo_copies).
TEMPOS = [0.85, 0.92, 1.08, 1.16]


def split_of(take: str, validation: list[str], test: list[str]) -> str:
    return "validation" if take in validation else "test" if take in test else "train"


def add_tracks(store: dict[str, np.ndarray], tracks, mirror: bool) -> None:
    """Keep one training couple (leader, follower Tracks at 30 fps) as couple i of
    train_tracks.npz: what training's own rollouts (training/learning/own_rollouts.py) dance beside."""
    i = len(store) // 11
    for role, t in zip(("leader", "follower"), tracks):
        for k in ("positions", "rotations", "root", "heading", "beat"):
            store[f"{i}_{role}_{k}"] = getattr(t, k)
    store[f"{i}_mirror"] = np.array(mirror)


def prepare(data: str, out: str, validation: list[str], test: list[str], leader: str | None = None,
            all_phases: bool = True, quiet: bool = False, tempos: list[float] | None = None) -> dict:
    takes = discover_takes(data, leader)
    names = [t.name for t in takes]
    for n in validation + test:
        if n not in names:
            raise DataError(f"split take {n} is not in {data} (have {', '.join(names)})")
    parts: dict[str, list[dict]] = {"train": [], "validation": [], "test": [], "train_tempo": []}
    dancer_frames = {"train": 0, "validation": 0, "test": 0}
    recorded_bodies: list[np.ndarray] = []   # world positions of every training dancer, as recorded
    train_tracks: dict[str, np.ndarray] = {}  # the training couples themselves (train_tracks.npz)
    for take in tqdm(takes, desc="prepare", unit="take", disable=quiet):
        lead, follow = load_pair(take)
        split = split_of(take.name, validation, test)
        dancer_frames[split] += len(range(0, lead.frames, phases(lead)))
        # Extra samples from the 4 phase offsets of 120 fps and mirroring help training only;
        # validation and test stay one clean pass so their numbers mean frames of real motion.
        n_phase = phases(lead) if (all_phases and split == "train") else 1
        mirrors = (False, True) if split == "train" else (False,)
        # Tempo copies (train only): the couple danced faster or slower, both partners together.
        speeds = [1.0] + (list(tempos or []) if split == "train" else [])
        for tempo in speeds:
            for phase in range(n_phase):
                for mirror in mirrors:
                    tracks = pair_tracks(lead, follow, phase, mirror, tempo)
                    s = samples(*tracks)
                    if split == "train" and tempo == 1.0 and phase == 0 and not mirror:
                        recorded_bodies += [t.positions for t in tracks]
                    if split == "train" and tempo == 1.0 and phase == 0:
                        add_tracks(train_tracks, tracks, mirror)
                    n = len(s["frame"])
                    s["take"] = np.full(n, names.index(take.name), np.int16)
                    s["phase"] = np.full(n, phase, np.int8)
                    s["mirror"] = np.full(n, mirror, np.bool_)
                    s["tempo"] = np.full(n, tempo, np.float32)
                    parts[split if tempo == 1.0 else "train_tempo"].append(s)
    outdir = Path(out)
    outdir.mkdir(parents=True, exist_ok=True)
    summary = {"takes": {k: sorted({names[p["take"][0]] for p in v}) for k, v in parts.items()},
               "dancer_frames_30fps": dancer_frames, "samples": {}}
    arrays = {}
    (outdir / "train_tempo.npz").unlink(missing_ok=True)    # never a stale file of another call
    for split, plist in parts.items():
        if split == "train_tempo" and not plist:
            continue
        if not plist:
            raise DataError(f"split {split} is empty; choose other --validation/--test takes")
        arrays[split] = {k: np.concatenate([p[k] for p in plist]) for k in plist[0]}
        np.savez(outdir / f"{split}.npz", takes=np.array(names), **arrays[split])
        summary["samples"][split] = len(arrays[split]["frame"])
    np.savez(outdir / "train_tracks.npz", **train_tracks)
    stats = {}
    for role in ("follower", "leader"):
        for kind in ("input", "output", "intention"):
            mean, std = F.normalization(arrays["train"][f"{role}_{kind}"])
            if kind == "input":
                # The figure block is read as it is (inside and progress, 0 to 1): a figure seldom
                # at the past second's first key would otherwise be scaled far past the others.
                fig = F.block_slices(F.LEADER_INPUT_LAYOUT if role == "leader" else F.FOLLOWER_INPUT_LAYOUT)["figure"]
                mean[fig], std[fig] = 0.0, 1.0
            if role == "leader" and kind == "input":
                # The hands plan likewise keeps `shown` raw and its moves centred on "stay": a hidden
                # plan (zeros) then reads as no move, and the moves keep their own spread.
                plan = F.block_slices(F.LEADER_INPUT_LAYOUT)["hands_plan"]
                mean[plan], std[plan.start] = 0.0, 1.0
            if kind == "input":
                # The music block is read as it is (points on circles), its tempo on a fixed scale:
                # the tempo copies and the recorded takes must read alike (training/mirror/music.py).
                music = F.block_slices(F.LEADER_INPUT_LAYOUT if role == "leader" else F.FOLLOWER_INPUT_LAYOUT)["music"]
                mean[music], std[music] = 0.0, 1.0
                mean[music.stop - 1], std[music.stop - 1] = TEMPO_MEAN, TEMPO_STD
            stats[f"{role}_{kind}_mean"], stats[f"{role}_{kind}_std"] = mean, std
    # Bone offsets of each role (the first take's, as export ships them): the training terms on
    # the decoded body (partner_losses) run forward kinematics with them. In the CMU takes each
    # subject has one skeleton: with these offsets forward kinematics reproduces every training
    # sample's joint positions within 2e-7 m.
    lead, follow = load_pair(takes[0])
    stats["leader_offsets"], stats["follower_offsets"] = lead.offsets, follow.offsets
    np.savez(outdir / "stats.npz", **stats)
    # The recording's range of poses and speeds (evaluation.plausibility): what a generated frame is
    # judged against (export copies it into the manifest).
    P.save_ranges(outdir / "plausibility.json", P.ranges(recorded_bodies))
    summary["sizes"] = {"input": F.INPUT_SIZE, "leader input": F.LEADER_INPUT_SIZE, "output": F.OUTPUT_SIZE,
                        "intention": F.INTENTION_SIZE}
    return summary


def print_summary(s: dict) -> None:
    print("split        takes                     dancer frames @30fps   samples per role")
    for split in ("train", "validation", "test"):
        print(f"{split:<12} {','.join(s['takes'][split]):<25} {s['dancer_frames_30fps'][split]:>21} "
              f"{s['samples'][split]:>18}")
    if "train_tempo" in s["samples"]:
        print(f"{'train_tempo':<12} {','.join(s['takes']['train_tempo']):<25} {'':>21} {s['samples']['train_tempo']:>18}"
              f"  (tempo copies)")
    total = sum(s["dancer_frames_30fps"].values())
    print(f"total dancer frames at 30 fps (per dancer): {total}")
    print("feature sizes:")
    for title, layout in (("follower input I", F.FOLLOWER_INPUT_LAYOUT),
                          ("leader input I", F.LEADER_INPUT_LAYOUT),
                          ("output O", F.OUTPUT_LAYOUT), ("intention", F.INTENTION_LAYOUT)):
        blocks = " | ".join(f"{n} {k}" for n, k in layout)
        print(f"  {title} ({sum(k for _, k in layout)}): {blocks}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.data.prepare", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "read")
    add_folder(ap, "prepared", "written (git-ignored)", old=("--out",))
    ap.add_argument("--validation", default=",".join(VALIDATION_TAKES), help="comma-separated takes")
    ap.add_argument("--test", default=",".join(TEST_TAKES), help="comma-separated takes")
    ap.add_argument("--leader", default=None, help="subject that leads (default: first by name)")
    ap.add_argument("--one-phase", action="store_true", help="use only phase 0 of 120 fps takes")
    ap.add_argument("--tempos", nargs="?", default=",".join(map(str, TEMPOS)), const=",".join(map(str, TEMPOS)), metavar="LIST",
                    help="write train_tempo.npz, the training couples at these tempos, for recipes "
                         f"with tempo copies (alone: {','.join(map(str, TEMPOS))}; default: none)")
    args = ap.parse_args(argv)
    try:
        tempos = [float(t) for t in args.tempos.split(",") if t]
    except ValueError:
        ap.error(f"--tempos: expected numbers such as 0.9,1.1, got {args.tempos!r}")
    if any(not 0.5 <= t <= 2.0 for t in tempos):
        ap.error(f"--tempos: each tempo must be within 0.5-2 (a salsa couple at half or double speed), got {args.tempos}")
    t0 = time.time()
    try:
        s = prepare(args.data, args.prepared, [t for t in args.validation.split(",") if t],
                    [t for t in args.test.split(",") if t], args.leader, not args.one_phase,
                    tempos=[t for t in tempos if t != 1.0])
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print_summary(s)
    files = "train,train_tempo,validation,test,stats" if "train_tempo" in s["samples"] else "train,validation,test,stats"
    print(f"wrote {args.prepared}/{{{files}}}.npz in {time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
