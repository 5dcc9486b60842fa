"""training/learning/distill.py and train --teacher: a step model read back from its int8 ONNX file
computes what the file computes, and a student distilled from it learns the teacher's codes.
Uses the session's smoke models (conftest.exported)."""
from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
import torch

from training.data.prepared import TrainError
from training.learning.distill import teacher_from_onnx
from training.learning.runs import load_run
from training.learning.train import MODELS, distill_terms, main
from training.mirror.policy import open_session


@pytest.fixture(scope="module")
def validation(exported):
    with np.load(exported["prepared"] / "validation.npz") as z:
        return {role: z[f"{role}_input"].astype(np.float32) for role in ("follower", "leader")}


@pytest.mark.parametrize("name", ["follower", "follower_ccm", "leader"])
def test_the_teacher_computes_what_its_onnx_file_computes(exported, validation, name):
    """Dequantized, the int8 weights give the file's codes wherever its activations' own int8
    rounding does not flip them (the int8-against-fp32 bound of test_export) and its outputs."""
    run = load_run(exported["runs"] / name, str(exported["prepared"]))
    teacher = teacher_from_onnx(exported["models"] / f"{name}.onnx", replace(run.cfg, hidden=7, intention_hidden=5))
    assert teacher.cfg.hidden == run.cfg.hidden
    if run.cfg.intention:
        assert teacher.cfg.intention_hidden == run.cfg.intention_hidden
    x = validation[run.cfg.role]
    noise = np.full((len(x), run.cfg.latent), 0.5, np.float32)
    got = open_session(exported["models"] / f"{name}.onnx").run(
        None, {"input": x, "temperature": np.zeros(1, np.float32), "noise": noise})
    with torch.no_grad():
        ref = teacher(torch.from_numpy(x), torch.zeros(1), torch.from_numpy(noise))
    agree = (got[-1] == ref[-1].numpy()).all(1)
    assert agree.mean() >= 0.9, f"{name}: {agree.mean():.1%} of rows with the file's codes"
    out, mine = got[0][agree], ref[0].numpy()[agree]
    assert np.linalg.norm(out - mine) / np.linalg.norm(out) < 0.01
    # and it is the trained network, not any network of those sizes
    with torch.no_grad():
        trained = run.model(torch.from_numpy(x), torch.zeros(1), torch.from_numpy(noise))
    assert (trained[-1].numpy() == ref[-1].numpy()).all(1).mean() >= 0.9


def test_a_teacher_of_other_sizes_is_refused(exported, tmp_path):
    cfg = MODELS["leader"].model   # 8 channels; the smoke files hold 2
    with pytest.raises(TrainError, match="configuration says"):
        teacher_from_onnx(exported["models"] / "leader.onnx", cfg)
    with pytest.raises(TrainError, match="no teacher model"):
        teacher_from_onnx(tmp_path / "leader.onnx", cfg)


def test_distillation_brings_the_student_to_the_teachers_codes(exported, validation, tmp_path):
    """train --teacher: from other initial weights (another seed), the student ends nearer the
    teacher (the KL of its code distribution, its decoder on the teacher's codes) than the same
    recipe trained from the recording alone, and the run records both terms."""
    prepared = exported["prepared"]
    common = ["--model", "leader", "--smoke", "--epochs", "4", "--seed", "5", "--prepared", str(prepared)]
    assert main(common + ["--teacher", str(exported["models"] / "leader.onnx"), "--runs", str(tmp_path / "distilled")]) == 0
    assert main(common + ["--runs", str(tmp_path / "alone")]) == 0
    x = torch.from_numpy(validation["leader"])
    distances = {}
    for kind in ("distilled", "alone"):
        run = load_run(tmp_path / kind / "leader", str(prepared))
        teacher = teacher_from_onnx(exported["models"] / "leader.onnx", run.cfg)
        xn = (x - run.stats["input_mean"]) / run.stats["input_std"]
        torch.manual_seed(0)
        with torch.no_grad():
            distances[kind] = [t.item() for t in distill_terms(teacher, run.matching, xn, run.predictor(xn))]
    assert distances["distilled"][0] < distances["alone"][0], distances
    assert distances["distilled"][1] < distances["alone"][1], distances
    history = json.loads((tmp_path / "distilled" / "leader" / "history.json").read_text())
    assert len(history["distill_codes"]) == 4 and len(history["distill_decoder"]) == 4
