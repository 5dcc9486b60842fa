"""python -m training.data.count_report: the count training/data/count.py finds in each recorded take.

Prints, per take, the tempo and phase the couple, the leader alone and the follower alone give, and
how far the count found in 10 s windows is from the take's; `--plot FILE` draws footwork with the
found beats (docs/count.png, docs/music.md).
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

from ..mirror.skeleton import FPS
from .count import Count, find_count, footwork, normalized, plot_footwork, measure_strength, phase_at, phase_gap, window_gaps
from .dataset import DataError, discover_takes, load_pair, pair_tracks
from .folders import add_folder


def _takes(data: str):
    for take in discover_takes(data):
        lead, follow = pair_tracks(*load_pair(take))
        yield take.name, lead.positions, follow.positions


def report(data: str) -> list[dict]:
    rows = []
    for name, lp, fp in _takes(data):
        couple = find_count(lp, fp)
        lone = [find_count(p) for p in (lp, fp)]
        # each dancer alone, at the couple's tempo: does the beat fall at the same moments?
        alone_phase = [Count(couple.bpm, phase_at(normalized(footwork(p)), couple.bpm)) for p in (lp, fp)]
        windows = window_gaps(lp, fp, couple)
        beat_gaps = [phase_gap(c, couple, group=1.0) for c in alone_phase]
        rows.append({
            "take": name, "seconds": len(lp) / FPS, "bpm": couple.bpm, "beat0": couple.beat0,
            "bpm_leader": lone[0].bpm, "bpm_follower": lone[1].bpm,
            "beat_leader": beat_gaps[0], "beat_follower": beat_gaps[1],
            "group_leader": abs(phase_gap(alone_phase[0], couple)) < 0.5,
            "group_follower": abs(phase_gap(alone_phase[1], couple)) < 0.5,
            "window_tempo": float(np.median([abs(w["tempo"]) for w in windows])),
            "window_beat": max(abs(w["beat"]) for w in windows),
            "window_group": sum(abs(w["group"]) < 0.5 for w in windows) / len(windows),
            "leader_swing": measure_strength(lp, couple), "follower_swing": measure_strength(fp, couple),
        })
    return rows


def print_report(rows: list[dict]) -> None:
    print("take    s    bpm | alone: tempo (bpm) L F | beat off (beats) L F | same group L F | "
          "10 s windows: tempo off (median), beat off (worst), same group | leader swing every 1/2/4/8 beats (x noise)")
    yes = {True: "yes", False: " no"}
    for r in rows:
        s = r["leader_swing"]
        print(f"{r['take']:>4} {r['seconds']:5.1f} {r['bpm']:6.1f} | {r['bpm_leader']:6.1f} {r['bpm_follower']:6.1f} | "
              f"{r['beat_leader']:+.2f} {r['beat_follower']:+.2f} | {yes[r['group_leader']]} {yes[r['group_follower']]} | "
              f"{100 * r['window_tempo']:4.1f} % {r['window_beat']:.2f} {100 * r['window_group']:4.0f} % | "
              f"{s[1]:.1f} {s[2]:.1f} {s[4]:.1f} {s[8]:.1f}")
    agree = sum(abs(r["bpm_leader"] / r["bpm"] - 1) <= 0.02 and abs(r["bpm_follower"] / r["bpm"] - 1) <= 0.02 for r in rows)
    same = sum(max(abs(r["beat_leader"]), abs(r["beat_follower"])) <= 0.15 for r in rows)
    group = sum(r["group_leader"] and r["group_follower"] for r in rows)
    steady = sum(r["window_beat"] <= 0.15 for r in rows)
    windows_group = float(np.mean([r["window_group"] for r in rows]))
    med = {b: float(np.median([r["leader_swing"][b] for r in rows])) for b in (1, 2, 4, 8)}
    print(f"each dancer alone finds the couple's tempo within 2 %: {agree} of {len(rows)} takes; at the couple's "
          f"tempo, the beat within 0.15 beats: {same} of {len(rows)}, the same two-beat group: {group} of {len(rows)}")
    print(f"every 10 s window's beat within 0.15 beats of its take's: {steady} of {len(rows)} takes; "
          f"windows in the take's two-beat group: {100 * windows_group:.0f} %")
    print("the leader's footwork swing (median over takes, x its neighbouring frequencies): "
          + ", ".join(f"every {b} beats {v:.1f}" for b, v in med.items()))


def plot(data: str, out: str, takes: list[str], start: float = 6.0, seconds: float = 5.0) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [(n, lp, fp) for n, lp, fp in _takes(data) if n in takes]
    fig, axes = plt.subplots(len(rows), 1, figsize=(10, 1.9 * len(rows)), sharex=True, squeeze=False)
    for ax, (name, lp, fp) in zip(axes[:, 0], rows):
        c = find_count(lp, fp)
        t, _ = plot_footwork(ax, lp, fp, start, seconds)
        b = c.beats(t)
        for k in range(int(np.ceil(b[0])), int(np.floor(b[-1])) + 1):
            x = (k - c.beat0) * 60.0 / c.bpm
            ax.axvline(x, color="k", lw=1.4 if k % 2 == 0 else 0.6, alpha=0.6 if k % 2 == 0 else 0.35)
        ax.set_ylabel("m/s")
        ax.set_title(f"take {name}: {c.bpm:.1f} beats a minute (lines: found beats, bold: even)", fontsize=9, loc="left")
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("seconds from the take's start (footwork: summed ankle speed; a foot lands at its lows)")
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    print(f"wrote {out}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.data.count_report", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "read")
    ap.add_argument("--plot", metavar="FILE", help="draw footwork with the found beats (PNG)")
    ap.add_argument("--takes", default="01,07,09,13", help="takes to plot (comma-separated)")
    args = ap.parse_args(argv)
    try:
        print_report(report(args.data))
        if args.plot:
            plot(args.data, args.plot, [t for t in args.takes.split(",") if t])
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
