"""training.data.synthetic: procedural couples written as BVH the loader reads back exactly, in the
data layout every command accepts; and where the data folder comes from (training.data.folders)."""
from __future__ import annotations

import re

import numpy as np
import pytest

from training.data import folders, synthetic
from training.mirror.bvh import parse_bvh
from training.data.dataset import discover_takes, load_pair
from training.data.prepare import main as prepare_main
from training.mirror.skeleton import JOINT_NAMES, reduce_bvh


def test_euler_round_trip(rng):
    angles = rng.uniform(-80, 80, (50, 3))      # x within ±90°: the ZXY decomposition is unique
    zxy = synthetic.euler_zxy(synthetic.euler(angles))
    np.testing.assert_allclose(zxy, angles[:, [2, 0, 1]], atol=1e-9)


def test_bvh_text_reads_back_as_the_motion():
    lead, follow = synthetic.synthetic_couple(np.random.default_rng(4), 300)
    for m in (lead, follow):
        bvh = parse_bvh(synthetic.bvh_text(m), "synthetic.bvh")
        assert {"lCollar", "rCollar", "lButtock", "rButtock"} <= set(bvh.names)   # folded away
        back = reduce_bvh(bvh, "synthetic.bvh")
        np.testing.assert_allclose(back.positions, m.positions, atol=2e-5)
        np.testing.assert_allclose(back.offsets, m.offsets, atol=2e-6)
        np.testing.assert_allclose(back.rotations, m.rotations, atol=2e-5)
        assert back.fps == pytest.approx(120, rel=1e-4)


def test_couple_faces_each_other_on_the_floor():
    lead, follow = synthetic.synthetic_couple(np.random.default_rng(5), 1200)
    apart = np.linalg.norm(lead.positions[:, 0, [0, 2]] - follow.positions[:, 0, [0, 2]], axis=-1)
    assert 0.5 < apart.min() and apart.max() < 1.5
    feet = [JOINT_NAMES.index("lFoot"), JOINT_NAMES.index("rFoot")]
    assert 0.0 < lead.positions[:, feet, 1].min() < 0.15         # ankles touch down, never sink
    travel = np.linalg.norm(np.diff(lead.positions[:, 0, [0, 2]], axis=0), axis=-1).sum()
    assert travel > 2.0                                           # 10 s of motion goes somewhere


def test_command_writes_couples_that_prepare_takes_with_default_splits(tmp_path, capsys):
    data = tmp_path / "synthetic"
    assert synthetic.main(["--data", str(data), "--takes", "01,02,12,13"]) == 0
    assert sorted(p.name for p in data.iterdir()) == [f"{s}_{t}.bvh" for s in ("60", "61")
                                                      for t in ("01", "02", "12", "13")]
    takes = discover_takes(data)
    lead, follow = load_pair(takes[0])
    assert lead.frames == follow.frames == synthetic.CMU_TAKES["01"]
    capsys.readouterr()
    assert prepare_main(["--data", str(data), "--prepared", str(tmp_path / "prepared")]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^train\s+01\s", out, re.M) and re.search(r"^test\s+02,13\s", out, re.M)
    # Never over takes already there (real ones, perhaps).
    before = (data / "60_01.bvh").read_bytes()
    assert synthetic.main(["--data", str(data), "--takes", "01"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "60_01.bvh exists" in err[0]
    assert (data / "60_01.bvh").read_bytes() == before


def test_default_data_folder(tmp_path, monkeypatch):
    repo_data, shared = tmp_path / "repo" / "data" / "cmu-salsa", tmp_path / "shared" / "data" / "cmu-salsa"
    monkeypatch.setattr(folders, "REPO_DATA", repo_data)
    monkeypatch.setattr(folders, "SHARED_DATA", shared)
    monkeypatch.delenv(folders.DATA_ENV, raising=False)
    assert folders.default_data() == str(repo_data)              # nothing exists: where README says
    shared.mkdir(parents=True)
    assert folders.default_data() == str(shared)                 # the project machines' copy
    repo_data.mkdir(parents=True)
    assert folders.default_data() == str(repo_data)              # the repository's own folder first
    monkeypatch.setenv(folders.DATA_ENV, str(tmp_path / "mine"))
    assert folders.default_data() == str(tmp_path / "mine")      # DUET_DATA over both
