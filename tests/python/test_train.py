"""python -m training.learning.train: smoke runs of the shipped models, resume, bad input, DDP (2 CPU
processes). All on 3 prepared takes in tmp (conftest.prepared3)."""
from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch

from training.mirror import features as feat
from training.learning import train as T

from conftest import REPO



def run_main(capsys, *args):
    rc = T.main(list(map(str, args)))
    out, err = capsys.readouterr()
    return rc, out, err


def error_line(err: str) -> str:
    lines = [l for l in err.replace("\r", "\n").splitlines() if l.strip()]
    assert lines and lines[-1].startswith("error: "), err
    assert sum(l.startswith("error:") for l in lines) == 1, err
    return lines[-1]


# ---------------------------------------------------------------- smoke runs

@pytest.mark.parametrize("name", T.SHIPPED)
def test_smoke_training_writes_its_outputs(smoke_runs, name):
    run = smoke_runs / name
    assert (run / "losses.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    h = json.loads((run / "history.json").read_text())
    smoke = T.smoke(T.MODELS[name])
    assert len(h["val_mse"]) == smoke.epochs == 2
    assert len(h["reconstruction"]) == 2 and len(h["val_codebook"]) == 2
    has_intention = smoke.model.intention
    assert len(h["intention_train"]) == (1 if has_intention else 0)
    assert all(math.isfinite(v) for k in ("val_mse", "reconstruction", "codebook", "generator") for v in h[k])
    assert h["seconds"] > 0
    ck = torch.load(run / "checkpoint.pt", map_location="cpu", weights_only=False)
    assert ck["stage"] == "done" and ck["epoch"] == 2 and ck["name"] == name
    assert ck["config"]["model"] == smoke.model.to_dict()
    assert {"predictor", "matching", "disc", "opt_p", "opt_g", "opt_d"} <= set(ck)


def test_resume_continues_an_interrupted_run(prepared3, tmp_path, monkeypatch, capsys):
    """Kill the run in its second matching epoch (validation raises), then --resume: it picks up
    at matching epoch 1 with the saved intention predictor and history instead of starting over."""
    calls = {"n": 0}
    real_validate = T.validate

    def crashing_validate(*a, **k):
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt("simulated crash")
        return real_validate(*a, **k)

    monkeypatch.setattr(T, "validate", crashing_validate)
    args = ["--model", "follower", "--smoke", "--prepared", prepared3, "--runs", tmp_path]
    with pytest.raises(KeyboardInterrupt):
        T.main(list(map(str, args)))
    monkeypatch.setattr(T, "validate", real_validate)
    ckpt = tmp_path / "follower" / "checkpoint.pt"
    crashed = torch.load(ckpt, map_location="cpu", weights_only=False)
    assert (crashed["stage"], crashed["epoch"]) == ("matching", 1)
    assert not (tmp_path / "follower" / "history.json").exists()
    capsys.readouterr()

    rc, out, _ = run_main(capsys, *args, "--resume")
    assert rc == 0
    assert "resumed at matching epoch 1" in out
    assert "intention 1/1" not in out            # stage 1 is not trained again
    done = torch.load(ckpt, map_location="cpu", weights_only=False)
    assert (done["stage"], done["epoch"]) == ("done", 2)
    h = json.loads((tmp_path / "follower" / "history.json").read_text())
    assert len(h["val_mse"]) == 2 and h["val_mse"][0] == crashed["history"]["val_mse"][0]
    assert h["intention_train"] == crashed["history"]["intention_train"]
    for k, v in crashed["predictor"].items():     # the frozen predictor came from the checkpoint
        assert torch.equal(v, done["predictor"][k]), k


def test_resume_of_a_finished_run_changes_nothing(smoke_runs, prepared3, tmp_path, capsys):
    shutil.copytree(smoke_runs / "follower_ccm", tmp_path / "follower_ccm")
    before = torch.load(tmp_path / "follower_ccm" / "checkpoint.pt", map_location="cpu", weights_only=False)
    rc, out, _ = run_main(capsys, "--model", "follower_ccm", "--smoke", "--prepared", prepared3, "--runs", tmp_path, "--resume")
    assert rc == 0 and "resumed at done epoch 2" in out
    after = torch.load(tmp_path / "follower_ccm" / "checkpoint.pt", map_location="cpu", weights_only=False)
    for k, v in before["matching"].items():
        assert torch.equal(v, after["matching"][k]), k


# ---------------------------------------------------------------- bad input

def test_missing_prepared_data(tmp_path, capsys):
    rc, _, err = run_main(capsys, "--model", "follower", "--smoke", "--prepared", tmp_path / "none", "--runs", tmp_path / "out")
    assert rc == 2
    line = error_line(err)
    assert "train.npz not found" in line and "training.data.prepare" in line


def test_old_flag_names_still_work_with_a_note(tmp_path, capsys):
    """train --data / --out were renamed --prepared / --runs (training/data/folders.py): the old names
    are hidden aliases that say so."""
    rc, _, err = run_main(capsys, "--model", "follower", "--smoke", "--data", tmp_path / "none", "--out", tmp_path / "out")
    assert rc == 2
    assert "note: --data is now --prepared" in err and "note: --out is now --runs" in err
    assert "none/train.npz not found" in error_line(err)


def test_help_shows_the_folder_vocabulary(capsys):
    with pytest.raises(SystemExit):
        T.main(["--help"])
    out = capsys.readouterr().out
    assert "--prepared DIR" in out and "--runs DIR" in out
    assert "--data" not in out and "--out" not in out      # hidden aliases


def test_mismatched_feature_sizes(tmp_path, capsys):
    data = tmp_path / "data"
    data.mkdir()
    n = 10
    arrays = {f"{role}_{k}": np.zeros((n, w), np.float32)
              for role in ("follower", "leader")
              for k, w in (("input", 600), ("output", feat.OUTPUT_SIZE), ("intention", feat.INTENTION_SIZE))}
    for split in ("train", "validation"):
        np.savez(data / f"{split}.npz", **arrays)
    rc, _, err = run_main(capsys, "--model", "follower", "--smoke", "--prepared", data, "--runs", tmp_path / "out")
    assert rc == 2
    line = error_line(err)
    assert "follower input has 600 features" in line and "expects 817" in line and "re-run training.data.prepare" in line


@pytest.mark.parametrize("damage", ["truncated", "foreign"])
def test_unreadable_prepared_data(prepared3, tmp_path, capsys, damage):
    """train.npz cut short (prepare writes it in place, so an interrupted prepare leaves this) or
    an npz from something else: bad input like the cases above, so exit 2 with one 'error:'
    line naming the file, not a BadZipFile / KeyError traceback."""
    data = tmp_path / "data"
    shutil.copytree(prepared3, data)
    if damage == "truncated":
        good = (prepared3 / "train.npz").read_bytes()
        (data / "train.npz").write_bytes(good[:len(good) // 3])
    else:
        np.savez(data / "train.npz", x=np.zeros(3))
    rc, _, err = run_main(capsys, "--model", "follower", "--smoke", "--prepared", data, "--runs", tmp_path / "out")
    assert rc == 2
    assert "train.npz" in error_line(err)


@pytest.mark.parametrize("damage", ["garbage", "truncated"])
def test_corrupt_checkpoint_is_reported_and_kept(smoke_runs, prepared3, tmp_path, capsys, damage):
    run = tmp_path / "follower"
    run.mkdir()
    ckpt = run / "checkpoint.pt"
    if damage == "garbage":
        ckpt.write_bytes(b"this is not a checkpoint\x00\xff" * 100)
    else:   # a half-written file, as a crash mid-copy would leave
        good = (smoke_runs / "follower" / "checkpoint.pt").read_bytes()
        ckpt.write_bytes(good[:len(good) // 2])
    before = ckpt.read_bytes()
    rc, _, err = run_main(capsys, "--model", "follower", "--smoke", "--prepared", prepared3, "--runs", tmp_path, "--resume")
    assert rc == 2
    line = error_line(err)
    assert "checkpoint.pt" in line and "unreadable" in line
    assert ckpt.read_bytes() == before, "the damaged checkpoint was overwritten"
    assert not (run / "history.json").exists()


def test_resume_with_another_configuration_is_refused(smoke_runs, prepared3, tmp_path, capsys):
    shutil.copytree(smoke_runs / "follower", tmp_path / "follower")
    before = (tmp_path / "follower" / "checkpoint.pt").read_bytes()
    rc, _, err = run_main(capsys, "--model", "follower", "--smoke", "--epochs", "3", "--prepared", prepared3,
                          "--runs", tmp_path, "--resume")
    assert rc == 2
    assert "another configuration" in error_line(err)
    assert (tmp_path / "follower" / "checkpoint.pt").read_bytes() == before


def test_no_model_named_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as e:
        T.main([])
    assert e.value.code == 2
    assert "--model" in capsys.readouterr().err


# ---------------------------------------------------------------- leader control augmentation

def test_control_augmentation_turns_the_path_rigidly():
    """With no position noise the control path is only turned about the root: distances from the
    root and unit forward vectors are kept, the turn stays within control_rotation, and nothing
    outside the control block changes."""
    g = torch.Generator().manual_seed(0)
    x = torch.randn(64, feat.INPUT_SIZE)
    sl = feat.block_slices(feat.LEADER_INPUT_LAYOUT)["control"]
    keys = torch.zeros(64, 6, 4)
    keys[..., 1] = torch.arange(1, 7) * 0.2        # straight ahead
    keys[..., 3] = 1.0                             # facing ahead
    x[:, sl] = keys.reshape(64, -1)
    cfg = replace(T.TrainConfig(), control_noise=0.0, control_rotation=15.0)
    y = T.augment_control(x, cfg, g)
    torch.testing.assert_close(y[:, :sl.start], x[:, :sl.start])
    k = y[:, sl].reshape(64, 6, 4)
    torch.testing.assert_close(k[..., :2].norm(dim=-1), keys[..., :2].norm(dim=-1))
    torch.testing.assert_close(k[..., 2:].norm(dim=-1), torch.ones(64, 6))
    angle = torch.atan2(k[..., 0], k[..., 1])
    assert angle.abs().max() <= math.radians(15) + 1e-6 and angle.abs().max() > math.radians(5)
    torch.testing.assert_close(angle, torch.atan2(k[..., 2], k[..., 3]))   # path and facing turn together


# ---------------------------------------------------------------- data parallel

@pytest.mark.slow
def test_ddp_two_cpu_processes(prepared3, tmp_path):
    torchrun = Path(sys.executable).with_name("torchrun")
    assert torchrun.exists(), torchrun
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    r = subprocess.run([str(torchrun), "--standalone", "--nproc_per_node", "2", "-m", "training.learning.train",
                        "--model", "follower", "--smoke", "--prepared", str(prepared3), "--runs", str(tmp_path)],
                       cwd=REPO, env=env, capture_output=True, text=True, timeout=3600)   # a hang guard, not a speed check
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "on cpu x2" in r.stdout
    h = json.loads((tmp_path / "follower" / "history.json").read_text())
    assert len(h["val_mse"]) == 2 and all(math.isfinite(v) for v in h["val_mse"])
    ck = torch.load(tmp_path / "follower" / "checkpoint.pt", map_location="cpu", weights_only=False)
    assert ck["stage"] == "done"


# ---------------------------------------------------------------- validation table

def test_validation_table_of_smoke_runs(smoke_runs, prepared3, capsys):
    """training.learning.validation: one row per run; the target-code MPJPE equals train.validate's when
    the estimated code is replaced by the target one, and both are in a plausible range."""
    from training.learning import validation as V
    runs = [smoke_runs / "follower", smoke_runs / "follower_ccm"]
    assert V.main([str(r) for r in runs] + ["--prepared", str(prepared3)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 4 and out[2].startswith(f"| {runs[0]} | yes | 2 |") and "| no | 2 |" in out[3]
    row = V.measure(runs[0], str(prepared3))
    assert 0 < row["mpjpe_target_cm"] < 100 and 0 < row["mpjpe_cm"] < 100
    assert 0 <= row["wrong_channels"] <= 2
    # codebook error = 2 x wrong channels / (C x D): the two ways of counting agree.
    assert math.isclose(row["codebook"], 2 * row["wrong_channels"] / 8, rel_tol=1e-5)
    # train.validate's MPJPE is the estimated-code one.
    import torch as _t
    from training.learning.models import CodebookMatching, IntentionPredictor, ModelConfig
    ck = _t.load(runs[0] / "checkpoint.pt", map_location="cpu", weights_only=False)
    cfg = ModelConfig(**ck["config"]["model"])
    p, m = IntentionPredictor(cfg), CodebookMatching(cfg)
    p.load_state_dict(ck["predictor"]); m.load_state_dict(ck["matching"])
    stats, val = T.load_stats(prepared3, "follower"), T.load_split(prepared3, "validation", "follower")
    norm = lambda a, k: ((_t.from_numpy(a) - stats[f"{k}_mean"]) / stats[f"{k}_std"]).float()
    _, cb, mpjpe = T.validate(p, m, cfg, norm(val["input"], "input"), norm(val["output"], "output"), "cpu", stats)
    assert math.isclose(mpjpe, row["mpjpe_cm"], rel_tol=1e-4) and math.isclose(cb, row["codebook"], rel_tol=1e-4)


def test_validation_refuses_unfinished_and_missing_runs(smoke_runs, prepared3, tmp_path, capsys):
    from training.learning import validation as V
    assert V.main([str(tmp_path / "none"), "--prepared", str(prepared3)]) == 2
    assert "checkpoint.pt not found" in capsys.readouterr().err
    run = tmp_path / "half"
    run.mkdir()
    ck = torch.load(smoke_runs / "follower" / "checkpoint.pt", map_location="cpu", weights_only=False)
    ck["stage"] = "matching"
    torch.save(ck, run / "checkpoint.pt")
    assert V.main([str(run), "--prepared", str(prepared3)]) == 2
    assert "has not finished" in capsys.readouterr().err


def test_moving_the_partner_closer_shifts_its_whole_window_rigidly(prepared3):
    from training.data.prepared import load_split
    x = torch.from_numpy(load_split(str(prepared3), "train", "follower")["input"][:2000]).float()
    xm, moved = T.move_partner_closer(x, 0.5, torch.Generator().manual_seed(0))
    assert 0.2 < moved.float().mean() < 0.56     # half drawn, minus those already closer
    torch.testing.assert_close(xm[~moved], x[~moved], rtol=0, atol=0)
    sl = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)
    pose = lambda t, b: t[:, sl[b]].reshape(len(t), feat.N_JOINTS, 12)
    hips = (pose(xm, "self_pose")[:, 0, [0, 2]] - pose(xm, "partner_pose")[:, 0, [0, 2]]).norm(dim=-1)[moved]
    lo, hi = T.PROXIMITY_HIP_DISTANCE
    assert lo - 1e-5 <= hips.min() and hips.max() <= hi + 1e-5
    # One shift for every partner position; heights, velocities, directions and the own body stay.
    shift = pose(xm, "partner_pose")[moved][:, 0, [0, 2]] - pose(x, "partner_pose")[moved][:, 0, [0, 2]]
    keys = lambda t, b: t[:, sl[b]].reshape(len(t), -1, 4)[moved][..., :2]
    torch.testing.assert_close(keys(xm, "partner_trajectory_future") - keys(x, "partner_trajectory_future"),
                               shift[:, None].expand(-1, feat.KEYS, -1), rtol=0, atol=1e-5)
    torch.testing.assert_close(pose(xm, "partner_pose")[..., [1] + list(range(3, 12))],
                               pose(x, "partner_pose")[..., [1] + list(range(3, 12))], rtol=0, atol=0)
    for block in ("self_trajectory_past", "self_key_joints_past", "self_pose"):
        torch.testing.assert_close(xm[:, sl[block]], x[:, sl[block]], rtol=0, atol=0)


def test_command_line_overrides_change_only_what_was_given():
    import argparse
    unset = argparse.Namespace(**{k: None for k in T.OVERRIDES})
    base = T.MODELS["follower"]
    assert T.apply_overrides(base, unset) == base
    given = argparse.Namespace(**{**vars(unset), "seed": 3, "channels": 8, "intention_hidden": 64})
    cfg = T.apply_overrides(base, given)
    assert (cfg.seed, cfg.model.channels, cfg.model.intention_hidden) == (3, 8, 64)
    assert replace(cfg, seed=base.seed, model=base.model) == base


def test_state_dropout_hides_the_state_from_the_decoder_only():
    """state_keep 0 gives the decoder the mean pose (0 in normalized units) and nothing else: the
    same output as an input whose state columns are 0; 1 changes nothing."""
    import torch
    from training.learning.models import CodebookMatching, ModelConfig
    torch.manual_seed(0)
    m = CodebookMatching(ModelConfig(decoder_state=True, hidden=32, channels=2, classes=4)).eval()
    x = torch.randn(3, m.cfg.input_size)
    code = torch.nn.functional.one_hot(torch.tensor([[1, 2], [0, 3], [3, 3]]), 4).float().reshape(3, -1)
    zeroed = x.clone()
    zeroed[:, m.state_columns] = 0
    keep = torch.tensor([[0.0], [1.0], [0.0]])
    out = m.decode(code, x, keep)
    assert torch.allclose(out[[0, 2]], m.decode(code, zeroed)[[0, 2]])
    assert torch.allclose(out[1], m.decode(code, x)[1])
    assert not torch.allclose(m.decode(code, x)[0], m.decode(code, zeroed)[0])


def test_a_run_saved_before_a_model_field_existed_is_fine_tuned_and_resumed(smoke_runs, prepared3, tmp_path, capsys):
    """A checkpoint whose model config lacks a field added later (decoder_music) reads as that
    field's default: it can be fine-tuned from (--init-from) and resumed, and another size cannot."""
    run = tmp_path / "old" / "follower"
    shutil.copytree(smoke_runs / "follower", run)
    ck = torch.load(run / "checkpoint.pt", map_location="cpu", weights_only=False)
    del ck["config"]["model"]["decoder_music"]
    torch.save(ck, run / "checkpoint.pt")
    rc, out, err = run_main(capsys, "--model", "follower", "--smoke", "--prepared", prepared3,
                            "--runs", tmp_path / "new", "--init-from", run)
    assert rc == 0, err
    assert "fine-tuning" in out
    shutil.copytree(run, tmp_path / "resumed" / "follower")
    rc, out, err = run_main(capsys, "--model", "follower", "--smoke", "--prepared", prepared3,
                            "--runs", tmp_path / "resumed", "--resume")
    assert rc == 0 and "resumed at done" in out, err
    ck["config"]["model"]["hidden"] = 7
    torch.save(ck, run / "checkpoint.pt")
    rc, _, err = run_main(capsys, "--model", "follower", "--smoke", "--prepared", prepared3,
                          "--runs", tmp_path / "other", "--init-from", run)
    assert rc == 2 and "not a finished run of the same model sizes" in err
