"""The soak tool: its steering script and a short soak of the shipped models (CI's version of
the full 100 x 10 min run documented in docs/reliability.md)."""
import json
from pathlib import Path

import numpy as np
import pytest

from training.evaluation import duet, soak
from training.mirror.skeleton import FPS

MODELS = Path(__file__).resolve().parents[2] / "public" / "models"


def test_steering_script_has_idles_holds_and_reversals():
    sticks = duet.steering_script(np.random.default_rng(3), 20 * 60 * FPS)
    assert np.all(np.linalg.norm(sticks, axis=1) <= 1 + 1e-9)
    idle = ~sticks.any(1)
    assert 0.05 < idle.mean() < 0.6
    changes = np.flatnonzero(np.any(np.diff(sticks, axis=0) != 0, axis=1))
    gaps = np.diff(changes) / FPS
    assert gaps.min() >= 0.5 - 1e-9 and gaps.max() > 3.0          # 0.5-3 s segments, long holds
    before, after = sticks[changes], sticks[changes + 1]
    reversals = np.all(np.isclose(after, -before), axis=1) & before.any(1)
    assert reversals.sum() > 10


def test_failures_name_each_broken_limit():
    ok = {"nonfinite": 0, "max_distance": 1.0, "bone_error": 0.0, "min_foot": 0.04,
          "frozen_leader": 0.0, "frozen_follower": 0.0, "resets": 0}
    assert soak.failures(ok) == []
    bad = dict(ok, nonfinite=3, max_distance=3.5, min_foot=-0.05, frozen_follower=0.9, resets=1)
    assert len(soak.failures(bad)) == 5
    assert soak.failures(dict(ok, collapsed=["follower"])) == ["follower collapsed"]
    assert soak.failures(dict(ok, fell=True)) == ["follower fell"]


@pytest.mark.skipif(not (MODELS / "manifest.json").exists(), reason="no shipped models")
def test_short_soak_of_the_shipped_models_passes(tmp_path, capsys):
    out = tmp_path / "soak.json"
    assert soak.main(["--models", str(MODELS), "--rollouts", "2", "--minutes", "1", "--out", str(out)]) == 0
    summary = json.loads(out.read_text())["summary"]
    assert summary["nonfinite"] == 0 and summary["max_distance"] < 3.0
    assert "summary: 0 of 2 rollouts failed" in capsys.readouterr().out


@pytest.mark.skipif(not (MODELS / "manifest.json").exists(), reason="no shipped models")
def test_each_rollout_dances_as_its_seed_alone_does(tmp_path, capsys):
    """Rollout 1 of a soak from seed 0 is the rollout of a soak from seed 1: nothing of the rollout
    before carries over (the leader's chooser on the count forgot its footwork too), so a soak's
    fall can be danced again from its seed."""
    both, alone = tmp_path / "both.json", tmp_path / "alone.json"
    args = ["--models", str(MODELS), "--minutes", "0.3"]
    soak.main([*args, "--rollouts", "2", "--seed", "0", "--out", str(both)])
    soak.main([*args, "--rollouts", "1", "--seed", "1", "--out", str(alone)])
    capsys.readouterr()
    second, first = (json.loads(p.read_text())["rollouts"] for p in (both, alone))
    assert second[1]["seed"] == first[0]["seed"] == 1
    for key in ("max_distance", "guarded", "rhythm"):
        assert second[1][key] == first[0][key], key


def test_soak_out_may_name_a_folder_and_a_missing_one_is_refused_first(tmp_path, capsys):
    """--out DIR writes DIR/soak.json; --out in a folder that does not exist is refused before
    any dancing, not after an hour of it."""
    assert soak.main(["--models", str(MODELS), "--rollouts", "1", "--minutes", "0.05",
                      "--out", str(tmp_path)]) in (0, 1)
    assert json.loads((tmp_path / "soak.json").read_text())["summary"]
    capsys.readouterr()
    assert soak.main(["--models", str(MODELS), "--out", str(tmp_path / "nowhere" / "soak.json")]) == 2
    printed = capsys.readouterr()
    assert "no folder" in printed.err and "rollouts x" not in printed.out    # refused before the first rollout


def test_missing_models_is_a_clear_error(tmp_path, capsys):
    assert soak.main(["--models", str(tmp_path)]) == 2
    assert "manifest.json not found" in capsys.readouterr().err


def test_soak_runs_on_freshly_exported_models(exported, tmp_path, capsys):
    """The pipeline's last step on models this session trained (smoke size, so they may well
    break a limit: the command must run to its summary and say so, not crash)."""
    out = tmp_path / "soak.json"
    rc = soak.main(["--models", str(exported["models"]), "--rollouts", "1", "--minutes", "0.1", "--out", str(out)])
    assert rc in (0, 1)
    summary = json.loads(out.read_text())["summary"]
    assert summary["rollouts"] == 1 and summary["frames"] == 180
    assert "summary:" in capsys.readouterr().out


def test_soak_runs_the_guard_and_refuses_a_guard_of_one(tmp_path, capsys):
    """--guard K (mirror/guard.py) on the shipped models: the count of chosen steps is in the
    summary and printed, and the header names the guard; one sample is nothing to choose from."""
    out = tmp_path / "soak.json"
    rc = soak.main(["--models", str(MODELS), "--rollouts", "1", "--minutes", "0.2", "--guard", "4",
                    "--follower-temperature", "1", "--out", str(out)])
    assert rc in (0, 1)
    summary = json.loads(out.read_text())["summary"]
    printed = capsys.readouterr().out
    assert summary["guarded"] >= 0 and "upright guard: chose" in printed
    assert "upright guard of 4 samples" in printed
    assert soak.main(["--models", str(MODELS), "--guard", "1"]) == 2
    assert "--guard 1" in capsys.readouterr().err


