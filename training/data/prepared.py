"""The prepared arrays (training.data.prepare's output) as training reads them, and their normalization.

Every network works on normalized features: (raw - mean) / std with the training split's
statistics in stats.npz. `normalize` applies them, `pose_error_cm` reads a pose error back in
centimetres from two normalized outputs.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ..mirror import features as feat


class TrainError(RuntimeError):
    """Bad training input or output (prepared data, checkpoints); the message is one line for a user."""


def _unreadable(path: Path, e: Exception) -> TrainError:
    return TrainError(f"{path}: unreadable or not written by training.data.prepare "
                      f"({e.__class__.__name__}); re-run training.data.prepare")


def require_tempo_copies(prepared: str) -> None:
    """Tempo copies are written by prepare unless `--tempos ''` turned them off: a recipe that trains
    on them (the shipped ones do) says how to get them instead of failing on a missing file."""
    path = Path(prepared) / "train_tempo.npz"
    if not path.exists():
        raise TrainError(f"{path} not found: this recipe trains on tempo copies: run "
                         f"`python -m training.data.prepare --prepared {prepared} --tempos` (its default) first")


def load_split(prepared: str, split: str, role: str, tempo_copies: bool = False) -> dict[str, np.ndarray]:
    """{"input", "output", "intention"} raw float32 arrays of one split and role; with
    `tempo_copies` the training split is followed by its time-warped copies (train_tempo.npz)."""
    if tempo_copies:
        a = load_split(prepared, split, role)    # the recorded samples first (and their checks)
        require_tempo_copies(prepared)
        b = load_split(prepared, "train_tempo", role)
        return {k: np.concatenate([a[k], b[k]]) for k in a}
    path = Path(prepared) / f"{split}.npz"
    if not path.exists():
        raise TrainError(f"{path} not found: run `python -m training.data.prepare --prepared {prepared}` first")
    try:
        with np.load(path) as z:
            arrays = {k: z[f"{role}_{k}"] for k in ("input", "output", "intention")}
    except Exception as e:  # zipfile, pickle and key errors all mean the same thing here
        raise _unreadable(path, e) from None
    sizes = {"input": feat.INPUT_SIZES[role], "output": feat.OUTPUT_SIZE, "intention": feat.INTENTION_SIZE}
    for k, n in sizes.items():
        if arrays[k].shape[1] != n:
            raise TrainError(f"{path}: {role} {k} has {arrays[k].shape[1]} features, this code "
                             f"expects {n}; re-run training.data.prepare")
    return arrays


def load_stats(prepared: str, role: str) -> dict[str, torch.Tensor]:
    """{"input_mean", "input_std", "output_mean", ..., "intention_std"} of one role."""
    path = Path(prepared) / "stats.npz"
    if not path.exists():
        raise TrainError(f"{path} not found: run `python -m training.data.prepare --prepared {prepared}` first")
    try:
        with np.load(path) as z:
            return {f"{k}_{s}": torch.from_numpy(z[f"{role}_{k}_{s}"])
                    for k in ("input", "output", "intention") for s in ("mean", "std")}
    except Exception as e:
        raise _unreadable(path, e) from None


def normalize(a: np.ndarray, stats: dict[str, torch.Tensor], key: str) -> torch.Tensor:
    """Raw features -> normalized float32 tensor with the prepared mean/std of `key`."""
    return ((torch.as_tensor(a) - stats[f"{key}_mean"]) / stats[f"{key}_std"]).float()


def pose_error_cm(y_hat: torch.Tensor, y: torch.Tensor, stats: dict[str, torch.Tensor]) -> torch.Tensor:
    """Per-sample MPJPE in cm between two normalized outputs [B, 323]: the pose block's joint
    positions (dancer's root space), de-normalized."""
    pose = feat.block_slices(feat.OUTPUT_LAYOUT)["pose"]
    mean, std = stats["output_mean"].to(y.device), stats["output_std"].to(y.device)
    p, q = ((t * std + mean)[:, pose].reshape(len(t), feat.N_JOINTS, 12)[..., :3] for t in (y_hat, y))
    return (p - q).norm(dim=-1).mean(-1) * 100


def load_offsets(prepared: str, role: str, device) -> torch.Tensor:
    """[2, 17, 3] bone offsets of the role: as recorded, and mirrored (prepare's mirrored samples);
    the training terms on the decoded body run forward kinematics with them."""
    from ..mirror.skeleton import MIRROR
    path = Path(prepared) / "stats.npz"
    with np.load(path) as z:
        if f"{role}_offsets" not in z:
            raise TrainError(f"{path} has no bone offsets (written by an older training.data.prepare); "
                             f"re-run training.data.prepare")
        off = z[f"{role}_offsets"]
    return torch.tensor(np.stack([off, off[MIRROR] @ np.diag([-1.0, 1.0, 1.0])]), dtype=torch.float32, device=device)


def load_mirror_flags(prepared: str, tempo_copies: bool = False) -> np.ndarray:
    """Per training sample (in load_split's order): True where it is a mirrored copy (its
    skeleton is mirrored too)."""
    if tempo_copies:
        require_tempo_copies(prepared)
    files = ["train.npz"] + (["train_tempo.npz"] if tempo_copies else [])
    flags = []
    for f in files:
        with np.load(Path(prepared) / f) as z:
            flags.append(z["mirror"].astype(bool))
    return np.concatenate(flags)
