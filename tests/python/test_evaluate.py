"""python -m training.evaluation.evaluate end to end on one short take with the smoke models.

The ground-truth row runs through the very same loop (recorded outputs fed to apply_output), so
it must reproduce the recording: MPJPE 0 and FID ~0. That checks the rollout bookkeeping, the
feature windows and the encoder path in one go.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from training.evaluation import evaluate as E
from training.evaluation.evaluate_inputs import load_eval_takes, window
from training.evaluation.evaluate_rollouts import bend_plan
from training.mirror.features import FUTURE_OFFSETS, follower_input, output_features
from training.mirror.rollout import NOW

from conftest import SMALL_TAKES

HEADLINE = {"mpjpe_cm", "fid", "diversity", "codebook_error", "foot_skate_cm", "jitter"}
FRAMES = 40


def args(exported, data3, out, *extra):
    return ["--data", str(data3), "--takes", SMALL_TAKES["test"], "--models", str(exported["models"]),
            "--train-data", str(data3), "--out", str(out), "--encoder-cache", str(out.parent / "encoder"),
            "--encoder-epochs", "2", "--max-frames", str(FRAMES), "--quiet", *extra]


@pytest.fixture(scope="module")
def result(exported, data3, tmp_path_factory):
    out = tmp_path_factory.mktemp("eval") / "out"
    rc = E.main(args(exported, data3, out, "--seeds", "0,1", "--temperatures", "0.5,0",
                     "--conditions", "playback:rot+30,playback:side-0.5,mm,model:rot-60"))
    assert rc == 0
    return out, json.loads((out / "metrics.json").read_text())


def test_schema(result):
    out, r = result
    assert r["takes"] == [SMALL_TAKES["test"]]
    assert r["frames"] == FRAMES
    assert set(r["methods"]) == {"ours", "ccm", "motion_matching", "ground_truth"}
    for name in ("ours", "ccm", "motion_matching"):
        assert HEADLINE <= set(r["methods"][name]), name
        for k in HEADLINE - {"codebook_error"}:
            assert isinstance(r["methods"][name][k], float), (name, k)
    assert isinstance(r["methods"]["ground_truth"]["diversity"], float)
    # The evaluation files are there: codebook error is computed, in [0, 1].
    for name in ("ours", "ccm", "motion_matching"):
        assert 0.0 <= r["methods"][name]["codebook_error"] <= 1.0
    p = r["protocols"]
    assert set(p) == {"teacher_forced", "rollout", "controlled"}
    assert len(p["rollout"]["ours"]["runs"]) == 4                # 2 seeds x 2 temperatures
    assert set(p["rollout"]["ours"]["by_temperature"]) == {"0.5", "0"}
    assert len(p["rollout"]["motion_matching"]["runs"]) == 1     # deterministic
    assert set(p["controlled"]) == {"playback:rot+30", "playback:side-0.5", "mm", "model:rot-60"}
    for cond in p["controlled"].values():
        for m in cond.values():
            assert {"foot_skate_cm", "jitter", "fid", "fid_drift", "distance_to_leader", "divergence"} <= set(m)
            assert 0.0 <= m["divergence"] <= 1.0
    md = (out / "metrics.md").read_text()
    assert "| method | MPJPE cm" in md and "| ours |" in md and "## Controlled" in md
    # Her rhythm at the count she hears, beside the recording's own (rhythm.py's measures).
    for name in ("ours", "ccm", "motion_matching", "ground_truth"):
        m = r["methods"][name]
        assert -1.0 <= m["on_beat"] <= 1.0 and 0.0 <= m["together"] <= 1.0 and 0.0 <= m["pulse"] <= 1.0, name
    assert "| method | pulse | on the beat | together |" in md


def test_ground_truth_against_itself(result):
    _, r = result
    gt = r["methods"]["ground_truth"]
    assert gt["mpjpe_cm"] == 0.0
    assert gt["fid"] == pytest.approx(0.0, abs=1e-6)
    assert gt["rollout_mpjpe_cm"] < 1e-6 and gt["root_error_m"] < 1e-6
    assert gt["diversity"] > 0
    # A played-back follower is where the recording is, whatever the leader's plan says.
    bent = r["protocols"]["controlled"]["playback:rot+30"]["ground_truth"]
    assert bent["fid"] == pytest.approx(0.0, abs=1e-6)


def test_seeds_and_temperatures_matter(result):
    _, r = result
    runs = r["protocols"]["rollout"]["ours"]["runs"]
    zero = [x for x in runs if x["temperature"] == 0]
    # Temperature 0 is the argmax: both seeds give the same motion.
    assert zero[0]["mpjpe_cm"] == pytest.approx(zero[1]["mpjpe_cm"], rel=1e-9)


def test_codebook_error_comes_from_the_exported_files(result, exported, data3):
    """ours: the int8 step model's code at temperature 0 against the code of its fp32 output
    encoder file, which is the trained output encoder (torch) to float rounding."""
    import torch
    from training.evaluation import metrics as M
    from training.mirror.rollout import OnnxPolicy
    from training.learning.runs import load_run
    _, r = result
    take = load_eval_takes(str(data3), [SMALL_TAKES["test"]], FRAMES, None)[0]
    x = follower_input(take.lead, take.follow, take.frames, take.figure(take.frames)).astype(np.float32)   # as evaluate reads it
    y = output_features(take.follow, take.frames).astype(np.float32)
    run = load_run(exported["runs"] / "follower", str(exported["prepared"]))
    with torch.no_grad():
        target = run.model.logits(torch.from_numpy(x), torch.from_numpy(y)).target.numpy()
    c, d = run.cfg.channels, run.cfg.classes
    target = target.reshape(len(x), c, d).argmax(-1)
    estimate = OnnxPolicy(exported["models"] / "follower.onnx")(x, 0.0, np.random.default_rng(0))["code"]
    expected = M.codebook_error(M.one_hot(target, d), M.one_hot(estimate, d))
    assert r["methods"]["ours"]["codebook_error"] == pytest.approx(expected, abs=2 / (c * d) / len(x) + 1e-12)


def copy_models(exported, tmp_path):
    import shutil
    dst = tmp_path / "models"
    shutil.copytree(exported["models"], dst)
    return dst


def short_args(exported, data3, out, models):
    a = args(exported, data3, out, "--seeds", "0", "--temperatures", "0.5", "--conditions", "")
    a[a.index("--models") + 1] = str(models)
    return a


def test_codebook_is_null_without_evaluation_files(exported, data3, tmp_path):
    models = copy_models(exported, tmp_path)
    for f in (models / "eval").iterdir():
        f.unlink()
    out = tmp_path / "out"
    assert E.main(short_args(exported, data3, out, models) + ["--methods", "ours,motion_matching"]) == 0
    r = json.loads((out / "metrics.json").read_text())
    assert r["methods"]["ours"]["codebook_error"] is None
    assert r["methods"]["motion_matching"]["codebook_error"] is None
    assert isinstance(r["methods"]["ours"]["fid"], float)          # the rest is still measured
    assert "follower.output_encoder.onnx not found" in (out / "metrics.md").read_text()


@pytest.mark.parametrize("mix", ["eval file", "step model", "manifest"])
def test_files_of_different_trainings_are_refused(exported, data3, tmp_path, capsys, mix):
    """CCM's files stand in for another training of ours: each way of mixing is one error line."""
    models = copy_models(exported, tmp_path)
    if mix == "eval file":
        (models / "eval" / "follower_ccm.output_encoder.onnx").replace(models / "eval" / "follower.output_encoder.onnx")
    elif mix == "step model":
        (models / "follower_ccm.onnx").replace(models / "follower.onnx")
    else:
        m = json.loads((models / "manifest.json").read_text())
        m["models"]["follower"]["fingerprint"] = m["models"]["follower_ccm"]["fingerprint"]
        (models / "manifest.json").write_text(json.dumps(m))
    assert E.main(short_args(exported, data3, tmp_path / "out", models)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("error: ") and "different trainings" in err[-1] and "python -m training.learning.export" in err[-1]
    assert not (tmp_path / "out" / "metrics.json").exists()


@pytest.mark.parametrize("change, message", [
    (("--takes", "99"), "unknown take"),
    (("--models", "/nonexistent/models"), "not found"),
    (("--methods", "ours,nope"), "not available"),
    (("--conditions", "sideways"), "condition"),
])
def test_bad_input_is_one_line_and_exit_2(exported, data3, tmp_path, capsys, change, message):
    a = args(exported, data3, tmp_path / "out")
    if change[0] in a:
        a[a.index(change[0]) + 1] = change[1]
    else:
        a += list(change)
    assert E.main(a) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("error: ") and message in err[-1]
    assert not (tmp_path / "out" / "metrics.json").exists()


def test_bend_plan_turns_and_shifts_the_future_keys(take_tracks):
    lead, _ = take_tracks
    t = 100
    w = window(lead, t)
    turned = window(lead, t)
    bend_plan(turned, ("rot", 90.0))
    keys = NOW + FUTURE_OFFSETS
    rel, rel_t = w.root[keys] - w.root[NOW], turned.root[keys] - turned.root[NOW]
    np.testing.assert_allclose(np.linalg.norm(rel, axis=-1), np.linalg.norm(rel_t, axis=-1))
    # Turning by +90 degrees maps a direction (sin h, cos h) to (cos h, -sin h).
    np.testing.assert_allclose(rel_t, np.stack([rel[:, 1], -rel[:, 0]], -1), atol=1e-12)
    np.testing.assert_array_equal(turned.root[:NOW + 1], w.root[:NOW + 1])   # past untouched
    shifted = window(lead, t)
    bend_plan(shifted, ("side", 0.6))
    np.testing.assert_allclose(np.linalg.norm(shifted.root[keys[-1]] - w.root[keys[-1]]), 0.6)


def test_plausibility_of_the_free_run(result, exported):
    """Every method gets the follower's implausible share and worst second against the manifest's
    range; the ground-truth row is the recording itself, judged the same way."""
    from training.evaluation import plausibility as P
    _, r = result
    manifest = json.loads((exported["models"] / "manifest.json").read_text())
    assert "plausibility" in manifest
    for name in ("ours", "ccm", "motion_matching", "ground_truth"):
        m = r["methods"][name]
        assert 0.0 <= m["implausible"] <= 1.0 and 0.0 <= m["worst_second"] <= 1.0, name
        assert m["worst_second"] >= m["implausible"] or m["implausible"] == 0.0
    runs = r["protocols"]["rollout"]["ours"]["runs"]
    assert r["protocols"]["rollout"]["ours"]["by_temperature"]["0.5"]["worst_second"] == \
        max(i["worst_second"] for i in runs if i["temperature"] == 0.5)
