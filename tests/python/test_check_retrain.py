"""training.evaluation.check_retrain: the comparison and its verdict (the retrain itself is not run here)."""
from __future__ import annotations

import json

from training.evaluation import check_retrain as C


def metrics(**ours):
    base = {"mpjpe_cm": 5.17, "codebook_error": 0.0242, "fid": 96.9, "rollout_mpjpe_cm": 14.36}
    return {"methods": {"ours": {**base, **ours}, "ccm": dict(base)}}


def test_within_and_outside_tolerance(tmp_path, capsys):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps(metrics()))
    b.write_text(json.dumps(metrics(mpjpe_cm=5.17 + 0.15, fid=120.0)))
    assert C.main(["--shipped-metrics", str(a), "--retrain-metrics", str(b)]) == 0
    out = capsys.readouterr().out
    assert "8 of 8 numbers within tolerance" in out and "| ours | fid | 96.9000 | 120.0000 |" in out
    b.write_text(json.dumps(metrics(codebook_error=0.03, rollout_mpjpe_cm=None)))
    assert C.main(["--shipped-metrics", str(a), "--retrain-metrics", str(b)]) == 1
    out = capsys.readouterr().out
    assert "outside: ours codebook_error, ours rollout_mpjpe_cm" in out


def test_identical_numbers_pass_and_bad_files_are_an_error(tmp_path, capsys):
    a = tmp_path / "a.json"
    a.write_text(json.dumps(metrics()))
    assert all(r["ok"] and r["difference"] == 0 for r in C.compare(metrics(), metrics()))
    assert C.main(["--shipped-metrics", str(a), "--retrain-metrics", str(tmp_path / "none.json")]) == 2
    assert "none.json: not a readable metrics.json" in capsys.readouterr().err


def test_models_compared_with_themselves(exported, data3, tmp_path, monkeypatch, capsys):
    """Both sides evaluated by training.evaluation.evaluate: the same files give the same numbers, and the
    manifests' fingerprints say the weights are identical."""
    from conftest import SMALL_TAKES
    monkeypatch.setattr(C, "EVALUATE", ["--takes", SMALL_TAKES["test"], "--methods", "ours,ccm", "--seeds", "0",
                                        "--temperatures", "0.5", "--conditions", "", "--max-frames", "30",
                                        "--encoder-epochs", "1", "--quiet"])
    models = str(exported["models"])
    assert C.main(["--data", str(data3), "--shipped", models, "--retrain", models, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "8 of 8 numbers within tolerance" in out
    assert "identical weights (same fingerprint): follower, follower_ccm, leader" in out
    assert (tmp_path / "shipped" / "metrics.json").exists() and (tmp_path / "retrain" / "metrics.json").exists()
