"""training.evaluation.plots: the pure helpers, and main() on missing / partial inputs (no real models needed)."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import torch

from training.mirror import features as feat
from training.evaluation import metrics as M
from training.evaluation import plots as P
from training.evaluation.plots.codebook import FOLLOWER_IN, rotate_partner_future
from training.evaluation.plots.common import FILES, per_frame_codebook_error
from training.evaluation.plots.sweep import log_positions
from training.evaluation.plots.tsne import evenly, knn_mixing, log_softmax_channels

SL = FOLLOWER_IN["partner_trajectory_future"]


def _inputs(rng, n=7):
    return rng.normal(size=(n, feat.INPUT_SIZE))


def test_rotation_zero_is_identity(rng):
    x = _inputs(rng)
    np.testing.assert_array_equal(rotate_partner_future(x, 0.0), x)
    np.testing.assert_allclose(rotate_partner_future(x, 360.0), x, atol=1e-12)


def test_rotation_preserves_lengths_and_touches_only_the_future_path(rng):
    x = _inputs(rng)
    for deg in (30.0, -60.0, 137.0):
        r = rotate_partner_future(x, deg)
        keys, rk = x[:, SL].reshape(-1, feat.KEYS, 4), r[:, SL].reshape(-1, feat.KEYS, 4)
        for i in (0, 2):   # positions and forward directions
            np.testing.assert_allclose(np.linalg.norm(rk[..., i:i + 2], axis=-1),
                                       np.linalg.norm(keys[..., i:i + 2], axis=-1), rtol=1e-12)
        # A rigid turn: the angle between a key's position and its forward stays the same.
        np.testing.assert_allclose((rk[..., 0:2] * rk[..., 2:4]).sum(-1), (keys[..., 0:2] * keys[..., 2:4]).sum(-1),
                                   rtol=1e-9, atol=1e-12)
        outside = np.ones(feat.INPUT_SIZE, bool)
        outside[SL] = False
        np.testing.assert_array_equal(r[:, outside], x[:, outside])
        np.testing.assert_allclose(rotate_partner_future(r, -deg), x, atol=1e-12)
    assert not np.shares_memory(rotate_partner_future(x, 10.0), x)


def test_rotation_sense_matches_heading_convention():
    """Heading h faces (sin h, cos h): a key ahead on +z turned by +90 lies on +x and faces +x."""
    x = np.zeros((1, feat.INPUT_SIZE))
    keys = np.zeros((feat.KEYS, 4))
    keys[:, 1], keys[:, 3] = np.arange(1, feat.KEYS + 1), 1.0       # straight ahead, facing ahead
    x[0, SL] = keys.reshape(-1)
    r = rotate_partner_future(x, 90.0)[0, SL].reshape(feat.KEYS, 4)
    np.testing.assert_allclose(r[:, 0], np.arange(1, feat.KEYS + 1), atol=1e-12)
    np.testing.assert_allclose(r[:, 1], 0, atol=1e-12)
    h = math.atan2(r[0, 2], r[0, 3])
    assert h == pytest.approx(math.pi / 2)


def test_per_frame_codebook_error_is_the_one_hot_mse(rng):
    c, d = 8, 32
    t = rng.integers(0, d, (50, c))
    e = t.copy()
    flip = rng.random((50, c)) < 0.3
    e[flip] = (e[flip] + 1) % d
    per = per_frame_codebook_error(t, e, d)
    assert per.shape == (50,)
    assert per.mean() == pytest.approx(M.codebook_error(M.one_hot(t, d), M.one_hot(e, d)))
    np.testing.assert_allclose(per, 2 * flip.sum(1) / (c * d))
    assert np.all(per_frame_codebook_error(t, t, d) == 0)


def test_knn_mixing(rng):
    a, b = rng.normal(size=(150, 5)), rng.normal(size=(150, 5))
    assert knn_mixing(a, b) == pytest.approx(1.0, abs=0.15)
    assert knn_mixing(a, b + 100.0) == 0.0


def test_log_positions_and_log_softmax():
    pos, zero = log_positions([0.0, 0.001, 0.01, 0.1])
    assert zero == pytest.approx(1e-4)
    np.testing.assert_allclose(pos, [1e-4, 0.001, 0.01, 0.1])
    pos, zero = log_positions([0.0])
    assert pos[0] == zero > 0
    logits = np.random.default_rng(0).normal(size=(3, 4 * 5)) * 5
    ls = log_softmax_channels(logits, 4).reshape(3, 4, 5)
    np.testing.assert_allclose(np.exp(ls).sum(-1), 1.0)
    np.testing.assert_allclose(log_softmax_channels(logits + 7.0, 4), ls.reshape(3, -1))   # offset-free


def test_evenly():
    assert list(evenly(5, 10)) == [0, 1, 2, 3, 4]
    idx = evenly(972, 500)
    assert len(idx) == 500 and idx[0] == 0 and idx[-1] == 971 and np.all(np.diff(idx) > 0)


def _missing_args(tmp_path):
    nowhere = tmp_path / "nowhere"
    return ["--prepared", str(nowhere), "--runs", str(nowhere), "--sweep", str(nowhere), "--models", str(nowhere),
            "--data", str(nowhere), "--out", str(tmp_path / "out")]


def test_main_without_inputs_exits_with_a_message(tmp_path, capsys):
    rc = P.main(_missing_args(tmp_path))
    err = capsys.readouterr().err
    assert rc == 2
    assert "error: no figure could be made" in err
    assert "not found" in err and "Traceback" not in err
    for f in FILES.values():
        assert f"skipped {f}" in err
    assert not (tmp_path / "out").exists()


def test_main_rejects_unknown_figure(tmp_path):
    with pytest.raises(SystemExit) as e:
        P.main(_missing_args(tmp_path) + ["--only", "tsne,nope"])
    assert e.value.code == 2


def _fake_run(folder, stage, epochs, lg, lc=10.0):
    folder.mkdir(parents=True)
    hist = {"val_mse": list(np.linspace(0.8, 0.4, epochs)), "val_codebook": list(np.linspace(0.05, 0.02 + lg / 100, epochs))}
    torch.save({"stage": stage, "epoch": epochs, "history": hist,
                "config": {"lambda_generator": lg, "lambda_codebook": lc}}, folder / "checkpoint.pt")
    if stage == "done":
        (folder / "history.json").write_text(json.dumps({"seconds": 1.0, **hist}))


def test_curves_and_sweep_from_partial_runs(tmp_path, capsys):
    runs, sweep = tmp_path / "runs", tmp_path / "sweep"
    _fake_run(runs / "follower", "done", 5, 0.01)
    _fake_run(runs / "follower_no_gan", "done", 5, 0.0)
    _fake_run(runs / "follower_ccm", "matching", 3, 0.01)        # still training: a curve, no sweep point
    _fake_run(sweep / "lg1" / "follower", "done", 5, 1.0)
    (sweep / "lg0.1" / "follower").mkdir(parents=True)            # not started: a note
    out = tmp_path / "out"
    rc = P.main(["--only", "curves,sweep", "--runs", str(runs), "--sweep", str(sweep), "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0
    assert (out / FILES["curves"]).stat().st_size > 10_000
    assert (out / FILES["sweep"]).stat().st_size > 10_000
    assert "λG 0 / λC 10 = 0:" in text and "λG 1 / λC 10 = 0.1:" in text
    assert "lg0.1/follower: no checkpoint yet" in text
    assert "(still training)" in text and "follower_small" in text   # listed as not available
