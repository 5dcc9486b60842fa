"""training/learning/own_rollouts.py: rollouts beside the recorded partner, as training samples.

A policy that answers the recorded next frame dances the recording itself, so every sample its
rollouts make must be the prepared sample of that frame: the rollout builds its inputs and targets
exactly as training.data.prepare does. A real network's rollouts then differ from the recording,
and a recipe with own rollouts trains on them."""
from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
import torch

from training.data.prepared import TrainError, load_offsets
from training.learning import train as T
from training.learning.own_rollouts import load_couples, own_rollout_samples
from training.mirror import features as feat


class Replay:
    """A step model that answers the prepared output of the prepared input nearest to the one it
    reads (phase 0 samples): it dances the recording."""

    def __init__(self, prepared, role):
        with np.load(prepared / "train.npz") as z:
            keep = z["phase"] == 0
            self.x = z[f"{role}_input"][keep].astype(np.float64)
            self.y = z[f"{role}_output"][keep].astype(np.float64)
        self.cfg = SimpleNamespace(channels=2, classes=4)
        self.distances = []

    def __call__(self, x, temperature, noise):
        x = x.double().numpy()
        d = ((x[:, None, :] - self.x[None]) ** 2).sum(-1)
        i = d.argmin(1)
        self.distances += np.sqrt(d[np.arange(len(i)), i]).tolist()
        return (torch.from_numpy(self.y[i]),)


@pytest.mark.parametrize("role", ["follower", "leader"])
def test_replaying_the_recording_makes_the_recorded_samples(prepared3, role):
    couples = load_couples(str(prepared3))
    assert len(couples) == 2 and {c.mirror for c in couples} == {False, True}   # one training take, mirrored
    step = Replay(prepared3, role)
    off = load_offsets(str(prepared3), role, "cpu").double().numpy()
    s = own_rollout_samples(step, couples, off, role, every=40, horizon=6, temperatures=(1.0,),
                            gen=torch.Generator().manual_seed(0))
    starts = sum(len(range(feat.HISTORY + 1, c.follower.frames - feat.HISTORY - 2 - 6, 40)) for c in couples)
    assert len(s["input"]) == starts * 5          # the first frame of each is the recording: skipped
    assert s["mirror"].sum() == len(s["input"]) / 2
    # Every input the replay read was a recorded one (the float32 prepared arrays round at 1e-6 m).
    assert max(step.distances) < 1e-2
    # ... and each sample is that frame's prepared sample: input and target.
    d = ((s["input"][:, None, :].astype(np.float64) - step.x[None]) ** 2).sum(-1)
    i = d.argmin(1)
    assert np.abs(s["output"] - step.y[i]).max() < 1e-4
    assert np.sqrt(d.min(1)).max() < 1e-2


def test_a_network_drifts_from_the_recording_and_trains_on_it(prepared3, tmp_path, capsys):
    """The smoke recipe with own rollouts: samples made at its epochs, and they are not the recording."""
    cfg = T.smoke(T.MODELS["follower"])
    cfg = T.replace(cfg, epochs=3, own_rollouts_from=1, own_rollouts_every=1, own_rollouts_stride=20,
                    own_rollouts_horizon=8)
    r = T.train_model("follower", cfg, str(prepared3), str(tmp_path))
    h = json.loads((tmp_path / "follower" / "history.json").read_text())
    assert len(h["own_rollout_samples"]) == 2 and min(h["own_rollout_samples"]) > 0
    assert "own rollouts at epoch 1" in capsys.readouterr().out
    assert np.isfinite(r["val_mse"])


def test_own_rollouts_need_the_training_couples(prepared3, tmp_path):
    for f in prepared3.iterdir():
        if f.name != "train_tracks.npz":
            (tmp_path / f.name).symlink_to(f)
    with pytest.raises(TrainError, match="train_tracks.npz not found.*training.data.prepare"):
        load_couples(str(tmp_path))
