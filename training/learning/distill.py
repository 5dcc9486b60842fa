"""A shipped step model read back from its int8 ONNX file as a float network: the teacher a
narrower network is distilled from (train --teacher FILE).

Trained from the recording by the shipped recipe, a narrower leader stopped turning and a request
stopped making her turn (docs/measurements.md, the tried table): the recorded frames alone do not
say which of the codes a wide network learnt to draw carry a turn. Distilled, the narrow network
learns the shipped one's code distribution on every input (its logits, not one recorded code) and
what its decoder makes of each code, on the recorded frames and on its own rollouts.

The ONNX file is the teacher because it is what the page runs: its weights are the int8 levels the
page multiplies with, dequantized here once (per output column: (q - zero point) * scale). The
runs/ checkpoints it was exported from are not kept beside a clone.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import torch

from .models import CodebookMatching, IntentionPredictor, ModelConfig, StepModel
from ..data.prepared import TrainError


def _dequantized(inits: dict[str, np.ndarray], name: str) -> np.ndarray:
    """The float matrix [in, out] an int8 initializer stands for (per-column or per-tensor scale)."""
    q = inits[f"{name}_quantized"].astype(np.float32)
    zp = inits[f"{name}_zero_point"].astype(np.float32)
    scale = inits[f"{name}_scale"].astype(np.float32)
    return (q - zp) * scale


def teacher_from_onnx(path: str | Path, student: ModelConfig) -> StepModel:
    """The step model in `path` (written by export.py) as float torch modules in eval mode, its
    normalization its own: the student's configuration at the widths the file holds. TrainError
    when the file is missing or does not hold such a network."""
    import onnx
    from onnx import numpy_helper
    path = Path(path)
    if not path.exists():
        raise TrainError(f"{path}: no teacher model there (a step model file as export writes it)")
    graph = onnx.load(str(path)).graph
    inits = {i.name: numpy_helper.to_array(i).copy() for i in graph.initializer}
    if "matching.decoder.0.bias" not in inits:
        raise TrainError(f"{path}: not a step model written by export")
    predictor_width = len(inits["predictor.net.0.bias"]) if student.intention else student.intention_hidden
    cfg = replace(student, hidden=len(inits["matching.decoder.0.bias"]), intention_hidden=predictor_width)
    predictor, matching = IntentionPredictor(cfg), CodebookMatching(cfg)
    state: dict[str, torch.Tensor] = {}
    for module, prefix in ((predictor, "predictor."), (matching, "matching.")):
        for key, p in module.state_dict().items():
            full = prefix + key
            if key.startswith("output_encoder") or (prefix == "predictor." and not cfg.intention):
                continue   # the page's step runs neither: left as initialized
            if key == "decoder.0.weight":
                continue   # split by export into a gather (the code) and a product (the state)
            if full.endswith(".bias"):
                value = inits[full]
            else:
                value = _dequantized(inits, full).T
            if tuple(value.shape) != tuple(p.shape):
                raise TrainError(f"{path}: {full} is {tuple(value.shape)}, the configuration says {tuple(p.shape)}")
            state[full] = torch.from_numpy(np.ascontiguousarray(value))
    # The decoder's first layer: the code's columns are a per-tensor uint8 Gather table, the
    # state's an int8 MatMul, both named by the exporter (the only ones of their shape).
    latent, hidden = cfg.latent, cfg.hidden
    gather = [n[: -len("_quantized")] for n, a in inits.items()
              if n.endswith("_quantized") and a.shape == (latent, hidden) and "Gather" in n]
    product = [n[: -len("_quantized")] for n, a in inits.items()
               if n.endswith("_quantized") and a.shape == (len(cfg.state_columns), hidden) and "MatMul" in n]
    if len(gather) != 1 or (cfg.decoder_state and len(product) != 1):
        raise TrainError(f"{path}: cannot find the decoder's first layer")
    parts = [_dequantized(inits, gather[0])] + ([_dequantized(inits, product[0])] if cfg.decoder_state else [])
    state["matching.decoder.0.weight"] = torch.from_numpy(np.ascontiguousarray(np.concatenate(parts).T))
    for module, prefix in ((predictor, "predictor."), (matching, "matching.")):
        own = {k[len(prefix):]: v for k, v in state.items() if k.startswith(prefix)}
        module.load_state_dict({**module.state_dict(), **own})
    stats = {k: torch.from_numpy(inits[k].astype(np.float32))
             for k in ("input_mean", "input_std", "output_mean", "output_std")}
    if cfg.intention:
        # Only what the step de-normalizes is in the file; the teacher's intention is read
        # normalized (train compares it with the student's predictor's, same statistics).
        stats["intention_mean"] = torch.zeros(cfg.intention_size)
        stats["intention_std"] = torch.ones(cfg.intention_size)
    return StepModel(cfg, predictor if cfg.intention else None, matching, stats).eval()
