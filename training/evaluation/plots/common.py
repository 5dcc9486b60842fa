"""What the figures of training.evaluation.plots share: one colour and label per method, the
inputs they read (runs, the prepared test split, evaluate's metrics.json), and saving."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

FILES = {"tsne": "tsne_latent.png", "codebook": "codebook_error_density.png", "sweep": "lambda_sweep.png",
         "rollout": "rollout_topview.png", "curves": "training_curves.png", "facing": "facing_angle.png"}
DPI = 110

# One colour per method across every figure: ours red, CCM blue/grey, Motion Matching green.
COLORS = {
    "follower": "#d62728", "follower_no_gan": "#ff7f0e", "follower_small": "#e377c2",
    "follower_end_to_end": "#8c564b", "follower_end_to_end_no_ss": "#bcbd22",
    "follower_ccm": "#4a7bb7", "follower_ccm_large": "#1f3f7a", "motion_matching": "#2ca02c",
    "leader": "#9467bd", "recording": "#111111", "recorded_leader": "#9467bd",
}
LABELS = {
    "follower": "ours", "follower_no_gan": "ours w/o GAN (λG=0)", "follower_small": "ours, small (256)",
    "follower_end_to_end": "ours, end-to-end", "follower_end_to_end_no_ss": "ours, end-to-end w/o SS",
    "follower_ccm": "CCM", "follower_ccm_large": "CCM large (24 ch)", "motion_matching": "Motion Matching",
    "leader": "leader model (leader data)",
}


class Skip(RuntimeError):
    """A figure's inputs are missing or unfinished; the message is one line for a user."""


def per_frame_codebook_error(target: np.ndarray, estimate: np.ndarray, classes: int) -> np.ndarray:
    """Code indices [N, C] -> per-frame MSE between the one-hot codes [N]: 2k/(C*D) for k
    channels that differ (the mean of this is metrics.codebook_error)."""
    target, estimate = np.asarray(target), np.asarray(estimate)
    return 2.0 * (target != estimate).sum(1) / (target.shape[1] * classes)

def run_state(run: Path) -> dict | None:
    """{'stage', 'epoch', 'history', 'config'} of a training folder, or None when there is no
    readable checkpoint. history.json is preferred for a finished run (it is written last)."""
    from ...data.prepared import TrainError
    from ...learning.runs import load_checkpoint
    ckpt = run / "checkpoint.pt"
    hist = run / "history.json"
    if not ckpt.exists():
        return None
    try:
        ck = load_checkpoint(ckpt)
    except TrainError:   # being written right now, or damaged
        return None
    history = ck.get("history", {})
    if ck.get("stage") == "done" and hist.exists():
        try:
            history = json.loads(hist.read_text())
        except ValueError:
            pass
    return {"stage": ck.get("stage"), "epoch": ck.get("epoch"), "history": history, "config": ck.get("config", {})}

def load_model(runs: Path, name: str, prepared: str):
    """The step model of a finished run, or Skip with the reason."""
    from ...data.prepared import TrainError
    from ...learning.runs import load_run
    try:
        return load_run(runs / name, prepared).model
    except TrainError as e:
        raise Skip(str(e)) from None

def load_test(prepared: str) -> dict[str, np.ndarray]:
    from ...data.prepared import TrainError, load_split
    try:
        return load_split(prepared, "test", "follower")
    except TrainError as e:
        raise Skip(str(e)) from None

def encode(model, x_raw: np.ndarray, y_raw: np.ndarray | None = None):
    """(estimate logits Ŝ, target logits S or None) [N, C*D] from raw inputs/outputs; the
    intention comes from the model's own predictor."""
    import torch
    with torch.no_grad():
        x = torch.from_numpy(np.asarray(x_raw, np.float32))
        y = None if y_raw is None else torch.from_numpy(np.asarray(y_raw, np.float32))
        est, tgt, _ = model.logits(x, y)
    return est.numpy(), None if tgt is None else tgt.numpy()

def codes_of(logits: np.ndarray, channels: int) -> np.ndarray:
    return logits.reshape(len(logits), channels, -1).argmax(-1)

def read_eval(args) -> dict | None:
    """runs/eval/metrics.json (training.evaluation.evaluate) when it is there and readable."""
    try:
        return json.loads(Path(args.eval).read_text())
    except (OSError, ValueError):
        return None


def save_figure(fig, out: Path, key: str) -> None:
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / FILES[key], dpi=DPI)


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"font.size": 10, "axes.titlesize": 11, "legend.fontsize": 9})
    return plt
