"""From the moments before a soak fall, dance on many times under each guard setting and count falls.

    PYTHONPATH=. .venv/bin/python scripts/fall_continuations.py 33 --fall 147.0 --back 0.4,0.25,0.1 \
        --variants "base,guard=128,guard_hip_margin=0.2,leader.hipMargin=0.2"

A soak rollout (training.evaluation.soak: the same steering script and random stream for SEED) is
danced to each moment --back seconds before --fall (without --fall, the rollout is first danced
in full and the fall is the first second the soak would fail: her body mostly low, folded or
split), the duet is saved there, and it is danced on --n times for --seconds with fresh random
streams (1000, 1001, ...: the same ones for every variant) and the soak's own steering. A
continuation falls when one of its seconds would fail the soak. One soak fall is a rare event (1
in 100 rollouts of 10 minutes), so this is how guard settings are compared at the moment that
matters, in minutes instead of a 40-minute soak each.

A variant is `base` (the manifest as it is) or options joined by `+`: an evaluation option by its
attribute name (guard, guard_margin, guard_hip_margin, leader_guard, on_count, on_count_strength,
on_count_hips:
training/evaluation/options.py) or a leader guard
field of the manifest as `leader.FIELD` (margin, headMargin, hipMargin), or `follower=FILE.onnx` /
`leader=FILE.onnx`: another network dances on from the same moments (the duet up to them is the
--models pair's), which compares trained networks (another --seed) where the fall was made. --rollout VARIANT dances the
rollout up to the moments with that setting (a soak run with options: its fall is found there).
"""
from __future__ import annotations

import argparse
import copy
import json
import sys
from pathlib import Path

import numpy as np

from training.evaluation import options as O
from training.evaluation import plausibility as P
from training.evaluation.duet import steering_script
from training.mirror.rollout import NOW, OnnxPolicy, start_duet, step
from training.mirror.skeleton import FPS

OPTIONS = ("temperature", "follower_temperature", "guard", "guard_margin", "guard_hip_margin",
           "leader_guard",
           "on_count", "on_count_strength", "on_count_hips")
WHOLE = ("guard", "leader_guard", "on_count")   # options that count samples


def policies(manifest: dict, leader, follower, variant: str):
    """(leader policy, follower policy, the leader's temperature) as the page runs them, with the
    variant's changes."""
    m = copy.deepcopy(manifest)
    args = argparse.Namespace(**{k: None for k in OPTIONS})
    for change in variant.split("+"):
        if change == "base":
            continue
        key, _, value = change.partition("=")
        if key in ("leader", "follower"):
            if not Path(value).is_file():
                raise SystemExit(f"error: variant {variant!r}: {value} not found")
            if key == "leader":
                leader = OnnxPolicy(Path(value))
            else:
                follower = OnnxPolicy(Path(value))
        elif key.startswith("leader."):
            m.setdefault("leaderGuard", {})[key[len("leader."):]] = float(value)
        elif key in OPTIONS:
            setattr(args, key, int(value) if key in WHOLE else float(value))
        else:
            raise SystemExit(f"error: variant {variant!r}: unknown setting {key!r} (one of {', '.join(OPTIONS)}, leader.FIELD, leader, follower)")
    error = O.resolve(args, m)
    if error:
        raise SystemExit(f"error: variant {variant!r}: {error}")
    return O.leader_policy(leader, m, args), O.follower_policy(follower, m, args, args.temperature), args.temperature


