"""python -m training.data.prepare: bad input folders fail with exit 2 and one 'error:' line; the real
data prints per-split frame counts and feature sizes and writes the arrays (in tmp only)."""
from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

from training.data.prepare import main

from conftest import README_FRAMES, REAL_DATA, REPO, copy_takes, needs_real_data


def run_main(capsys, *args):
    rc = main(list(map(str, args)))
    out, err = capsys.readouterr()
    return rc, out, err


def assert_one_error_line(rc, err, *words):
    """Exit 2; stderr ends with exactly one 'error: ...' line (tqdm may have drawn a bar before
    it) that contains every word."""
    assert rc == 2, err
    lines = [l for l in re.split(r"[\r\n]+", err) if l.strip()]
    errors = [l for l in lines if l.startswith("error:")]
    assert len(errors) == 1 and lines[-1] == errors[0], err
    for w in words:
        assert w in errors[0], f"{w!r} not in {errors[0]!r}"


def assert_nothing_written(out_dir):
    assert not any(out_dir.glob("*.npz")) if out_dir.exists() else True


def test_missing_data_folder(tmp_path, capsys):
    rc, _, err = run_main(capsys, "--data", tmp_path / "nowhere", "--prepared", tmp_path / "out")
    assert_one_error_line(rc, err, "nowhere", "does not exist")
    assert_nothing_written(tmp_path / "out")


def test_folder_without_bvh_files(tmp_path, capsys):
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "notes.txt").write_text("hello")
    rc, _, err = run_main(capsys, "--data", tmp_path / "data", "--prepared", tmp_path / "out")
    assert_one_error_line(rc, err, "no .bvh files")


