"""python -m training.evaluation.plots: the paper's analysis figures from the trained models -> PNGs.

    python -m training.evaluation.plots --out docs                 # every figure
    python -m training.evaluation.plots --out docs --only tsne,sweep

Figures (each prints the numbers it shows; one whose inputs are missing is skipped with a note):

tsne_latent.png             t-SNE of the output encoder's target logits S (blue) and the input
                            encoder's estimate Ŝ (red) on test frames, with (follower) and without
                            (follower_no_gan) the adversarial term (paper: DrawLatentSpace).
codebook_error_density.png  per-frame codebook matching error on the test frames (paper:
                            CodebookErrorDensity), as recorded and with the leader's future path
                            in the follower input turned by ±30° / ±60° about the follower's root.
lambda_sweep.png            last-epoch validation codebook error and MSE against λG/λC (paper:
                            MatchingError).
rollout_topview.png         top view of free-running rollouts on a test take, leader played back
                            from the recording (evaluate.rollout), ours vs CCM vs the recording.
training_curves.png         validation MSE and codebook error per epoch of every model.
facing_angle.png            the follower's facing over time beside the played-back recorded leader:
                            recorded, ours, CCM, Motion Matching, each turn marked (figures.py).

Codebook error of one frame: the MSE between the one-hot target code (argmax of S per channel)
and the one-hot estimate (argmax of Ŝ, temperature 0), i.e. 2k/(C*D) for k channels that differ,
as train.validate and evaluate measure it. Under control both encoders read the turned input (the
target still encodes the recorded output, the only one there is); Motion Matching has no encoder
of its own, so its code is our output encoder's code of the frame it picked (as in evaluate).
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from .codebook import figure_codebook
from .common import FILES, Skip
from .curves import figure_curves
from .facing import figure_facing
from .rollout import figure_rollout
from .sweep import figure_sweep
from .tsne import figure_tsne

FIGURES = ["tsne", "codebook", "sweep", "rollout", "curves", "facing"]


def main(argv=None) -> int:
    from ...data.folders import add_folder
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.plots", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="docs", help="folder for the PNGs")
    ap.add_argument("--only", default=",".join(FIGURES), help=f"comma-separated subset of {','.join(FIGURES)}")
    add_folder(ap, "prepared", "test split for t-SNE and codebook error")
    add_folder(ap, "runs", "checkpoints and training history")
    ap.add_argument("--sweep", default="runs/sweep", help="λG sweep: one folder per value, each with follower/")
    add_folder(ap, "models", "rollout top view")
    add_folder(ap, "data", "rollout take, Motion Matching database", old=("--bvh",))
    ap.add_argument("--eval", default="runs/eval/metrics.json", help="training.evaluation.evaluate output (cross-checks)")
    ap.add_argument("--take", default="13", help="test take of the rollout")
    ap.add_argument("--frames", type=int, default=600, help="rollout steps at most")
    ap.add_argument("--temperature", type=float, default=0.5, help="rollout sampling temperature")
    ap.add_argument("--seed", type=int, default=0, help="rollout seed (drawn)")
    ap.add_argument("--summary-seeds", type=int, default=3, help="seeds seed.. seed+N-1 in the rollout's printed spread")
    ap.add_argument("--rollout-bend", default="rot+60", help="second rollout panel: rot±DEG or side±M ('' for none)")
    ap.add_argument("--tsne-frames", type=int, default=500, help="test frames in the t-SNE (2 points each)")
    ap.add_argument("--tsne-iter", type=int, default=1000)
    ap.add_argument("--no-motion-matching", dest="motion_matching", action="store_false",
                    help="leave Motion Matching out of the codebook figure")
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args(argv)
    wanted = [f for f in args.only.split(",") if f]
    unknown = [f for f in wanted if f not in FIGURES]
    if unknown:
        ap.error(f"unknown figure(s) {', '.join(unknown)}; choose from {', '.join(FIGURES)}")
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, str(args.threads))
    import torch
    torch.set_num_threads(args.threads)
    out = Path(args.out)
    makers = {"tsne": figure_tsne, "codebook": figure_codebook, "sweep": figure_sweep,
              "rollout": figure_rollout, "curves": figure_curves, "facing": figure_facing}
    written, skipped = [], []
    for f in wanted:
        try:
            lines = makers[f](args, out)
        except Skip as e:
            skipped.append(f"{FILES[f]}: {e}")
            print(f"skipped {FILES[f]}: {e}", file=sys.stderr)
            continue
        written.append(out / FILES[f])
        print(f"== {out / FILES[f]}")
        print("\n".join(lines), flush=True)
    if not written:
        print("error: no figure could be made (" + "; ".join(skipped) + ")", file=sys.stderr)
        return 2
    print(f"wrote {len(written)} figure(s) to {out}" + (f"; skipped {len(skipped)}" if skipped else ""))
    return 0
