"""python -m training.evaluation.jitter: do the dancers' hips jitter, against the recorded couples'?

Two figures per dancer, from the hip joint's world path at 30 fps:
- **reversals a second**: frames where the hips' motion turns back, i.e. this frame's step and the
  one before point more than 90 degrees apart (a dot product below zero), with both steps longer
  than STILL (a hip standing still turns every way and says nothing);
- **speed change**: the mean change of the hips' velocity from one frame to the next, in cm a frame
  (|v(t) - v(t-1)| with v in cm a frame): a smooth path changes little between frames.

Measured on the recorded couples (every take, as recorded) and on the page's loop in Python (the
soak's duets, steered by its stick and with nobody steering, at the manifest's tempo): the bodies
the networks leave ("raw") and the ones the page draws after its contact layer ("shown"). Each is
printed with its ratio to the recorded dancer's and the worst seed.

    python -m training.evaluation.jitter --seeds 20 --seconds 30 --out runs/jitter
    python -m training.evaluation.jitter --plot OUT.png --plot-seed 7 --steer nobody   # one duet, seen from above
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
from ..mirror.on_count import STILL   # m a frame (6 cm/s): shorter steps are standing still
from ..mirror.skeleton import FPS

HIP = 0


def hip_jitter(positions: np.ndarray, fps: int = FPS) -> dict:
    """World positions [T, 17, 3] -> reversals a second and the mean speed change (cm a frame)."""
    v = np.diff(positions[:, HIP], axis=0)
    seconds = len(positions) / fps
    return {"reversals_per_s": int(reversal_frames(positions).sum()) / seconds,
            "speed_change_cm": float(np.linalg.norm(v[1:] - v[:-1], axis=-1).mean() * 100)}


def recorded(data: str) -> dict:
    """Each recorded dancer's figures, pooled over the takes (frame-weighted means)."""
    from ..data.dataset import discover_takes, load_pair, pair_tracks
    rows = {"leader": [], "follower": []}
    for take in discover_takes(data):
        lead, follow = pair_tracks(*load_pair(take))
        rows["leader"].append((hip_jitter(lead.positions), len(lead.positions)))
        rows["follower"].append((hip_jitter(follow.positions), len(follow.positions)))
    return {role: {k: float(sum(r[k] * n for r, n in items) / sum(n for _, n in items)) for k in items[0][0]}
            for role, items in rows.items()}


def rollouts(args, steer: bool) -> list[dict]:
    """Per seed: each dancer's figures, raw and shown."""
    from .rhythm import load_dancers
    from .duet import soak_one
    from .options import restart_count
    manifest, leader, follower, temperature = load_dancers(args)
    out = []
    for seed in tqdm(range(args.first_seed, args.first_seed + args.seeds), desc="steered" if steer else "nobody steering",
                     disable=args.quiet):
        rec = {}
        restart_count(leader, follower)   # each seed dances as if alone (on_count.OnCount.restart)
        soak_one(manifest, leader, follower, seed, int(args.seconds * FPS), temperature, record=rec,
                 tempo=args.tempo, steer=steer)
        out.append({"seed": seed, **{f"{role}_{kind}": hip_jitter(rec[role if kind == "raw" else f"{role}_shown"])
                                     for role in ("leader", "follower") for kind in ("raw", "shown")}})
    return out


def reversal_frames(positions: np.ndarray) -> np.ndarray:
    """[T, 17, 3] -> [T - 2] bool: the frames where the hips' step turns back (hip_jitter's count)."""
    v = np.diff(positions[:, HIP], axis=0)
    a, b = v[1:], v[:-1]
    moving = (np.linalg.norm(a, axis=-1) > STILL) & (np.linalg.norm(b, axis=-1) > STILL)
    return (np.sum(a * b, -1) < 0) & moving