def test_take_without_partner(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    (data / "60_12.bvh").write_bytes((couples / "60_12.bvh").read_bytes())
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out")
    assert_one_error_line(rc, err, "60_12", "no partner", "61_12.bvh")
    assert_nothing_written(tmp_path / "out")


def test_badly_named_file(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    (data / "salsa.bvh").write_bytes((couples / "60_12.bvh").read_bytes())
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out")
    assert_one_error_line(rc, err, "salsa.bvh", "SUBJECT_TAKE")


def test_three_subjects(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    (data / "62_10.bvh").write_bytes((couples / "61_10.bvh").read_bytes())
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out")
    assert_one_error_line(rc, err, "two subjects", "60, 61, 62")


def truncated(text: str, keep: int, fix_header: bool) -> str:
    head, motion = text.split("MOTION", 1)
    lines = motion.strip().splitlines()   # Frames:, Frame Time:, then one line per frame
    frames = lines[2:2 + keep]
    header = f"Frames: {keep}" if fix_header else lines[0]
    return head + "MOTION\n" + "\n".join([header, lines[1], *frames]) + "\n"


def test_partners_with_different_frame_counts(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    (data / "61_10.bvh").write_text(truncated((couples / "61_10.bvh").read_text(), 1000, fix_header=True))
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out", "--validation", "10", "--test", "10")
    assert_one_error_line(rc, err, "take 10", "different frame counts", "60_10.bvh 1197", "61_10.bvh 1000")
    assert_nothing_written(tmp_path / "out")


def test_truncated_download(couples, tmp_path, capsys):
    """A file cut short (its header still says 1197 frames) is a BVH error, not a crash."""
    data = copy_takes(tmp_path / "data", ["10"], couples)
    (data / "61_10.bvh").write_text(truncated((couples / "61_10.bvh").read_text(), 1000, fix_header=False))
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out", "--validation", "10", "--test", "10")
    assert_one_error_line(rc, err, "61_10.bvh", "1197 frames")


def test_file_that_is_not_bvh(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    (data / "61_10.bvh").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4)
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out", "--validation", "10", "--test", "10")
    assert_one_error_line(rc, err, "61_10.bvh", "not a BVH")
    assert_nothing_written(tmp_path / "out")


def test_skeleton_lacking_a_joint(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    (data / "60_10.bvh").write_text((couples / "60_10.bvh").read_text().replace("lFoot", "lToe"))
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out", "--validation", "10", "--test", "10")
    assert_one_error_line(rc, err, "60_10.bvh", "lFoot")
    assert_nothing_written(tmp_path / "out")


def test_take_too_short_for_a_sample(couples, tmp_path, capsys):
    """A take of 200 frames at 120 fps is 50 frames at 30 fps: less than the 2 s + 1 frame that one
    sample needs. prepare must say so (exit 2 naming the take) or leave it out, never crash."""
    data = copy_takes(tmp_path / "data", ["06", "10", "12"], couples)
    for s in ("60", "61"):
        p = data / f"{s}_10.bvh"
        p.write_text(truncated(p.read_text(), 200, fix_header=True))
    rc, out, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out", "--validation", "12", "--test", "12")
    if rc == 2:
        assert_one_error_line(rc, err, "10")
    else:
        assert rc == 0
        with np.load(tmp_path / "out" / "stats.npz") as z:
            assert all(np.isfinite(z[k]).all() for k in z.files)


def test_split_take_not_in_folder(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out")   # default validation 12
    assert_one_error_line(rc, err, "split take 12")


def test_empty_training_split(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out", "--validation", "10", "--test", "10")
    assert_one_error_line(rc, err, "split train is empty")


def test_unknown_leader(couples, tmp_path, capsys):
    data = copy_takes(tmp_path / "data", ["10"], couples)
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out", "--leader", "99")
    assert_one_error_line(rc, err, "leader subject '99'")


@pytest.mark.slow
@needs_real_data
def test_real_data(tmp_path):
    """The whole CMU folder through the real command line (a subprocess, as a user runs it)."""
    out = tmp_path / "prepared"
    try:
        r = subprocess.run([sys.executable, "-m", "training.data.prepare", "--data", str(REAL_DATA), "--prepared", str(out)],
                           cwd=REPO, capture_output=True, text=True, timeout=3600)   # a hang guard, not a speed check
        check_real_data(r, out)
    finally:
        shutil.rmtree(out, ignore_errors=True)   # ~270 MB of arrays; pytest keeps old tmp folders


def check_real_data(r, out):
    assert r.returncode == 0, r.stderr
    # Dancer frames at 30 fps per take: every 4th of the 120 fps frames (README frame counts).
    frames30 = {t: math.ceil(f / 4) for t, f in README_FRAMES.items()}
    expect = {"train": sum(v for t, v in frames30.items() if t not in ("12", "02", "13")),
              "validation": frames30["12"], "test": frames30["02"] + frames30["13"]}
    # Samples per role: frames with a second of context each side; train has the 4 phases of
    # 120 fps and a mirrored copy of each.
    valid = lambda f: max(0, f - 61)   # noqa: E731
    samples = {"train": sum(2 * valid(math.ceil((f - p) / 4)) for t, f in README_FRAMES.items()
                            if t not in ("12", "02", "13") for p in range(4)),
               "validation": valid(frames30["12"]), "test": valid(frames30["02"]) + valid(frames30["13"])}
    for split, takes in (("train", "01,03,04,06,07,09,10,11,15"), ("validation", "12"), ("test", "02,13")):
        line = next(l for l in r.stdout.splitlines() if l.startswith(split))
        assert line.split()[1:] == [takes, str(expect[split]), str(samples[split])], line
    total = sum(expect.values())
    assert 5900 < total < 6100
    assert f"total dancer frames at 30 fps (per dancer): {total}" in r.stdout
    for text in ("follower input I (817)", "leader input I (854)", "output O (323)", "intention (90)",
                 "partner_trajectory_past 24", "self_pose 204", "control 24", "contacts 2"):
        assert text in r.stdout, text
    # The arrays on disk agree with the summary.
    with np.load(out / "validation.npz") as z:
        assert z["follower_input"].shape == (samples["validation"], 817)
        assert z["leader_output"].shape == (samples["validation"], 323)
        assert z["follower_intention"].shape == (samples["validation"], 90)
        assert list(z["takes"]) == sorted(README_FRAMES)
        assert not z["mirror"].any() and (z["phase"] == 0).all()
    with np.load(out / "stats.npz") as z:
        for role in ("follower", "leader"):
            std = z[f"{role}_input_std"]
            assert std.shape == ({"follower": 817, "leader": 854}[role],) and np.isfinite(std).all()
            assert std.min() >= 1e-2 - 1e-9
            assert z[f"{role}_output_mean"].shape == (323,)


def test_files_in_other_units(tmp_path, capsys):
    """BVH in centimetres instead of the CMU copy's units: prepare names the file and the units."""
    from dataclasses import replace
    from training.data import synthetic
    data = tmp_path / "data"
    data.mkdir()
    for s, m in zip(("60", "61"), synthetic.synthetic_couple(np.random.default_rng(0), 600)):
        cm = replace(m, positions=m.positions * 100, offsets=m.offsets * 100)
        (data / f"{s}_10.bvh").write_text(synthetic.bvh_text(cm))
    rc, _, err = run_main(capsys, "--data", data, "--prepared", tmp_path / "out", "--validation", "10", "--test", "10")
    assert_one_error_line(rc, err, "60_10.bvh", "head joint", "other units")
    assert_nothing_written(tmp_path / "out")


def test_tempo_copies_are_written_by_default_and_change_nothing_else(data3, prepared3, tmp_path):
    """prepare writes the tempo copies the shipped recipes read (prepare.TEMPOS), in a file of their
    own, carrying the count warped with them; --tempos '' writes none and changes nothing else."""
    from training.data.prepare import TEMPOS
    from training.data.prepared import load_mirror_flags, load_split
    plain_dir = tmp_path / "plain"
    assert main(["--data", str(data3), "--prepared", str(plain_dir), "--validation", "12", "--test", "06",
                 "--tempos", ""]) == 0
    assert (prepared3 / "train_tempo.npz").exists() and not (plain_dir / "train_tempo.npz").exists()
    # The recorded tempo's arrays and statistics are the same with or without the copies.
    for f in ("train.npz", "validation.npz", "test.npz", "stats.npz"):
        with np.load(prepared3 / f) as a, np.load(plain_dir / f) as b:
            for k in a.files:
                np.testing.assert_array_equal(a[k], b[k])
    with np.load(prepared3 / "train_tempo.npz") as z:
        tempos = z["tempo"]
    assert sorted(set(tempos.tolist())) == pytest.approx(TEMPOS)
    plain = load_split(str(prepared3), "train", "follower")["input"]
    more = load_split(str(prepared3), "train", "follower", tempo_copies=True)
    # slower copies play longer (more samples), faster shorter; the copies follow the recorded samples.
    slow, fast = min(TEMPOS), max(TEMPOS)
    assert (tempos == np.float32(slow)).sum() > len(plain) > (tempos == np.float32(fast)).sum() > 0
    assert len(more["input"]) == len(plain) + len(tempos) and np.array_equal(more["input"][:len(plain)], plain)
    assert len(load_mirror_flags(str(prepared3), tempo_copies=True)) == len(more["input"])
    # The music they hear is warped with them: a copy at 1.16x hears a tempo 1.16x the recorded one.
    bps = more["input"][:, -1]
    recorded = float(np.median(bps[:len(plain)]))
    assert float(np.median(bps[len(plain):][tempos == np.float32(fast)])) == pytest.approx(fast * recorded, rel=0.01)


def test_a_tempo_recipe_without_copies_says_to_prepare_with_tempos(data3, tmp_path, capsys):
    from training.data.prepared import TrainError, load_mirror_flags, load_split
    from training.learning.train import main as train_main
    bare = tmp_path / "bare"
    assert main(["--data", str(data3), "--prepared", str(bare), "--validation", "12", "--test", "06",
                 "--tempos", ""]) == 0
    capsys.readouterr()
    for read in (lambda: load_split(str(bare), "train", "follower", tempo_copies=True),
                 lambda: load_mirror_flags(str(bare), tempo_copies=True)):
        with pytest.raises(TrainError, match=r"train_tempo\.npz not found.*training\.data\.prepare .*--tempos"):
            read()
    # Training a shipped recipe (they read the copies) stops with that one line, before any epoch.
    assert train_main(["--model", "follower", "--smoke", "--prepared", str(bare),
                       "--runs", str(tmp_path / "runs")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "--tempos" in err[-1] and "train_tempo.npz" in err[-1]


@pytest.mark.parametrize("bad", ["fast", "0.1", "3"])
def test_bad_tempos_are_refused(data3, tmp_path, capsys, bad):
    with pytest.raises(SystemExit) as e:
        main(["--data", str(data3), "--prepared", str(tmp_path / "out"), "--tempos", bad])
    assert e.value.code == 2 and "--tempos" in capsys.readouterr().err
