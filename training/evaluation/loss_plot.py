"""losses.png of one training run: every logged loss against the epoch, one small panel each.

training.learning.train writes it at the end of a run; training.evaluation.plots draws the figures that compare runs.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


def plot_history(history: dict, path: Path, title: str):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    keys = [k for k in history if history[k]]
    cols = min(4, len(keys))
    rows = (len(keys) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.6 * rows), squeeze=False)
    for ax in axes.flat[len(keys):]:
        ax.axis("off")
    for ax, k in zip(axes.flat, keys):
        ax.plot(np.arange(1, len(history[k]) + 1), history[k])
        ax.set_title(k, fontsize=9)
        ax.set_xlabel("epoch", fontsize=8)
        ax.set_yscale("log" if min(history[k]) > 0 else "linear")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
