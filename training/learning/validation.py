"""python -m training.learning.validation RUN [RUN ...]: teacher-forced numbers of trained checkpoints on
the prepared validation take, as a markdown table (the latent-size study of docs/results.md).

    python -m training.learning.validation runs/latent/*/*

Each RUN is a folder holding checkpoint.pt (training.learning.train's output). MPJPE is split in two:
"target code" decodes the code the output encoder picks when it sees the answer (what the
autoencoder can reconstruct at all), "estimated code" decodes the input encoder's argmax (what
the model delivers). Their difference is what wrong codes cost, the part that matching, and so
the intention, can win back.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import torch

from ..data.folders import add_folder
from .models import code_logits, sample_codes
from ..data.prepared import TrainError, load_split, normalize, pose_error_cm
from .runs import load_run
from .train import validate


@torch.no_grad()
def measure(run: Path, prepared: str) -> dict:
    r = load_run(run, prepared)
    cfg, stats = r.cfg, r.stats
    val = load_split(prepared, "validation", cfg.role)
    x, y = normalize(val["input"], stats, "input"), normalize(val["output"], stats, "output")
    _, codebook, mpjpe = validate(r.predictor, r.matching, cfg, x, y, "cpu", stats)
    target = sample_codes(code_logits(r.predictor, r.matching, x, y).target, cfg.channels, 0.0)
    return {"run": str(run), "intention": cfg.intention, "channels": cfg.channels, "seed": r.config["seed"],
            # A wrong channel puts two mismatched ones in a row's C·D one-hot entries.
            "codebook": codebook, "wrong_channels": codebook * cfg.latent / 2,
            "mpjpe_target_cm": float(pose_error_cm(r.matching.decode(target, x), y, stats).mean()), "mpjpe_cm": mpjpe}


def table(rows: list[dict]) -> str:
    lines = ["| run | intention | C | seed | MPJPE cm | MPJPE target code cm | wrong channels | codebook |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['run']} | {'yes' if r['intention'] else 'no'} | {r['channels']} | {r['seed']} | "
                     f"{r['mpjpe_cm']:.3f} | {r['mpjpe_target_cm']:.3f} | {r['wrong_channels']:.2f} | {r['codebook']:.4f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.learning.validation", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", type=Path, help="folders with checkpoint.pt")
    add_folder(ap, "prepared", "the data the runs were trained on (normalization, validation split)",
               old=("--data",))
    args = ap.parse_args(argv)
    try:
        for run in args.runs:
            if not (run / "checkpoint.pt").exists():
                raise TrainError(f"{run}/checkpoint.pt not found")
        rows = [measure(r, args.prepared) for r in args.runs]
    except TrainError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
