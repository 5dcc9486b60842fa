"""python -m training.evaluation.soak: long free-running duets with random steering, checked for failure.

    python -m training.evaluation.soak                          # 100 rollouts x 10 minutes (the full run)
    python -m training.evaluation.soak --rollouts 2 --minutes 1 # what CI runs

Runs the exported ONNX models through training/mirror/rollout.py (the loop the page mirrors) with a
steering script that changes every 0.5-3 s: random directions, sharp reversals, long holds and
idle spells. Per rollout it reports non-finite numbers, the largest leader-follower distance,
bone-length error, the lowest foot, the share of frozen frames, guard resets, collapses (hips
below the recording's lowest for a second) and follower falls (a second mostly low, folded or
split), both against the range the manifest carries (evaluation.plausibility); it exits 1 when any
rollout breaks a limit. The summary gives every plausibility share with its worst rollout, and how
the duet reads as a couple (metrics.interaction), for the networks alone and with the run-time
contact layer (training/mirror/contact.py).

The dancers run as the page runs them, from the manifest: each at its own variety, the follower
with its upright guard (training/mirror/guard.py), whose chosen steps are counted and reported
(training/evaluation/options.py for the options that change this).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..data.folders import add_folder
from ..mirror.rollout import OnnxPolicy, start_duet, step
from .duet import soak_one
from . import options as O
from . import metrics as M
from . import rhythm as R
from . import plausibility as P
from ..mirror.skeleton import FPS

MAX_DISTANCE = 3.0        # m between the partners
MAX_BONE_ERROR = 0.001    # m
MIN_FOOT = -0.02          # m: the ankle joint may not sink below this
MAX_FROZEN = 0.25         # share of frames a dancer may stand frozen


TURN_HOLD_SECONDS = 4.0    # each steering trial: hold one direction, then the one 90 degrees off


def steering_trial(manifest, leader, follower, angle: float, turn: float, temperature: float,
                   seed: int) -> dict:
    """Hold the stick fully at `angle` (radians, world) for TURN_HOLD_SECONDS, then turn it by
    `turn` and hold again: metrics.steering_response of the leader's root after the turn."""
    rng = np.random.default_rng(seed)
    duet = start_duet(manifest)
    hold = int(TURN_HOLD_SECONDS * FPS)
    first = np.array([np.sin(angle), np.cos(angle)])
    second = np.array([np.sin(angle + turn), np.cos(angle + turn)])
    root = np.zeros((2 * hold, 2))
    for f in range(2 * hold):
        step(duet, leader, follower, first if f < hold else second, temperature, rng)
        root[f] = duet.leader.root
    return M.steering_response(root, hold, second)


def steering_trials(manifest, leader, follower, temperature: float, trials: int = 8) -> dict:
    """`trials` turns of 90 degrees (alternately left and right, from evenly spread headings):
    mean seconds until the leader moves within 30 degrees of the new direction (and how many
    never did within TURN_HOLD_SECONDS), and the mean speed reached."""
    res = [steering_trial(manifest, leader, follower, 2 * np.pi * i / trials, (-1) ** i * np.pi / 2,
                          temperature, seed=i) for i in range(trials)]
    reached = [r["seconds"] for r in res if r["seconds"] is not None]
    return {"trials": trials, "turn_seconds": float(np.mean(reached)) if reached else None,
            "turn_missed": trials - len(reached), "speed": float(np.mean([r["speed"] for r in res]))}


