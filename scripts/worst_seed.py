"""Side-view stick frames every 0.5 s of one steered seed (the loop and steering script of
training.evaluation.seeds, with the contact layer): the 6 s with most follower frames flagged, so
that the worst seed of a seeds table can be looked at, not only counted.

    PYTHONPATH=. .venv/bin/python scripts/worst_seed.py SEED OUT.png [--models DIR] [--flag angles_out|body]
        [--seconds 60] [--dancer follower|leader] [--temperature T --follower-temperature T --guard K --guard-margin M]
        [--nobody-steering --seconds 30 [--ask S:DIR]] [--at S]

--nobody-steering films the seed of training.evaluation.lead's tables instead (nobody steering,
no request; the least-turning seed), --ask S:DIR asks that duet for a turn at S seconds (the seed
whose requests worked least), --at films the 6 s from S.

The variety and guard options are training.evaluation.options' (default: the manifest's, as the
page dances); with --seconds 600 a seed is the soak's rollout of that seed.

--flag angles_out (default): joint angles out of the recorded range; body: hips low, head low or
feet wide (plausibility.BODY_FLAGS, what a bad second counts); guarded: the steps in which the
upright guard took another sample (what it caught, to look at). --dancer leader: his flags, not hers
(guarded: still the follower's guard).
"""
import argparse

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from training.evaluation import options as O
from training.evaluation import plausibility as P
from training.evaluation.evaluate_inputs import find_models, load_onnx
from training.evaluation.lead import unasked_duet
from training.evaluation.duet import soak_one
from training.mirror.skeleton import FPS, PARENTS

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("seed", type=int)
ap.add_argument("out")
ap.add_argument("--models", default="public/models")
ap.add_argument("--flag", choices=["angles_out", "body", "guarded"], default="angles_out")
ap.add_argument("--seconds", type=float, default=60.0)
ap.add_argument("--dancer", choices=["follower", "leader"], default="follower", help="whose flags choose the 6 s")
ap.add_argument("--nobody-steering", action="store_true",
                help="the seed as training.evaluation.lead dances it unasked (nobody steering), not the steered one")
ap.add_argument("--at", type=float, default=None, metavar="S",
                help="film the 6 s from S seconds instead of the 6 s with most flagged frames")
ap.add_argument("--ask", default=None, metavar="S:DIR",
                help="with --nobody-steering: ask the leader for a turn at S seconds, DIR 1 (her left) or -1")
O.add_options(ap)
args = ap.parse_args()

manifest, onnx, leader = find_models(args.models)
rec = {}
error = O.resolve(args, manifest)
if error:
    ap.error(error)
follower = O.follower_policy(load_onnx(onnx["ours"]), manifest, args, args.temperature)
chosen = []   # the frames in which the guard took another sample


def noted(x, temperature, rng):
    before = getattr(follower, "guarded", 0)
    out = follower(x, temperature, rng)
    if getattr(follower, "guarded", 0) > before:
        chosen.append(noted.frame)
    noted.frame += 1
    return out


noted.frame = 0
ask = None
if args.ask:
    at, direction = args.ask.split(":")
    ask = (float(at), int(direction))
    if not args.nobody_steering or ask[1] not in (-1, 1):
        ap.error("--ask S:DIR needs --nobody-steering and DIR 1 or -1")
if args.nobody_steering:
    rec = unasked_duet(manifest, O.leader_policy(load_onnx(leader), manifest, args), noted, args.temperature,
                       args.seed, args.seconds, ask, tempo=args.tempo)
else:
    soak_one(manifest, O.leader_policy(load_onnx(leader), manifest, args), noted, args.seed, int(args.seconds * FPS),
             args.temperature, rec, tempo=args.tempo)
L, F = rec["leader_shown"], rec["follower_shown"]
flags = P.frame_flags(F if args.dancer == "follower" else L, manifest["plausibility"])
flags["guarded"] = np.isin(np.arange(len(F)), chosen)
bad = (P.body_flagged(flags) if args.flag == "body" else flags[args.flag]).astype(float)
label = {"body": "body low, folded or split", "guarded": "guard chose"}.get(args.flag, "angle out")
if args.at is None:
    start = int(np.argmax(np.convolve(bad, np.ones(6 * FPS), "valid")))   # the 6 s with most flagged frames
else:
    start = min(int(args.at * FPS), len(F) - 6 * FPS)
fig, axes = plt.subplots(2, 6, figsize=(18, 6.5))
for k, ax in enumerate(axes.flat):
    t = start + k * FPS // 2
    c = (L[t, 0] + F[t, 0]) / 2
    for pos, col in ((L[t], "tab:blue"), (F[t], "tab:red")):
        for j, p in enumerate(PARENTS):
            if p >= 0:
                ax.plot([pos[j, 0] - c[0], pos[p, 0] - c[0]], [pos[j, 1], pos[p, 1]], color=col, lw=2)
    ax.set_xlim(-1.2, 1.2); ax.set_ylim(0, 1.9); ax.set_aspect("equal"); ax.set_xticks([]); ax.set_yticks([])
    # Flagged within the half second this frame stands for (a guard's choice is a single step).
    ax.set_title(f"t={t / FPS:.1f} s{'  ' + label if bad[t:t + FPS // 2].any() else ''}", fontsize=9)
mode = "nobody steering" if args.nobody_steering else "steered"
guard = f" (guard K={args.guard}, {args.guard_margin:g} m)" if args.guard else ""
which = f"the 6 s from {args.at:g} s" if args.at is not None else f"the 6 s with most {args.dancer} frames flagged"
fig.suptitle(f"{args.models}, {mode} seed {args.seed}{guard}: {which} ({label}: {bad.mean():.1%} of the "
             f"{args.dancer}'s frames), side view (x, height), a frame every 0.5 s")
fig.tight_layout()
fig.savefig(args.out, dpi=80)
print(f"worst 6 s from {start / FPS:.1f} s; {label}: {bad.mean():.1%} of the {args.seconds:g} s"
      + (f"; the guard chose {follower.guarded} steps" if args.guard else ""))
