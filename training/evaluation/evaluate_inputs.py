"""What training.evaluation.evaluate reads: the evaluated takes (windows of the recording around a
frame) and the methods (the follower models in a models folder, and the recording as a policy).
interaction and plots read them the same way."""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..data.dataset import DataError, discover_takes, load_pair, pair_tracks, select_takes, take_count
from ..data.led_figures import figure_spans
from ..mirror import features as feat
from ..mirror.features import HISTORY, Track, output_features
from ..mirror.rollout import OnnxPolicy
from . import metrics as M

NAMES = {"follower": "ours", "follower_ccm": "ccm"}      # ONNX stem -> method name


class EvalError(RuntimeError):
    """A problem with the evaluation's inputs; the message is one line for a user."""


# ---------------------------------------------------------------- takes

@dataclass
class EvalTake:
    name: str
    lead: Track
    follow: Track
    lead_offsets: np.ndarray
    follow_offsets: np.ndarray
    frames: np.ndarray       # the current frames t evaluated (each predicts t+1)
    figures: np.ndarray = None   # [M, 3] the figures the recorded leader led (led_figures.figure_spans)

    def __post_init__(self):
        if self.figures is None:
            self.figures = figure_spans(self.lead.positions, self.follow.positions)

    def figure(self, frames: np.ndarray) -> np.ndarray:
        """The figure block both dancers read at `frames` (features.figure_block): the recorded lead."""
        return feat.figure_block(self.figures, np.asarray(frames))


def load_eval_takes(data: str, names: list[str], max_frames: int | None, leader: str | None,
                    tempo: float | None = None) -> list[EvalTake]:
    """The test takes at 30 fps, each carrying its found count; with `tempo` (beats a minute)
    each take is time-warped so that its count runs at that tempo (the couple danced faster or
    slower, as the training's tempo copies), the recording and the methods alike."""
    out = []
    for take in select_takes(discover_takes(data, leader), names):
        lead_m, follow_m = load_pair(take)
        speed = 1.0 if tempo is None else tempo / take_count(lead_m, follow_m).bpm
        lead, follow = pair_tracks(lead_m, follow_m, tempo=speed)
        frames = feat.valid_frames(lead.frames)[:max_frames]
        if len(frames) < M.WINDOW + 1:
            raise DataError(f"take {take.name}: too short to evaluate ({lead.frames} frames at 30 fps; "
                            f"needs {2 * HISTORY + M.WINDOW + 2})")
        out.append(EvalTake(take.name, lead, follow, lead_m.offsets, follow_m.offsets, frames))
    return out


def window(track: Track, t: int) -> Track:
    """A copy of the 61 frames around t: the rollout's track layout with t at NOW."""
    sl = slice(t - HISTORY, t + HISTORY + 1)
    return Track(track.positions[sl].copy(), track.rotations[sl].copy(), track.root[sl].copy(),
                 track.heading[sl].copy())


# ---------------------------------------------------------------- methods

class RecordingPolicy:
    """The recording as a policy: at frame t it answers the recorded output O(t)."""

    def seek(self, track: Track, t: int) -> None:
        self.output = output_features(track, np.array([t]))

    def __call__(self, x, temperature, rng):
        return {"output": self.output}


def find_models(models: str) -> tuple[dict, dict[str, Path], Path | None]:
    """manifest, {method: follower onnx}, leader onnx (or None)."""
    root = Path(models)
    if not root.is_dir():
        raise EvalError(f"models folder {root} not found (python -m training.learning.export writes it)")
    mpath = root / "manifest.json"
    if not mpath.exists():
        raise EvalError(f"{mpath} not found (python -m training.learning.export writes it next to the models)")
    manifest = json.loads(mpath.read_text())
    roles = {name: m.get("role") for name, m in manifest.get("models", {}).items()}
    followers, leader = {}, None
    for f in sorted(root.glob("*.onnx")):
        role = roles.get(f.stem) or ("leader" if f.stem.startswith("leader") else "follower")
        if role == "follower":
            followers[NAMES.get(f.stem, f.stem)] = f
        elif f.stem == "leader":
            leader = f
    return manifest, followers, leader


def load_onnx(path: Path) -> OnnxPolicy:
    try:
        return OnnxPolicy(path)
    except Exception as e:   # onnxruntime raises its own types for a damaged or foreign file
        raise EvalError(f"{path}: cannot be loaded by onnxruntime ({e.__class__.__name__})") from None
