"""A probe of falls while he leads turns (docs/results.md, "Leading a turn"): the soak's steered
duets (soak.soak_one, the stick's script) with a turn asked every EVERY seconds, the way
alternating (T, then Shift+T), so that a request runs most of the time. Counts, as `seeds` does for
the drawn bodies (plausibility.py: a second mostly with hips low, head low or feet wide), the seeds
with a bad second and the collapses, for him and for her, and her turns a minute.

    PYTHONPATH=. .venv/bin/python scripts/led_falls_probe.py steered|nobody SEEDS SECONDS [--models DIR --follower NAME]
    PYTHONPATH=. .venv/bin/python scripts/led_falls_probe.py steered 30 60
"""
import argparse
import sys

import numpy as np

from training.evaluation import figures as Fg
from training.evaluation import options as O
from training.evaluation import plausibility as P
from training.evaluation import soak
from training.evaluation.rhythm import load_dancers
from training.mirror import rollout
from training.mirror.skeleton import FPS

EVERY = 3.0   # s between requests (a request lasts rollout.REQUEST_SECONDS, 2.5)


def main(argv: list[str]) -> int:
    if len(argv) < 3 or argv[0] not in ("steered", "nobody"):
        print(__doc__.split("\n\n")[-1], file=sys.stderr)
        return 2
    steer, seeds, seconds = argv[0] == "steered", int(argv[1]), int(argv[2])
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=None)
    ap.add_argument("--models", default="public/models")
    ap.add_argument("--follower", default="follower")
    O.add_options(ap)
    manifest, leader, follower, temperature = load_dancers(ap.parse_args(argv[3:]))
    ranges = manifest["plausibility"]

    def asking_step(duet, *args):
        if duet.frame % int(EVERY * FPS) == int(EVERY * FPS) // 2:
            rollout.ask_turn(duet, -1 if (duet.frame // int(EVERY * FPS)) % 2 == 0 else 1)
        rollout.step(duet, *args)

    soak.step = asking_step
    bad = {"leader": [], "follower": []}
    collapses, turns = 0, 0
    for seed in range(seeds):
        rec: dict = {}
        O.restart_count(follower)
        O.restart_count(leader)
        soak.soak_one(manifest, leader, follower, seed, seconds * FPS, temperature, record=rec, steer=steer)
        for who in bad:
            flags = P.frame_flags(rec[f"{who}_shown"], ranges)
            if P.first_bad_second(flags) is not None:
                bad[who].append(seed)
            collapses += P.collapsed(rec[f"{who}_shown"], ranges)
        turns += len(Fg.turns(Fg.facing(rec["follower"])))
    print(f"{'steered' if steer else 'nobody steering'}, {seeds} seeds x {seconds} s, a turn asked every {EVERY:g} s: "
          f"seeds with a bad second, him {len(bad['leader'])} {bad['leader']}, her {len(bad['follower'])} {bad['follower']}; "
          f"collapses {collapses}; her turns {turns / (seeds * seconds / 60):.1f} a minute")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
