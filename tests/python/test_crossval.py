"""training.evaluation.crossval: folds that test every take once, the paired interval, and the whole loop
(prepare, train, export, evaluate, report) on small synthetic couples, resumed."""
from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from training.data.prepare import TEMPOS
from training.evaluation import crossval
from training.data.synthetic import write_couples

TAKES = [f"{i:02d}" for i in (1, 2, 3, 4, 6, 7, 9, 10, 11, 12, 13, 15)]


def test_each_take_is_tested_exactly_once_and_never_trained_on_in_its_fold():
    folds = crossval.make_folds(TAKES, 6)
    tested = [t for f in folds for t in f["test"]]
    assert sorted(tested) == sorted(TAKES)
    for f in folds:
        assert len(f["validation"]) == 1 and f["validation"][0] not in f["test"]
        assert not set(f["train"]) & (set(f["test"]) | set(f["validation"]))
        assert sorted(f["train"] + f["test"] + f["validation"]) == sorted(TAKES)


@pytest.mark.parametrize("k", [1, 7])
def test_impossible_fold_counts_are_refused(k):
    with pytest.raises(crossval.CrossvalError, match="--folds"):
        crossval.make_folds(TAKES, k)


def test_paired_interval_is_a_t_interval_over_folds_of_seed_means():
    m = "mpjpe_cm"
    a = {(0, 1): {m: 2.0}, (0, 2): {m: 0.0}, (1, 1): {m: 3.0}, (1, 2): {m: 3.0}, (2, 1): {m: 5.0}, (2, 2): {m: 5.0}}
    b = {k: {m: 1.0} for k in a}
    p = crossval.paired(a, b, [0, 1, 2], [1, 2], m)
    per_fold = [0.0, 2.0, 4.0]                       # seed means of a - b per fold
    assert p["per_fold"] == per_fold
    half = 4.302652729911275 * np.std(per_fold, ddof=1) / np.sqrt(3)   # t(0.975, 2 df)
    assert p["mean"] == pytest.approx(2.0)
    assert (p["low"], p["high"]) == pytest.approx((2.0 - half, 2.0 + half))
    assert p["relative"] == pytest.approx(2.0)        # against b's mean of 1
    del a[(2, 2)]
    assert crossval.paired(a, b, [0, 1, 2], [1, 2], m) is None   # a missing run is not averaged away


@pytest.mark.slow
def test_crossval_runs_every_fold_and_resumes(tmp_path):
    data = write_couples(tmp_path / "couples", {t: 720 for t in ("01", "02", "03", "04")}, seed=3)
    out = tmp_path / "cv"
    argv = ["--data", str(data), "--out", str(out), "--folds", "2", "--seeds", "1", "--smoke",
            "--jobs", "1", "--eval-seeds", "0", "--methods", "ours,ccm", "--quiet"]
    assert crossval.main(argv) == 0
    res = json.loads((out / "crossval.json").read_text())
    assert res["complete_folds"] == [0, 1]
    # The turn figures need turns: smoke models on synthetic couples may make none (then a
    # precision or a ratio is undefined and its comparison None, never a made-up number).
    figures = {"turns_ratio", "spin_ratio", "recall", "precision"}
    for name in ("ours - ccm",):
        for metric in crossval.METRICS:
            p = res["comparisons"][name][metric]
            if p is None and metric in figures:
                continue
            assert np.isfinite([p["mean"], p["low"], p["high"]]).all() and p["low"] <= p["mean"] <= p["high"]
    assert all(k in res["means"]["ours"] for k in figures | {"pulse_ratio", "on_beat", "together_ratio"})
    # One data folder per fold, with the tempo copies the shipped recipes read.
    with np.load(out / "fold0" / "data" / "train_tempo.npz") as z:
        assert sorted(set(z["tempo"].tolist())) == pytest.approx(TEMPOS)
    runs = out / "fold0" / "seed1" / "runs"
    configs = {r: torch.load(runs / r / "checkpoint.pt", weights_only=False)["config"]["tempo_copies"]
               for r in ("follower", "follower_ccm")}
    assert configs == {"follower": True, "follower_ccm": True}
    stamp = (out / "fold0" / "seed1" / "eval_follower" / "metrics.json").stat().st_mtime_ns
    assert crossval.main(argv) == 0                     # everything on disk: nothing is redone
    assert (out / "fold0" / "seed1" / "eval_follower" / "metrics.json").stat().st_mtime_ns == stamp
    assert json.loads((out / "crossval.json").read_text())["comparisons"] == res["comparisons"]


def test_unknown_method_is_a_one_line_error(tmp_path, capsys):
    data = write_couples(tmp_path / "couples", {t: 720 for t in ("01", "02", "03", "04")}, seed=3)
    assert crossval.main(["--data", str(data), "--out", str(tmp_path / "cv"), "--methods", "ours,mine"]) == 2
    assert "unknown mine" in capsys.readouterr().err


def test_a_report_before_any_fold_finished_has_no_intervals(tmp_path):
    plan = {"folds": crossval.make_folds(TAKES, 6), "methods": ["ours", "ccm"], "seeds": [1],
            "epochs": 20, "intention_epochs": 10, "smoke": False, "tempos": []}
    res = crossval.report(tmp_path, plan, 0.0)
    assert res["complete_folds"] == [] and res["comparisons"]["ours - ccm"]["fid"] is None
    assert "0 of 6 complete" in (tmp_path / "crossval.md").read_text()
