"""python -m training.evaluation.turn_cues: how well can what a follower reads time her turns?

The turn issue asks a follower, beside the played-back recorded leader, to match 60 % of the
recorded follower's turns within 0.75 s (recall) with 60 % of hers matching one (precision). A
generative follower has to decide to start a turn from what she reads; this command measures how
far that decision can be made at all, with a model built only for it: a detector that reads the
follower's input at frame t and says "a turn of this direction completes at t + LEAD". Its
turns are scored with the very rule evaluate uses (figures.match), by take-out cross-validation
(the 6 folds of crossval: each pair of takes tested once, never trained on).

What the detector reads (feature sets, columns of the follower's input, docs/features.md):
- leader:            the leader's past path, his future path (the steered plan), his past key
                     joints and his pose: all a follower reads of him;
- leader+intention:  plus the leader's recorded key joints over the next second: a perfect
                     intention predictor (the paper's intention, given exactly);
- leader+own:        plus her own recorded past (a turn already started shows there);
- leader_body:       his own past, pose and planned path in his own root space: what his body
                     does, without where she is (her input holds him in her root space, which
                     turns with her, so "leader" also sees a turn she has already begun);
- hand:              one number, the leader's higher hand's height (the lead a dancer names).

Each fold fits a logistic regression (or, with --classifier mlp, a network of two hidden layers;
3 classes: left, none, right; standardized features) on
the training takes (4 phase offsets, mirrored too). A detection is a local maximum of a
direction's probability over +-MATCH_SECONDS above a threshold; the threshold is set on the
training takes so that the detector finds as many turns as were recorded there. "chance" is the
same detections shifted in time by a random offset (the mean of 200 shifts): what a follower
that turns as often but at moments unrelated to the leader scores.

    python -m training.evaluation.turn_cues --leads 0,0.5,1 --out runs/turn_cues
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from sklearn.linear_model import LogisticRegression
from sklearn.neural_network import MLPClassifier
from tqdm import tqdm

from ..data.dataset import DataError, discover_takes, load_pair, pair_tracks, phases
from ..data.folders import add_folder
from ..mirror import features as feat
from ..mirror.skeleton import FPS, HANDS
from . import figures as F

TOLERANCE = 3          # frames: a sample's label is a turn completing within this of t + LEAD
FEATURE_SETS = ("hand", "leader", "leader_body", "leader+intention", "leader+own")
LEADER_END = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)["partner_pose"].stop   # her input's leader blocks end here


def take_samples(lead, follow) -> dict:
    """One couple (one phase, maybe mirrored) -> its frames' inputs and the follower's turns."""
    frames = feat.valid_frames(lead.frames)
    x = feat.follower_input(lead, follow, frames)
    # The leader's higher hand's height (world y), the one cue a dancer would name.
    hand = lead.positions[frames][:, HANDS, 1].max(-1, keepdims=True)
    # His own body and path in his own root space (his past, pose and planned path): what he does,
    # without where she stands or faces. Her input holds him in her root space, which turns with
    # her: read there, a turn she has already begun shows in every block of his.
    body = leader_body(follow, lead, frames)
    return {"frames": frames, "input": x, "intention": feat.intention_target(lead, follow, frames),
            "hand": hand, "body": body, "turns": F.turns(F.facing(follow.positions))}


_LEADER = feat.block_slices(feat.LEADER_INPUT_LAYOUT)
LEADER_BODY = slice(_LEADER["self_trajectory_past"].start, _LEADER["control"].stop)
LEADER_BODY_SIZE = LEADER_BODY.stop - LEADER_BODY.start   # 342


def leader_body(follow, lead, frames: np.ndarray) -> np.ndarray:
    """[N, 342] the leader's own past path, key joints, pose and planned path, in his root space
    (the leader's input from his own past block to his control). The music is not among them: any
    block stands in for it where the tracks carry no count (a rollout's)."""
    music = None if (lead.beat is not None or follow.beat is not None) else np.zeros(feat.MUSIC_SIZE)
    return feat.leader_input(follow, lead, frames, music=music)[:, LEADER_BODY]


def labels(s: dict, lead: int) -> np.ndarray:
    """[N] in {0: none, 1: left (+), 2: right (-)}: a turn completing within TOLERANCE of t + lead."""
    y = np.zeros(len(s["frames"]), int)
    for f, d in s["turns"]:
        near = np.abs(s["frames"] + lead - f) <= TOLERANCE
        y[near] = 1 if d > 0 else 2
    return y


def design(s: dict, name: str) -> np.ndarray:
    """The columns a feature set reads (FEATURE_SETS, the module's docstring) of one take's samples."""
    if name == "hand":
        return s["hand"]
    if name == "leader_body":
        return s["body"]
    if name == "leader+own":
        return s["input"]
    x = s["input"][:, :LEADER_END]
    return np.concatenate([x, s["intention"]], -1) if name == "leader+intention" else x


def detections(p: np.ndarray, frames: np.ndarray, lead: int, threshold: float) -> list[tuple[int, int]]:
    """Class probabilities [N, 3] -> [(completion frame, direction)]: each direction's local
    maxima over +-MATCH_SECONDS above the threshold, completing `lead` frames later."""
    out, half = [], int(round(F.MATCH_SECONDS * FPS))
    for cls, d in ((1, 1), (2, -1)):
        q = p[:, cls]
        for i in np.flatnonzero(q >= threshold):
            lo, hi = max(0, i - half), min(len(q), i + half + 1)
            if q[i] == q[lo:hi].max():
                out.append((int(frames[i] + lead), d))
    return sorted(out)


def threshold_for(ps: list[np.ndarray], frames: list[np.ndarray], lead: int, wanted: int) -> float:
    """The threshold at which the detector finds `wanted` turns over these takes (bisection)."""
    lo, hi = 0.0, 1.0
    for _ in range(30):
        mid = (lo + hi) / 2
        n = sum(len(detections(p, f, lead, mid)) for p, f in zip(ps, frames))
        lo, hi = (mid, hi) if n > wanted else (lo, mid)
    return hi


def score(found: list, recorded: list) -> tuple[int, int, int]:
    return F.match(found, recorded), len(found), len(recorded)


def chance(found: list, recorded: list, n: int, rng: np.random.Generator, shifts: int = 200) -> float:
    """Mean matched count of the same detections shifted in time (circularly over the take of n frames)."""
    if not found:
        return 0.0
    m = []
    for _ in range(shifts):
        k = int(rng.integers(3 * FPS, n - 3 * FPS))
        m.append(F.match([((f + k) % n, d) for f, d in found], recorded))
    return float(np.mean(m))


def load(data: str) -> dict[str, list[dict]]:
    """{take: [samples of each phase/mirror copy; the first is phase 0, not mirrored]}."""
    out = {}
    takes = discover_takes(data)
    for take in tqdm(takes, desc="takes", leave=False):
        lead_m, follow_m = load_pair(take)
        copies = []
        for mirror in (False, True):
            for phase in range(phases(lead_m)):
                copies.append(take_samples(*pair_tracks(lead_m, follow_m, phase, mirror)))
        out[take.name] = copies
    return out


def classifier(args):
    """A linear detector, or a small network (two hidden layers) to see what a non-linear one adds."""
    if args.classifier == "mlp":
        return MLPClassifier((128, 64), alpha=args.alpha, early_stopping=True, max_iter=60, random_state=0)
    return LogisticRegression(C=args.c, max_iter=300)


def folds(names: list[str], k: int) -> list[list[str]]:
    return [list(a) for a in np.array_split(np.array(names), k)]


@dataclass
class Detector:
    """A fitted detector: the follower's input (and the leader's recorded next second, for
    leader+intention) at frames t -> [N, 3] probabilities of no turn / a left / a right turn
    completing `lead` frames later; `threshold` finds as many turns as its training takes had."""
    features: str
    lead: int
    model: object
    mean: np.ndarray
    std: np.ndarray
    threshold: float = 0.5

    def probabilities(self, s: dict) -> np.ndarray:
        return self.model.predict_proba((design(s, self.features) - self.mean) / self.std)

    def turns(self, s: dict) -> list[tuple[int, int]]:
        return detections(self.probabilities(s), s["frames"], self.lead, self.threshold)


def fit_detector(data: dict[str, list[dict]], takes: list[str], features: str, lead: int, args) -> Detector:
    """Fit on every copy of `takes`; the threshold on their as-recorded copies (phase 0)."""
    xs = np.concatenate([design(s, features) for t in takes for s in data[t]])
    ys = np.concatenate([labels(s, lead) for t in takes for s in data[t]])
    mu, sd = xs.mean(0), xs.std(0) + 1e-6
    det = Detector(features, lead, classifier(args).fit((xs - mu) / sd, ys), mu, sd)
    base = [data[t][0] for t in takes]
    det.threshold = threshold_for([det.probabilities(s) for s in base], [s["frames"] for s in base], lead,
                                  sum(len(s["turns"]) for s in base))
    return det


def run(args) -> dict:
    t0 = time.time()
    data = load(args.data)
    names = sorted(data)
    leads = [int(round(float(s) * FPS)) for s in args.leads.split(",") if s]
    sets = [s for s in args.features.split(",") if s]
    unknown = [s for s in sets if s not in FEATURE_SETS]
    if unknown:
        raise DataError(f"unknown feature set(s) {', '.join(unknown)}; have {', '.join(FEATURE_SETS)}")
    rng = np.random.default_rng(0)
    results = []
    jobs = [(name, lead) for name in sets for lead in leads]
    for name, lead in tqdm(jobs, desc="feature sets x leads"):
        m = f_ = r = 0
        cm, per_fold = [], []
        for test in folds(names, args.folds):
            det = fit_detector(data, [t for t in names if t not in test], name, lead, args)
            fm = ff = fr = 0
            for t in test:
                s = data[t][0]
                found = det.turns(s)
                a, b, c = score(found, s["turns"])
                fm, ff, fr = fm + a, ff + b, fr + c
                cm.append(chance(found, s["turns"], int(s["frames"][-1]) + 1, rng))
            per_fold.append({"test": test, "matched": fm, "found": ff, "recorded": fr})
            m, f_, r = m + fm, f_ + ff, r + fr
        row = {"features": name, "lead_s": lead / FPS, "matched": m, "found": f_, "recorded": r,
               "recall": m / r, "precision": m / max(1, f_), "chance_matched": float(np.sum(cm)),
               "chance_recall": float(np.sum(cm)) / r, "chance_precision": float(np.sum(cm)) / max(1, f_),
               "folds": per_fold}
        results.append(row)
        tqdm.write(f"{name:17s} lead {lead / FPS:.2f} s: recall {row['recall']:.0%} precision "
                   f"{row['precision']:.0%} ({m} of {r} recorded, {f_} found; chance {row['chance_recall']:.0%} "
                   f"/ {row['chance_precision']:.0%})")
    return {"results": results, "takes": names, "folds": args.folds, "classifier": args.classifier,
            "seconds": time.time() - t0}


def markdown(rep: dict) -> str:
    lines = ["| what the detector reads | turn completes after | recall | precision | chance recall / precision | turns found / recorded |",
             "|---|---|---|---|---|---|"]
    for r in rep["results"]:
        lines.append(f"| {r['features']} | {r['lead_s']:.2f} s | {r['recall']:.0%} | {r['precision']:.0%} | "
                     f"{r['chance_recall']:.0%} / {r['chance_precision']:.0%} | {r['found']} / {r['recorded']} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "the takes the detector is trained and tested on")
    ap.add_argument("--leads", default="0,0.5,1", help="seconds from the detecting frame to the turn's 300 degrees")
    ap.add_argument("--features", default=",".join(FEATURE_SETS), help=f"of {', '.join(FEATURE_SETS)}")
    ap.add_argument("--folds", type=int, default=6)
    ap.add_argument("--c", type=float, default=0.01, help="inverse L2 strength of the logistic regression")
    ap.add_argument("--classifier", choices=("logistic", "mlp"), default="logistic")
    ap.add_argument("--alpha", type=float, default=1e-2, help="L2 strength of the mlp")
    ap.add_argument("--out", default="runs/turn_cues", help="writes OUT/turn_cues.json and .md")
    args = ap.parse_args(argv)
    try:
        rep = run(args)
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "turn_cues.json").write_text(json.dumps(rep, indent=1))
    (out / "turn_cues.md").write_text(markdown(rep))
    print(markdown(rep))
    print(f"wrote {out}/turn_cues.json and .md in {rep['seconds']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
