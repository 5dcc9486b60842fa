"""training_curves.png: validation MSE and codebook error per epoch of every model."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .common import COLORS, LABELS, Skip, pyplot, run_state, save_figure

CURVE_MODELS = ["follower", "follower_ccm", "follower_ccm_large", "follower_small", "leader"]
ABLATIONS = ["follower_no_gan", "follower_end_to_end", "follower_end_to_end_no_ss"]


def figure_curves(args, out: Path) -> list[str]:
    runs = Path(args.runs)
    found, missing = [], []
    lines = ["validation per epoch (teacher-forced, temperature 0); last epoch [best]:"]
    extra = sorted(p.name for p in runs.iterdir() if (p / "checkpoint.pt").exists()
                   and p.name not in CURVE_MODELS + ABLATIONS) if runs.is_dir() else []
    for name in CURVE_MODELS + ABLATIONS + extra:
        st = run_state(runs / name)
        if st is None or not st["history"].get("val_mse"):
            missing.append(name)
            continue
        found.append((name, st))
    if not found:
        raise Skip(f"{runs}: no training history of {', '.join(CURVE_MODELS)}")
    plt = pyplot()
    from matplotlib.ticker import ScalarFormatter
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    spare = iter(["#17becf", "#7f7f7f", "#aec7e8", "#98df8a", "#c5b0d5", "#c49c94", "#f7b6d2", "#dbdb8d"] * 3)
    for name, st in found:
        h = st["history"]
        color = COLORS.get(name) or next(spare)
        done = st["stage"] == "done"
        label = LABELS.get(name, name) + ("" if done else f" (training, epoch {st['epoch']})")
        ls = "--" if name == "leader" else "-"
        for ax, key in zip(axes, ("val_mse", "val_codebook")):
            v = h[key]
            ax.plot(np.arange(1, len(v) + 1), v, ls, color=color, label=label, linewidth=1.6)
        lines.append(f"  {name:<26} MSE {h['val_mse'][-1]:.4f} [{min(h['val_mse']):.4f}]  codebook "
                     f"{h['val_codebook'][-1]:.4f} [{min(h['val_codebook']):.4f}]  "
                     f"{len(h['val_mse'])} epochs{'' if done else ' (still training)'}")
    axes[0].set_ylabel("validation MSE (normalized output)")
    axes[1].set_ylabel("validation codebook matching error")
    for ax, title in zip(axes, ("reconstruction", "codebook matching")):
        ax.set_xlabel("matching epoch")
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(ScalarFormatter())
        ax.yaxis.set_minor_formatter(ScalarFormatter())
        ax.set_title(title)
        ax.grid(alpha=0.3, which="both")
    axes[1].legend(fontsize=8, loc="upper right")
    fig.suptitle("Validation curves (take 12; the leader model on the leader's data)")
    fig.tight_layout()
    save_figure(fig, out, "curves")
    plt.close(fig)
    if missing:
        lines.append(f"  not available yet: {', '.join(missing)}")
    lines.append("  note: CCM large has 3x the channels: its codebook error per wrong channel is 1/3 of the others'")
    return lines
