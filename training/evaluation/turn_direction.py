"""python -m training.evaluation.turn_direction: the ceiling on reading which way she will turn.

A follower who turns when the leader leads still has to turn the way he leads. How well can that
way be told from what she reads of him at all? For every recorded turn of the follower (figures.turns:
300 degrees within 1.5 s, the frame it completes and its sign), a small classifier reads the
leader at LEAD seconds before the turn completes and says left or right. Cross-validated by take
(the folds of turn_cues: each take tested once, never trained on); trained on every phase copy,
as recorded and mirrored (a mirrored take turns the other way, so the two ways are balanced);
tested on the as-recorded copies. The accuracy over all test turns is the ceiling that a follower
network's turns can reach in matching a recorded turn's direction beside the played-back leader
(evaluate's "matched" against "matched either way"); the worst fold is printed beside it.

What the classifier reads (turn_cues.FEATURE_SETS): leader (all a follower reads of him, in her
root space), leader_body (his own body and path in his root space), leader+intention (plus his
recorded next second: a perfect intention predictor), hand (his higher hand's height: says that a
turn comes, never which way; a check that the classifier cannot guess from the take), and the
parts of "leader": his_hands, his_path, his_rest (PARTS below).

    python -m training.evaluation.turn_direction --leads 0.5,1 --out runs/turn_direction
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from sklearn.linear_model import LogisticRegression

from ..data.dataset import DataError
from ..data.folders import add_folder
from ..mirror.skeleton import FPS
from ..mirror import features as feat
from ..mirror.skeleton import HANDS
from .turn_cues import FEATURE_SETS as CUE_SETS, design as cue_design, folds, load

# Parts of "leader" (her input's blocks of him, in her root space), to see which carries the way:
# his hands (their keys over the past second, and their place, velocity and turn now), his path
# (past and planned), and the rest of him (head and feet keys, the other joints of his pose).
_B = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)
_KEYS_PAST = np.arange(_B["partner_key_joints_past"].start, _B["partner_key_joints_past"].stop).reshape(feat.KEYS, -1, 3)
_POSE = np.arange(_B["partner_pose"].start, _B["partner_pose"].stop).reshape(feat.N_JOINTS, 12)
_HAND_KEYS = [1, 2]   # KEY_JOINTS = head, hands, feet
HIS_HANDS = np.concatenate([_KEYS_PAST[:, _HAND_KEYS].ravel(), _POSE[HANDS].ravel()])
HIS_PATH = np.concatenate([np.arange(_B[k].start, _B[k].stop) for k in ("partner_trajectory_past", "partner_trajectory_future")])
HIS_REST = np.setdiff1d(np.arange(_B["partner_trajectory_past"].start, _B["partner_pose"].stop),
                        np.concatenate([HIS_HANDS, HIS_PATH]))
PARTS = {"his_hands": HIS_HANDS, "his_path": HIS_PATH, "his_rest": HIS_REST}
FEATURE_SETS = (*CUE_SETS, *PARTS)


def design(s: dict, name: str) -> np.ndarray:
    """The columns a feature set reads: turn_cues' sets, or a part of her input's blocks of him."""
    return s["input"][:, PARTS[name]] if name in PARTS else cue_design(s, name)


def turn_samples(s: dict, features: str, lead: int) -> tuple[np.ndarray, np.ndarray]:
    """One copy's recorded turns -> the features `lead` frames before each completes [K, D] and
    its direction [K] (+1 left, -1 right). Turns too early in the take to be read are left out."""
    index = {int(f): i for i, f in enumerate(s["frames"])}
    rows, ys = [], []
    x = design(s, features)
    for frame, direction in s["turns"]:
        i = index.get(int(frame) - lead)
        if i is not None:
            rows.append(x[i])
            ys.append(direction)
    return (np.array(rows).reshape(len(rows), x.shape[1]), np.array(ys, int))


def cross_validate(data: dict[str, list[dict]], features: str, lead: int, n_folds: int, c: float) -> dict:
    """Accuracy of telling each test turn's direction, per fold and pooled, and the share of the
    commoner direction in the test turns (what always guessing it would score)."""
    names = sorted(data)
    right = total = 0
    per_fold = []
    for test in folds(names, n_folds):
        train = [t for t in names if t not in test]
        pairs = [turn_samples(s, features, lead) for t in train for s in data[t]]
        x = np.concatenate([p[0] for p in pairs])
        y = np.concatenate([p[1] for p in pairs])
        mu, sd = x.mean(0), x.std(0) + 1e-6
        model = LogisticRegression(C=c, max_iter=500).fit((x - mu) / sd, y)
        tx, ty = zip(*(turn_samples(data[t][0], features, lead) for t in test))
        tx, ty = np.concatenate(tx), np.concatenate(ty)
        if len(ty) == 0:
            continue
        hit = int((model.predict((tx - mu) / sd) == ty).sum())
        per_fold.append({"test": test, "right": hit, "turns": int(len(ty)), "accuracy": hit / len(ty),
                         "commoner_share": float(max((ty > 0).mean(), (ty < 0).mean()))})
        right, total = right + hit, total + len(ty)
    return {"features": features, "lead_s": lead / FPS, "right": right, "turns": total,
            "accuracy": right / max(1, total), "worst_fold": min(f["accuracy"] for f in per_fold),
            "commoner_share": sum(f["commoner_share"] * f["turns"] for f in per_fold) / max(1, total),
            "folds": per_fold}


def markdown(rep: dict) -> str:
    lines = ["| what the classifier reads | before the turn completes | direction right | worst fold | always the commoner way |",
             "|---|---|---|---|---|"]
    for r in rep["results"]:
        lines.append(f"| {r['features']} | {r['lead_s']:.2f} s | {r['accuracy']:.0%} ({r['right']} of {r['turns']}) | "
                     f"{r['worst_fold']:.0%} | {r['commoner_share']:.0%} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "the takes the classifier is trained and tested on")
    ap.add_argument("--leads", default="0.5,1", help="seconds from the read frame to the turn's 300 degrees")
    ap.add_argument("--features", default="leader,leader_body,leader+intention,hand,his_hands,his_path,his_rest", help=f"of {', '.join(FEATURE_SETS)}")
    ap.add_argument("--folds", type=int, default=6)
    ap.add_argument("--c", type=float, default=0.01, help="inverse L2 strength of the logistic regression")
    ap.add_argument("--out", default="runs/turn_direction", help="writes OUT/turn_direction.json and .md")
    args = ap.parse_args(argv)
    t0 = time.time()
    try:
        sets = [s for s in args.features.split(",") if s]
        unknown = [s for s in sets if s not in FEATURE_SETS]
        if unknown:
            raise DataError(f"unknown feature set(s) {', '.join(unknown)}; have {', '.join(FEATURE_SETS)}")
        leads = [int(round(float(s) * FPS)) for s in args.leads.split(",") if s]
        data = load(args.data)
        results = []
        for name in sets:
            for lead in leads:
                row = cross_validate(data, name, lead, args.folds, args.c)
                results.append(row)
                print(f"{name:17s} {lead / FPS:.2f} s before: {row['accuracy']:.0%} of {row['turns']} turns "
                      f"(worst fold {row['worst_fold']:.0%}; the commoner way {row['commoner_share']:.0%})", flush=True)
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    rep = {"results": results, "takes": sorted(data), "folds": args.folds, "seconds": time.time() - t0}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "turn_direction.json").write_text(json.dumps(rep, indent=1))
    (out / "turn_direction.md").write_text(markdown(rep))
    print(markdown(rep))
    print(f"wrote {out}/turn_direction.json and .md in {rep['seconds']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