def failures(r: dict) -> list[str]:
    out = []
    if r["nonfinite"]:
        out.append("non-finite")
    if r["max_distance"] >= MAX_DISTANCE:
        out.append(f"distance {r['max_distance']:.2f} m")
    if r["bone_error"] >= MAX_BONE_ERROR:
        out.append(f"bone error {r['bone_error'] * 1000:.2f} mm")
    if r["min_foot"] <= MIN_FOOT:
        out.append(f"foot {r['min_foot'] * 100:.1f} cm")
    if max(r["frozen_leader"], r["frozen_follower"]) > MAX_FROZEN:
        out.append("frozen")
    if r["resets"]:
        out.append(f"{r['resets']} resets")
    for who in r.get("collapsed", []):
        out.append(f"{who} collapsed")
    # A fall can keep the hips a little above the recording's lowest (a follower crumpled into a
    # squat, then sprawled: docs/plausibility.md), so a second mostly low, folded or split fails
    # too; for the follower only, as the recorded leader dips that low in a figure.
    if r.get("fell"):
        out.append("follower fell")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.soak", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "models", "the leader and follower that dance")
    add_folder(ap, "data", "read for the recorded couples' rhythm, which the duets' is compared with (skipped when absent)")
    ap.add_argument("--follower", default="follower", help="follower model name in the manifest")
    ap.add_argument("--rollouts", type=int, default=100)
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None,
                    help="write the table as JSON to this file (a folder: soak.json in it)")
    O.add_options(ap)
    args = ap.parse_args(argv)
    manifest_path = Path(args.models) / "manifest.json"
    if not manifest_path.exists():
        print(f"error: {manifest_path} not found (python -m training.learning.export writes it)", file=sys.stderr)
        return 2
    manifest = json.loads(manifest_path.read_text())
    # Where the table goes is settled before the hour of dancing, not after it.
    out = None if args.out is None else Path(args.out)
    if out is not None and out.is_dir():
        out = out / "soak.json"
    if out is not None and not out.parent.is_dir():
        print(f"error: --out {args.out}: no folder {out.parent} to write it in", file=sys.stderr)
        return 2
    if args.follower not in manifest["models"]:
        print(f"error: no model {args.follower!r} in {manifest_path}", file=sys.stderr)
        return 2
    leader = OnnxPolicy(Path(args.models) / manifest["models"]["leader"]["file"])
    follower = OnnxPolicy(Path(args.models) / manifest["models"][args.follower]["file"])
    frames = int(args.minutes * 60 * FPS)
    error = O.resolve(args, manifest)
    if error:
        print(f"error: {manifest_path}: {error}", file=sys.stderr)
        return 2
    temperature = args.temperature
    ranges = manifest.get("plausibility")
    follower = O.follower_policy(follower, manifest, args, temperature)
    leader = O.leader_policy(leader, manifest, args)
    t0 = time.time()
    results = []
    print(f"{args.rollouts} rollouts x {frames} frames ({args.minutes:g} min at {FPS} Hz), "
          f"follower {args.follower}, variety: leader {temperature:g}, follower {args.follower_temperature:g}, " +
          (f"upright guard of {args.guard} samples, margin {args.guard_margin:g} m" +
           (f" (her hips {args.guard_hip_margin:g} m)" if args.guard_hip_margin is not None else "")
           if args.guard else "no upright guard"))
    print(" seed  nonfinite  max dist m  bone err mm  min foot cm  frozen L  frozen F  resets  result")
    for i in tqdm(range(args.rollouts), desc="soak", unit="rollout", leave=False):
        rec = {}
        # Each rollout its own duet: both choosers forget the footwork of the rollout before, so
        # rollout SEED dances as `--seed SEED --rollouts 1` does (scripts/fall_continuations.py
        # dances a soak's rollout again from its seed alone).
        O.restart_count(follower, leader)
        r = soak_one(manifest, leader, follower, args.seed + i, frames, temperature, rec, tempo=args.tempo)
        r["guarded"] = getattr(follower, "guarded", 0)
        r["interaction"] = M.interaction(rec["leader"], rec["follower"], rec["leader_contacts"], rec["follower_contacts"])
        r["interaction_layer"] = M.interaction(rec["leader_shown"], rec["follower_shown"], rec["leader_contacts"],
                                               rec["follower_contacts"])
        if ranges:   # the recording's range (a manifest from before it has none: skipped)
            r["plausibility"] = P.duet(rec["leader"], rec["follower"], ranges)
            r["collapsed"] = [who for who in ("leader", "follower") if r["plausibility"][who]["collapse"]]
            r["fell"] = r["plausibility"]["follower"]["worst_second"] > P.BAD_SECOND
        r["failures"] = failures(r)
        # on the count, as drawn and the networks' own (evaluation.rhythm)
        r["rhythm"] = R.bodies_rhythm(rec, args.tempo, r["seed"])
        results.append(r)
        tqdm.write(f"{r['seed']:>5} {r['nonfinite']:>10} {r['max_distance']:>11.2f} "
                   f"{r['bone_error'] * 1000:>12.4f} {r['min_foot'] * 100:>12.1f} {r['frozen_leader']:>9.3f} "
                   f"{r['frozen_follower']:>9.3f} {r['resets']:>7}  {'; '.join(r['failures']) or 'ok'}")
    bad = [r for r in results if r["failures"]]
    summary = {"rollouts": len(results), "frames": frames, "failed": len(bad),
               "nonfinite": sum(r["nonfinite"] for r in results),
               "max_distance": max(r["max_distance"] for r in results),
               "bone_error_mm": max(r["bone_error"] for r in results) * 1000,
               "min_foot_cm": min(r["min_foot"] for r in results) * 100,
               "frozen_max": max(max(r["frozen_leader"], r["frozen_follower"]) for r in results),
               "resets": sum(r["resets"] for r in results), "seconds": time.time() - t0,
               "guarded": sum(r["guarded"] for r in results)}
    for key in ("interaction", "interaction_layer"):
        summary[key] = {k: float(np.mean([r[key][k] for r in results])) for k in results[0][key]}
    if ranges:
        summary["plausibility"] = P.summarize([r["plausibility"] for r in results], [frames] * len(results))
        for who in ("leader", "follower"):
            q = summary["plausibility"][who]
            print(f"plausibility, {who}: " + ", ".join(f"{k} {q[k]:.1%} (worst rollout {q[k + '_worst_seed']:.1%})"
                                                       for k in P.FLAGS) +
                  f"; {q['collapses']} collapses; longest frozen {q['longest_frozen_s']:.1f} s")
    print(f"summary: {len(bad)} of {len(results)} rollouts failed; max distance {summary['max_distance']:.2f} m; "
          f"bone error {summary['bone_error_mm']:.4f} mm; lowest foot {summary['min_foot_cm']:.1f} cm; "
          f"most frozen {summary['frozen_max']:.3f}; resets {summary['resets']}; {summary['seconds']:.0f} s")
    if args.guard:
        print(f"upright guard: chose another sample in {summary['guarded']} steps "
              f"({summary['guarded'] / (frames * len(results)):.2%} of frames)")
    for key, title in (("interaction", "networks alone"), ("interaction_layer", "with the contact layer")):
        m = summary[key]
        print(f"interaction, {title}: torsos through each other {m['interpenetration']:.1%} of frames, "
              f"hands within 20 cm {m['hand_hold']:.1%}, closest hands {m['closest_hand_m']:.2f} m, "
              f"foot skate leader / follower {m['contact_skate_leader_cm']:.2f} / "
              f"{m['contact_skate_follower_cm']:.2f} cm per contact frame "
              f"({m['skate_leader_cm']:.2f} / {m['skate_follower_cm']:.2f} while low)")
    if Path(args.data).is_dir():
        try:
            reference = R.recorded(args.data)
        except Exception as e:   # a data folder that is not the couples: the rhythm stays unrated
            print(f"rhythm: not compared with the recording ({e})")
        else:
            summary["rhythm"] = {body: R.summarize([r["rhythm"][body] for r in results], reference) for body in R.BODIES}
            for body, what in R.BODIES.items():
                print(R.format_summary(f"rhythm at {args.tempo:g} beats a minute, steered, {what}",
                                       summary["rhythm"][body], reference))
    if out is not None:
        out.write_text(json.dumps({"summary": summary, "rollouts": results}, indent=1))
        print(f"wrote {out}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