def fell(positions: np.ndarray, ranges: dict) -> bool:
    """The soak's rule for her fall: a second mostly low, folded or split."""
    return P.worst_second(P.frame_flags(positions, ranges)) > P.BAD_SECOND


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("seed", type=int, help="the soak rollout (soak --seed S runs rollouts S, S+1, ...)")
    ap.add_argument("--models", default="public/models")
    ap.add_argument("--minutes", type=float, default=10.0, help="the soak's rollout length (its steering script)")
    ap.add_argument("--fall", type=float, default=None, help="seconds: the fall (default: found by dancing the rollout)")
    ap.add_argument("--back", default="1.5,0.8", help="seconds before the fall to continue from, comma-separated")
    ap.add_argument("--n", type=int, default=20, help="continuations from each moment (0: only find the fall)")
    ap.add_argument("--seconds", type=float, default=4.0, help="length of each continuation")
    ap.add_argument("--variants", default="base")
    ap.add_argument("--rollout", default="base", metavar="VARIANT",
                    help="the setting the rollout is danced with up to the moments (default: the manifest's)")
    ap.add_argument("--out", default=None, help="write {variant: {falls, continuations}} (and the fall) as JSON here")
    a = ap.parse_args(argv)
    if a.n < 0:
        ap.error(f"--n {a.n}: a count of continuations (0: only find the fall)")
    path = Path(a.models) / "manifest.json"
    if not path.exists():
        print(f"error: {path} not found", file=sys.stderr)
        return 2
    manifest = json.loads(path.read_text())
    ranges = manifest["plausibility"]
    leader = OnnxPolicy(Path(a.models) / manifest["models"]["leader"]["file"])
    follower = OnnxPolicy(Path(a.models) / manifest["models"]["follower"]["file"])
    frames = int(a.minutes * 60 * FPS)
    backs = [float(b) for b in a.back.split(",")]
    variants = a.variants.split(",")
    for v in variants + [a.rollout]:   # refuse a bad variant before minutes of dancing
        policies(manifest, leader, follower, v)

    def rollout():
        rng = np.random.default_rng(a.seed)   # the soak's: its steering script first, then the steps
        return rng, steering_script(rng, frames), start_duet(manifest)

    lp, fp, temperature = policies(manifest, leader, follower, a.rollout)
    fall = a.fall
    if fall is None:
        rng, sticks, duet = rollout()
        hers = np.zeros((frames, 17, 3))
        for f in range(frames):
            step(duet, lp, fp, sticks[f], temperature, rng)
            hers[f] = duet.follower.track.positions[NOW]
        first = P.first_bad_second(P.frame_flags(hers, ranges))
        if first is None:
            print(f"seed {a.seed}: no fall in {a.minutes:g} min")
            return 0
        fall = first / FPS
        print(f"seed {a.seed}: the first failing second starts at {fall:.2f} s")
    if a.n < 1:
        return 0
    stops = {int(round((fall - b) * FPS)): b for b in backs}
    if min(stops) < 1 or max(stops) >= frames:   # at least one step to continue
        print(f"error: --back {a.back} from {fall:g} s leaves the rollout", file=sys.stderr)
        return 2
    rng, sticks, duet = rollout()
    saved = []
    for f in range(max(stops)):
        step(duet, lp, fp, sticks[f], temperature, rng)
        if f + 1 in stops:
            saved.append((f + 1, copy.deepcopy(duet)))
    n = int(a.seconds * FPS)
    print(f"from {', '.join(f'{f / FPS:.2f} s' for f, _ in saved)}, {a.n} continuations of {a.seconds:g} s each")
    results = {}
    for v in variants:
        lp, fp, temperature = policies(manifest, leader, follower, v)
        falls, his_lowest = 0, []
        for f0, start in saved:
            for i in range(a.n):
                duet, r = copy.deepcopy(start), np.random.default_rng(1000 + i)
                hers, his = np.zeros((n, 17, 3)), np.zeros(n)
                for k in range(min(n, frames - f0)):
                    step(duet, lp, fp, sticks[f0 + k], temperature, r)
                    hers[k], his[k] = duet.follower.track.positions[NOW], duet.leader.track.positions[NOW][0, 1]
                falls += fell(hers[:k + 1], ranges)
                his_lowest.append(his[:k + 1].min())
        print(f"{v}: she fell in {falls} of {a.n * len(saved)}; her guard chose in {getattr(fp, 'guarded', 0)} steps; "
              f"his lowest hips per continuation: median {np.median(his_lowest):.3f} m, lowest {np.min(his_lowest):.3f} m")
        results[v] = {"falls": int(falls), "continuations": a.n * len(saved)}
    if a.out:
        Path(a.out).write_text(json.dumps({"seed": a.seed, "fall": fall, "variants": results}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