def _script(name: str):
    """scripts/NAME.py as a module (scripts/ is not a package)."""
    import importlib.util
    path = Path(__file__).resolve().parents[2] / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _fall_continuations():
    return _script("fall_continuations")


def test_fall_continuations_dance_on_from_a_moment_for_each_variant(capsys):
    """From a moment of a soak rollout, each variant dances the same continuations; a variant
    changes only the guard it names."""
    fc = _fall_continuations()
    assert fc.main(["3", "--models", str(MODELS), "--minutes", "0.2", "--fall", "6", "--back", "2,1", "--rollout", "guard=64",
                    "--n", "2", "--seconds", "1", "--variants", "base,guard=64+leader.hipMargin=0.2"]) == 0
    out = capsys.readouterr().out
    assert "from 4.00 s, 5.00 s, 2 continuations of 1 s each" in out
    assert "base: she fell in 0 of 4" in out and "guard=64+leader.hipMargin=0.2: she fell in" in out
    manifest = json.loads((MODELS / "manifest.json").read_text())
    lead, follow, _ = fc.policies(manifest, None, None, "guard=64+leader.hipMargin=0.2")
    assert (follow.samples, lead.hip_margin) == (64, 0.2)
    assert manifest["leaderGuard"]["hipMargin"] != 0.2           # the manifest itself is untouched


def test_fall_continuations_swap_in_another_network(capsys):
    """`follower=FILE` / `leader=FILE` dance on with that network: the page's own files by another
    path dance exactly the base's continuations; a file that is not there is refused before dancing."""
    fc = _fall_continuations()
    manifest = json.loads((MODELS / "manifest.json").read_text())
    files = {role: MODELS / manifest["models"][role]["file"] for role in ("leader", "follower")}
    assert fc.main(["3", "--models", str(MODELS), "--minutes", "0.2", "--fall", "6", "--back", "1", "--n", "2",
                    "--seconds", "1", "--variants", f"base,follower={files['follower']},leader={files['leader']}"]) == 0
    lines = [l.split(": ", 1)[1] for l in capsys.readouterr().out.splitlines() if "she fell" in l]
    assert len(lines) == 3 and lines[0] == lines[1] == lines[2]
    lead, follow, _ = fc.policies(manifest, None, None, f"follower={files['follower']}+leader={files['leader']}")
    assert lead is not None and follow is not None
    with pytest.raises(SystemExit, match="missing.onnx not found"):
        fc.main(["3", "--models", str(MODELS), "--variants", "leader=missing.onnx"])


def test_fall_continuations_set_the_choice_on_the_count():
    """The choice on the count's options are variants too (its samples, how the hips weigh), each
    reaching both dancers' choosers; the manifest is untouched; a bad value is refused."""
    fc = _fall_continuations()
    manifest = json.loads((MODELS / "manifest.json").read_text())
    before = json.dumps(manifest, sort_keys=True)
    lead, follow, _ = fc.policies(manifest, None, None, "on_count_hips=0.5+on_count=4")
    assert (follow.on_count.hips, follow.on_count.samples) == (0.5, 4)
    assert (lead.on_count.hips, lead.on_count.samples) == (0.5, 4)
    assert json.dumps(manifest, sort_keys=True) == before          # the manifest itself is untouched
    with pytest.raises(SystemExit, match="on-count-hips -1"):
        fc.policies(manifest, None, None, "on_count_hips=-1")


def test_fall_continuations_refuse_an_unknown_setting():
    fc = _fall_continuations()
    with pytest.raises(SystemExit, match="unknown setting 'guard_size'"):
        fc.main(["3", "--models", str(MODELS), "--variants", "guard_size=8"])


def test_screen_networks_counts_each_candidate_at_each_moment(tmp_path, capsys):
    """One row per moment, one column per candidate and the reference; the page's own follower
    under another name falls exactly as the reference does; bad moments and candidates are refused."""
    sn = _script("screen_networks")
    manifest = json.loads((MODELS / "manifest.json").read_text())
    same = MODELS / manifest["models"]["follower"]["file"]
    moments = tmp_path / "moments.json"
    moments.write_text(json.dumps([{"seed": 3, "models": str(MODELS), "fall": 6},
                                   {"seed": 4, "models": str(MODELS), "fall": 5, "rollout": "guard=64"}]))
    out = tmp_path / "screen.json"
    assert sn.main([str(moments), "--candidates", f"same={'follower=' + str(same)}", "--setting", "guard=64",
                    "--minutes", "0.2", "--back", "1", "--n", "1", "--seconds", "0.5", "--out", str(out)]) == 0
    table = json.loads(out.read_text())
    assert table["candidates"] == {"base": "guard=64", "same": f"guard=64+follower={same}"}
    assert [r["seed"] for r in table["rows"]] == [3, 4]
    assert all(r["falls"]["base"] == r["falls"]["same"] and r["continuations"] == 1 for r in table["rows"])
    assert "| **in all, of 2** |" in capsys.readouterr().out
    moments.write_text(json.dumps([{"seed": 3, "models": str(MODELS)}]))
    assert sn.main([str(moments), "--candidates", "a=guard=64"]) == 2
    assert "moment 0 lacks fall" in capsys.readouterr().err
    moments.write_text(json.dumps([{"seed": 3, "models": str(MODELS), "fall": 6}]))
    assert sn.main([str(moments), "--candidates", "follower.onnx"]) == 2
    assert "NAME=VARIANT" in capsys.readouterr().err
