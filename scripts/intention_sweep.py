"""The intention predictor alone, regularized several ways: validation MSE against training MSE.

    .venv/bin/python scripts/intention_sweep.py [--prepared runs/data] [--runs runs/intention_sweep]

Trains only stage 1 of the shipped follower's recipe (the predictor; about 25 s per row on one
thread) for each setting and prints a markdown table (docs/results.md, "Learning more from the
same frames"). The gap between the two MSEs is the overfitting the issue names; the last column is
what early stopping on validation (train --intention-best) would keep.
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from training.learning.train import MODELS, train_model  # noqa: E402

BASE = replace(MODELS["follower"], epochs=0)
ROWS = {
    "shipped (dropout 0.2, weight decay 1e-4)": BASE,
    "dropout 0.4": replace(BASE, intention_dropout=0.4),
    "dropout 0.6": replace(BASE, intention_dropout=0.6),
    "weight decay 0.05": replace(BASE, intention_weight_decay=0.05),
    "weight decay 0.5": replace(BASE, intention_weight_decay=0.5),
    "width 128": replace(BASE, model=replace(BASE.model, intention_hidden=128)),
    "width 64": replace(BASE, model=replace(BASE.model, intention_hidden=64)),
}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--prepared", default="runs/data")
    ap.add_argument("--runs", default="runs/intention_sweep")
    args = ap.parse_args()
    torch.set_num_threads(1)
    lines = ["| intention predictor | train MSE | validation MSE (last) | best epoch: validation MSE |",
             "|---|---|---|---|"]
    for i, (title, cfg) in enumerate(ROWS.items()):
        train_model(f"row{i}", cfg, args.prepared, args.runs, quiet=True)
        h = json.loads((Path(args.runs) / f"row{i}" / "history.json").read_text())
        val = h["intention_val"]
        best = min(range(len(val)), key=val.__getitem__)
        lines.append(f"| {title} | {h['intention_train'][-1]:.3f} | {val[-1]:.3f} | {best + 1}: {val[best]:.3f} |")
        print(lines[-1], flush=True)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