def plot(path: str, args, seed: int, steer: bool, seconds: float = 4.0) -> None:
    """Her hips over the floor, seen from above, as the network put them and as the page draws
    them: the `seconds` of one duet (of its --seconds) where the drawn hips turn back most, a dot a
    frame. Jitter is a path that doubles back."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from .rhythm import load_dancers
    from .duet import soak_one
    manifest, leader, follower, temperature = load_dancers(args)
    rec = {}
    soak_one(manifest, leader, follower, seed, int(args.seconds * FPS), temperature, record=rec,
             tempo=args.tempo, steer=steer)
    width = int(seconds * FPS)
    counts = np.convolve(reversal_frames(rec["follower_shown"]).astype(float), np.ones(width), "valid")
    start = int(np.argmax(counts))
    sl = slice(start, start + width)
    fig, axes = plt.subplots(1, 2, figsize=(10, 5), sharex=True, sharey=True)
    for ax, key, title in ((axes[0], "follower", "as the network put them"), (axes[1], "follower_shown", "as the page draws them")):
        p = rec[key][sl, HIP]
        j = hip_jitter(rec[key][sl])
        ax.plot(p[:, 0], p[:, 2], "-", color="#c33", lw=0.8)
        ax.plot(p[:, 0], p[:, 2], ".", color="#c33", ms=3)
        ax.set_title(f"her hips {title}: {j['reversals_per_s']:.2f} reversals a second", fontsize=10)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
    axes[0].set_ylabel("z (m)")
    fig.suptitle(f"seed {seed}, {'steered' if steer else 'nobody steering'}: {start / FPS:.1f}-{(start + width) / FPS:.1f} s, "
                 "where her drawn hips turn back most; a dot a frame")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def summarize(rows: list[dict], reference: dict) -> dict:
    """Means over seeds, each with its ratio to the recorded dancer's and the worst (highest) seed."""
    out = {}
    for role in ("leader", "follower"):
        for kind in ("raw", "shown"):
            for k in ("reversals_per_s", "speed_change_cm"):
                values = np.array([r[f"{role}_{kind}"][k] for r in rows])
                worst = int(np.argmax(values))
                out[f"{role}_{kind}_{k}"] = {"mean": float(values.mean()), "ratio": float(values.mean() / reference[role][k]),
                                             "worst": float(values[worst]), "worst_seed": rows[worst]["seed"]}
    return out


def markdown(title: str, s: dict, reference: dict) -> str:
    lines = [f"**{title}**", "", "| dancer | hip reversals a second | hips' speed change, cm a frame |", "|---|---|---|"]
    for role in ("leader", "follower"):
        ref = reference[role]
        lines.append(f"| recorded {role} | {ref['reversals_per_s']:.2f} | {ref['speed_change_cm']:.2f} |")
        for kind in ("shown", "raw"):   # as drawn first: what a visitor sees
            cells = []
            for k in ("reversals_per_s", "speed_change_cm"):
                c = s[f"{role}_{kind}_{k}"]
                cells.append(f"{c['mean']:.2f} ({c['ratio']:.2f}×; worst seed {c['worst_seed']}: {c['worst']:.2f})")
            lines.append(f"| {role}, {'as drawn' if kind == 'shown' else 'its network'} | {' | '.join(cells)} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    from . import options as O
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "the recorded couples the figures are read against")
    add_folder(ap, "models", "the dancers measured")
    ap.add_argument("--follower", default="follower", help="follower model name in the manifest")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--steer", choices=("both", "steered", "nobody"), default="both")
    ap.add_argument("--out", default="runs/jitter", help="writes OUT/jitter.json and .md")
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument("--plot", metavar="FILE", help="only draw her hips' path, raw and drawn, of --plot-seed (PNG)")
    ap.add_argument("--plot-seed", type=int, default=0)
    O.add_options(ap)
    args = ap.parse_args(argv)
    if args.seeds < 1 or args.seconds < 2:
        print("error: --seeds 1 or more and --seconds 2 or more", file=sys.stderr)
        return 2
    if args.plot:
        plot(args.plot, args, args.plot_seed, args.steer != "nobody")
        print(f"wrote {args.plot}")
        return 0
    t0 = time.time()
    reference = recorded(args.data)
    report, text = {"recorded": reference}, []
    for steer in ([True, False] if args.steer == "both" else [args.steer == "steered"]):
        name = "steered" if steer else "nobody steering"
        rows = rollouts(args, steer)
        report[name] = {"seeds": rows, "summary": summarize(rows, reference)}
        text.append(markdown(f"{args.seeds} seeds × {args.seconds:g} s, {name}", report[name]["summary"], reference))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "jitter.json").write_text(json.dumps(report, indent=1))
    (out / "jitter.md").write_text("\n".join(text))
    print("\n".join(text))
    print(f"wrote {out}/jitter.json and .md in {time.time() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
