"""lambda_sweep.png: last-epoch validation codebook error and MSE against λG/λC (paper:
MatchingError), from the finished runs of the sweep."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .common import COLORS, Skip, pyplot, run_state, save_figure


def log_positions(ratios, zero_at: float | None = None) -> tuple[np.ndarray, float]:
    """x positions on a log axis for values >= 0: a 0 goes to `zero_at` (default one decade
    below the smallest positive value). Returns (positions, zero position)."""
    r = np.asarray(ratios, dtype=float)
    pos = r[r > 0]
    if zero_at is None:
        zero_at = (pos.min() / 10) if len(pos) else 1e-4
    return np.where(r > 0, r, zero_at), zero_at

def sweep_runs(args) -> tuple[list[dict], list[str]]:
    """Finished runs with their λG/λC and last-epoch validation metrics, plus notes."""
    runs = Path(args.runs)
    candidates = [runs / "follower_no_gan", runs / "follower"]
    sweep = Path(args.sweep)
    if sweep.is_dir():
        candidates += sorted(p / "follower" for p in sweep.iterdir() if p.is_dir())
    points, notes = [], []
    for run in candidates:
        st = run_state(run)
        if st is None:
            notes.append(f"{run}: no checkpoint yet")
            continue
        if st["stage"] != "done":
            notes.append(f"{run}: still training ({st['stage']} epoch {st['epoch']})")
            continue
        h, cfg = st["history"], st["config"]
        if not h.get("val_codebook"):
            notes.append(f"{run}: no validation history")
            continue
        lg, lc = cfg.get("lambda_generator"), cfg.get("lambda_codebook")
        points.append({"run": str(run), "lambda_generator": lg, "lambda_codebook": lc, "ratio": lg / lc,
                       "val_codebook": h["val_codebook"][-1], "val_mse": h["val_mse"][-1],
                       "best_val_codebook": min(h["val_codebook"]), "epochs": len(h["val_codebook"])})
    points.sort(key=lambda p: p["ratio"])
    return points, notes

def figure_sweep(args, out: Path) -> list[str]:
    points, notes = sweep_runs(args)
    if not points:
        raise Skip("no finished run of the λG sweep: " + "; ".join(notes))
    lcs = {p["lambda_codebook"] for p in points}
    ratios = np.array([p["ratio"] for p in points])
    pos, zero_at = log_positions(ratios)
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2))
    for ax, key, label in ((axes[0], "val_codebook", "validation codebook matching error"),
                           (axes[1], "val_mse", "validation MSE (normalized output)")):
        v = np.array([p[key] for p in points])
        positive = ratios > 0
        ax.plot(pos[positive], v[positive], "-", color=COLORS["follower"], alpha=0.5)
        if (~positive).any() and positive.any():   # 0 is not on a log scale: a dotted link
            first = np.argmax(positive)
            ax.plot([zero_at, pos[first]], [v[~positive][-1], v[first]], ":", color=COLORS["follower"], alpha=0.5)
        ax.plot(pos, v, "o", color=COLORS["follower"], markersize=7)
        for x_, y_, p in zip(pos, v, points):
            ax.annotate(f"{y_:.4f}", (x_, y_), textcoords="offset points", xytext=(0, 8), ha="center", fontsize=8)
        ax.set_xscale("log")
        ticks = sorted(set(pos.tolist()))
        lg_of = {float(x_): p["lambda_generator"] for x_, p in zip(pos, points)}
        ax.set_xticks(ticks)
        ax.set_xticklabels([("0" if t == zero_at and 0 in ratios else f"{t:g}") + f"\nλG={lg_of[t]:g}" for t in ticks])
        ax.minorticks_off()
        if 0 in ratios and positive.any():
            brk = math.sqrt(zero_at * pos[positive].min())
            ax.text(brk, 0, "//", transform=ax.get_xaxis_transform(), ha="center", va="center",
                    fontsize=12, color="#555555", backgroundcolor="white")
        ax.set_xlim(min(ticks) / 2.5, max(ticks) * 2.5)
        ax.set_xlabel(f"λG / λC   (λC = {', '.join(f'{c:g}' for c in sorted(lcs))}; log axis, broken before 0)")
        ax.set_ylabel(label)
        ax.margins(y=0.2)
        ax.grid(alpha=0.3)
    fig.suptitle("GAN weight vs matching weight: last-epoch validation metrics (follower)")
    fig.tight_layout()
    save_figure(fig, out, "sweep")
    plt.close(fig)
    lines = ["λG/λC sweep, last epoch (best epoch in brackets):"]
    for p in points:
        lines.append(f"  λG {p['lambda_generator']:g} / λC {p['lambda_codebook']:g} = {p['ratio']:g}: val codebook "
                     f"{p['val_codebook']:.4f} ({p['best_val_codebook']:.4f}), val MSE {p['val_mse']:.4f}, "
                     f"{p['epochs']} epochs  [{p['run']}]")
    lines += [f"  note: {n}" for n in notes]
    return lines
