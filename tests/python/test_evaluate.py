"""python -m training.evaluate end to end on one short take with the smoke models.

The ground-truth row runs through the very same loop (recorded outputs fed to apply_output), so
it must reproduce the recording: MPJPE 0 and FID ~0. That checks the rollout bookkeeping, the
feature windows and the encoder path in one go.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from training import evaluate as E

from conftest import SMALL_TAKES

HEADLINE = {"mpjpe_cm", "fid", "diversity", "codebook_error", "foot_skate_cm", "jitter"}
FRAMES = 40


def args(exported, data3, out, *extra):
    return ["--data", str(data3), "--takes", SMALL_TAKES["test"], "--models", str(exported["models"]),
            "--runs", str(exported["runs"]), "--prepared", str(exported["prepared"]),
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
    # Checkpoints are there: codebook error is computed, in [0, 2/channels].
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


def test_codebook_is_null_without_checkpoints(exported, data3, tmp_path):
    out = tmp_path / "out"
    a = args(exported, data3, out, "--methods", "ours", "--seeds", "0", "--temperatures", "0.5",
             "--conditions", "")
    a[a.index("--runs") + 1] = str(tmp_path / "no-runs")
    assert E.main(a) == 0
    r = json.loads((out / "metrics.json").read_text())
    assert set(r["methods"]) == {"ours", "ground_truth"}
    assert r["methods"]["ours"]["codebook_error"] is None
    assert "no-runs" in (out / "metrics.md").read_text()


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
    w = E.window(lead, t)
    turned = E.window(lead, t)
    E.bend_plan(turned, ("rot", 90.0))
    keys = E.NOW + E.FUTURE_OFFSETS
    rel, rel_t = w.root[keys] - w.root[E.NOW], turned.root[keys] - turned.root[E.NOW]
    np.testing.assert_allclose(np.linalg.norm(rel, axis=-1), np.linalg.norm(rel_t, axis=-1))
    # Turning by +90 degrees maps a direction (sin h, cos h) to (cos h, -sin h).
    np.testing.assert_allclose(rel_t, np.stack([rel[:, 1], -rel[:, 0]], -1), atol=1e-12)
    np.testing.assert_array_equal(turned.root[:E.NOW + 1], w.root[:E.NOW + 1])   # past untouched
    shifted = E.window(lead, t)
    E.bend_plan(shifted, ("side", 0.6))
    np.testing.assert_allclose(np.linalg.norm(shifted.root[keys[-1]] - w.root[keys[-1]]), 0.6)
