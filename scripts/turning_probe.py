"""A probe of the choice on the count in her spins (docs/developing.md, "Footwork that repeats as
the recording's"): her feet are left to the network only while she turns faster than TURNING rad/s
(training/mirror/on_count.py's TURNING["follower"], 6.0 shipped). Dances the soak's duets at 170
beats a minute from seed 0 and prints her footwork's pulse, the share of seeds whose period is the
music's (within 4 %), her steps on the beat (training.evaluation.rhythm) and her turns a minute
(training.evaluation.figures), as ratios to the recorded follower's (pulse 0.33, 23.0 turns a minute).

    PYTHONPATH=. .venv/bin/python scripts/turning_probe.py TURNING steered|nobody SEEDS SECONDS [--models DIR --follower NAME]
    PYTHONPATH=. .venv/bin/python scripts/turning_probe.py 7.5 steered 40 60     # 0.83x, turns 0.70x
"""
import argparse
import sys

import numpy as np

from training.evaluation import figures as Fg
from training.evaluation import options as O
from training.evaluation.rhythm import PERIOD_TOLERANCE, load_dancers, rhythm
from training.evaluation.soak import soak_one
from training.mirror import on_count
from training.mirror.skeleton import FPS

RECORDED_PULSE, RECORDED_TURNS, TEMPO = 0.33, 23.0, 170.0


def main(argv: list[str]) -> int:
    if len(argv) < 4 or argv[1] not in ("steered", "nobody"):
        print(__doc__.split("\n\n")[-1], file=sys.stderr)
        return 2
    turning, steer, seeds, seconds = float(argv[0]), argv[1] == "steered", int(argv[2]), int(argv[3])
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=None)
    ap.add_argument("--models", default="public/models")
    ap.add_argument("--follower", default="follower")
    O.add_options(ap)
    args = ap.parse_args(argv[4:])
    manifest, leader, follower, temperature = load_dancers(args)
    on_count.TURNING["follower"] = turning
    rows, turns = [], 0
    for seed in range(seeds):
        rec: dict = {}
        O.restart_count(follower)
        O.restart_count(leader)
        soak_one(manifest, leader, follower, seed, seconds * FPS, temperature, record=rec, steer=steer, tempo=TEMPO)
        r = rhythm(rec["leader"][FPS:], rec["follower"][FPS:], rec["beat"][FPS:], TEMPO)
        rows.append([r["follower_pulse"], r["follower_period_off"] <= PERIOD_TOLERANCE, r["follower_on_beat"]])
        turns += len(Fg.turns(Fg.facing(rec["follower"])))
    pulse, period, beat = np.mean(rows, 0)
    per_minute = turns / (seeds * seconds / 60)
    print(f"TURNING {turning:g} rad/s, {'steered' if steer else 'nobody steering'}, {seeds} seeds x {seconds} s: "
          f"her pulse {pulse:.3f} ({pulse / RECORDED_PULSE:.2f}x), period within 4 % in {period * 100:.0f} % of seeds, "
          f"on the beat {beat:+.2f}, her turns {per_minute:.1f} a minute ({per_minute / RECORDED_TURNS:.2f}x)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
