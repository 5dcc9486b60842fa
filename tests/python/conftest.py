"""Shared fixtures for the Python tests.

BVH couples come from the CMU salsa takes where they are (training.data.folders.default_data():
$DUET_DATA, else data/cmu-salsa, else ../shared/data/cmu-salsa) and from synthetic couples
(training.data.synthetic, written to a tmp folder) where they are not, so the data tests run on a
fresh clone too. The few tests that check the real takes themselves are marked `needs_real_data`.
Everything derived from the data (copies, prepared arrays, checkpoints, ONNX files) is written
under pytest's tmp folders, never into the repository.

The expensive steps run once per session and are shared: prepare 3 short takes, smoke-train the
shipped models on them, export those models.
"""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from training.data.folders import default_data  # noqa: E402
from training.data.synthetic import CMU_TAKES, write_couples  # noqa: E402

REAL_DATA = Path(default_data()).resolve()
# The three shortest clean-enough takes: 10 trains, 12 validates, 06 tests (see dataset.py).
SMALL_TAKES = {"train": "10", "validation": "12", "test": "06"}
# Frame counts at 120 fps, from the data README (an independent record of what the files hold).
README_FRAMES = {"01": 2242, "02": 2101, "03": 1830, "04": 1871, "06": 1772, "07": 2071,
                 "09": 2575, "10": 1197, "11": 2108, "12": 1690, "13": 2271, "15": 2140}
assert README_FRAMES == CMU_TAKES, "the synthetic takes copy the CMU frame counts"


def have_real_data() -> bool:
    return all((REAL_DATA / f"{s}_{t}.bvh").is_file() for s in ("60", "61") for t in README_FRAMES)


needs_real_data = pytest.mark.skipif(
    not have_real_data(), reason=f"needs the 12 CMU salsa couples (60_NN.bvh, 61_NN.bvh), not in {REAL_DATA}: "
                                 f"docs/data.md, Getting the takes")


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: takes more than a few seconds (still part of the suite)")


def pytest_report_header(config):
    return (f"BVH couples: CMU salsa takes in {REAL_DATA}" if have_real_data() else
            f"BVH couples: synthetic (training.data.synthetic); no CMU salsa takes in {REAL_DATA}")


def copy_takes(dst: Path, takes, data: Path) -> Path:
    """Copy the lead and follow files of `takes` from `data` into dst (a tmp folder)."""
    dst.mkdir(parents=True, exist_ok=True)
    for t in takes:
        for s in ("60", "61"):
            shutil.copy(data / f"{s}_{t}.bvh", dst / f"{s}_{t}.bvh")
    return dst


# ---------------------------------------------------------------- BVH couples in memory

@pytest.fixture(scope="session")
def couples(tmp_path_factory) -> Path:
    """A folder of BVH couples holding at least SMALL_TAKES (60 leads, 61 follows, CMU frame
    counts): the real takes when present, else synthetic ones."""
    if have_real_data():
        return REAL_DATA
    return write_couples(tmp_path_factory.mktemp("synthetic"), {t: CMU_TAKES[t] for t in SMALL_TAKES.values()})


@pytest.fixture(scope="session")
def take_bvh(couples):
    """The lead of take 10 (shortest take) as parsed BVH."""
    from training.mirror.bvh import read_bvh
    return read_bvh(couples / "60_10.bvh")


@pytest.fixture(scope="session")
def take_pair(couples):
    """Leader and follower Motion of take 10 at 120 fps."""
    from training.data.dataset import discover_takes, load_pair, select_takes
    take = select_takes(discover_takes(couples), ["10"])[0]
    return load_pair(take)


@pytest.fixture(scope="session")
def take_tracks(take_pair):
    """(leader Track, follower Track) of take 10 at 30 fps, phase 0, as training builds them."""
    from training.data.dataset import pair_tracks
    return pair_tracks(*take_pair)


# ---------------------------------------------------------------- prepared / trained / exported

@pytest.fixture(scope="session")
def data3(couples, tmp_path_factory):
    return copy_takes(tmp_path_factory.mktemp("data3"), SMALL_TAKES.values(), couples)


@pytest.fixture(scope="session")
def prepared3(data3, tmp_path_factory):
    """training.data.prepare on 3 takes (all phases, mirrored train): train 10, validation 12, test 06."""
    from training.data.prepare import main
    out = tmp_path_factory.mktemp("prepared3")
    rc = main(["--data", str(data3), "--prepared", str(out), "--validation", SMALL_TAKES["validation"],
               "--test", SMALL_TAKES["test"]])
    assert rc == 0
    return out


@pytest.fixture(scope="session")
def smoke_runs(prepared3, tmp_path_factory):
    """`training.learning.train --all --smoke` on the 3-take data: one folder per shipped model."""
    from training.learning.train import main
    out = tmp_path_factory.mktemp("runs")
    rc = main(["--all", "--smoke", "--prepared", str(prepared3), "--runs", str(out)])
    assert rc == 0
    return out


@pytest.fixture(scope="session")
def exported(smoke_runs, prepared3, data3, tmp_path_factory):
    """`training.learning.export` of the smoke models: int8 models + manifest in `models`, fp32 in `fp32`."""
    from training.learning.export import main
    root = tmp_path_factory.mktemp("exported")
    models, fp32 = root / "models", root / "fp32"
    rc = main(["--runs", str(smoke_runs), "--prepared", str(prepared3), "--data", str(data3),
               "--models", str(models), "--fp32", str(fp32)])
    assert rc == 0
    return {"models": models, "fp32": fp32, "runs": smoke_runs, "prepared": prepared3}


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
