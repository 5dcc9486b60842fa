"""A trained run on disk (runs/models/NAME/checkpoint.pt) and the one way to load it.

training.learning.train writes the checkpoint (atomically, so a crash never leaves half a file); export,
validation, evaluation-only tools and plots read a finished run back with `load_run`: the saved
configuration, the networks with their weights, and the normalization of the prepared data it was
trained on, as eval-mode modules ready to call.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import torch

from .models import CodebookMatching, IntentionPredictor, ModelConfig, StepModel
from ..data.prepared import TrainError, load_stats


def save_checkpoint(path: Path, state: dict):
    tmp = path.with_suffix(".tmp")
    torch.save(state, tmp)
    tmp.replace(path)   # a crash mid-write never leaves a half checkpoint behind


def load_checkpoint(path: Path) -> dict:
    try:
        return torch.load(path, map_location="cpu", weights_only=False)
    except Exception as e:  # torch raises many types for a damaged file
        raise TrainError(f"{path}: checkpoint is unreadable ({e.__class__.__name__}); "
                         f"delete it to train from scratch") from None


@dataclass
class Run:
    path: Path
    config: dict                     # the TrainConfig it was trained with (dataclasses.asdict)
    predictor: IntentionPredictor    # loaded for every run (CCM's is trained but never used)
    matching: CodebookMatching
    stats: dict[str, torch.Tensor]   # normalization of the prepared data (prepared.load_stats)
    model: StepModel                 # one step on raw features: what export writes

    @property
    def name(self) -> str:
        return self.path.name

    @property
    def cfg(self) -> ModelConfig:
        return self.model.cfg

    def fingerprint(self) -> str:
        return fingerprint(self.model)


def fingerprint(model: StepModel) -> str:
    """16 hex digits that name one training (weights, configuration and normalization): export
    writes it into a step model, its evaluation files and the manifest, so evaluation can refuse
    files of different trainings side by side."""
    h = hashlib.sha256(json.dumps(asdict(model.cfg), sort_keys=True).encode())
    for name, t in sorted(model.state_dict().items()):
        h.update(f"{name} {t.dtype} {tuple(t.shape)}".encode())
        h.update(t.detach().cpu().contiguous().numpy().tobytes())
    return h.hexdigest()[:16]


def load_run(run: str | Path, prepared: str) -> Run:
    """A finished run with the normalization of `prepared`; TrainError (one line) when the
    checkpoint is missing, unreadable or unfinished."""
    run = Path(run)
    ckpt = run / "checkpoint.pt"
    if not ckpt.exists():
        raise TrainError(f"{ckpt} not found: train it first (python -m training.learning.train --model {run.name})")
    ck = load_checkpoint(ckpt)
    if ck.get("stage") != "done":
        raise TrainError(f"{ckpt}: training has not finished (stage {ck.get('stage')}); "
                         f"continue it with --resume")
    cfg = ModelConfig(**ck["config"]["model"])
    predictor, matching = IntentionPredictor(cfg), CodebookMatching(cfg)
    predictor.load_state_dict(ck["predictor"])
    matching.load_state_dict(ck["matching"])
    predictor.eval(); matching.eval()
    stats = load_stats(prepared, cfg.role)
    model = StepModel(cfg, predictor if cfg.intention else None, matching, stats).eval()
    return Run(run, ck["config"], predictor, matching, stats, model)
