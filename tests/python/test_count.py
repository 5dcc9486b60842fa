"""The count of a take found in its footwork (training/data/count.py), and the music block both
networks hear (training/mirror/music.py)."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import REAL_DATA, needs_real_data
from training.data import count as C
from training.data.count_report import report
from training.mirror import music as Mu
from training.mirror.skeleton import FEET, FPS


def stepping(seconds: float, bpm: float, beat0: float, seed: int = 0, noise: float = 0.05) -> np.ndarray:
    """[F, 17, 3] a dancer whose feet step once a beat, each landing on a whole count, the steps
    around even counts longer than those around odd ones (the two-beat group), count `beat0` at
    the first frame."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * FPS)) / FPS
    beat = beat0 + t * bpm / 60
    pos = np.zeros((len(t), 17, 3))
    # A foot moves between landings: speed ~ sin^2 of the beat's phase (0 on the whole counts),
    # swelling toward the even counts.
    size = 0.8 + 0.2 * np.cos(np.pi * beat)
    speed = size * np.sin(np.pi * beat) ** 2 + noise * rng.random(len(t))
    x = np.cumsum(speed) / FPS
    pos[:, FEET[0], 0] = x
    pos[:, FEET[1], 2] = 0.3 * x
    return pos


@pytest.mark.parametrize("bpm,beat0", [(164.0, 0.3), (187.0, 1.6), (152.0, 0.0)])
def test_finds_tempo_beat_and_two_beat_group(bpm, beat0):
    c = C.find_count(stepping(15, bpm, beat0))
    assert abs(c.bpm - bpm) <= 0.5
    # the same count: whole beats where a foot lands, even ones at the long step
    assert abs(C.phase_gap(c, C.Count(bpm, beat0), 7.0)) < 0.08


def test_each_dancer_alone_and_windows_agree_with_the_couple():
    lead, follow = stepping(16, 170, 0.4, seed=1), stepping(16, 170, 0.4, seed=2)
    couple = C.find_count(lead, follow)
    for alone in (C.find_count(lead), C.find_count(follow)):
        assert abs(alone.bpm / couple.bpm - 1) < 0.01 and abs(C.phase_gap(alone, couple)) < 0.1
    for w in C.window_gaps(lead, follow, couple):
        assert abs(w["beat"]) < 0.1 and abs(w["group"]) < 0.5


def test_a_dancer_out_of_step_is_told_apart():
    lead, late = stepping(16, 170, 0.4, seed=1), stepping(16, 170, 0.9, seed=2)   # half a beat later
    assert abs(abs(C.phase_gap(C.find_count(late), C.find_count(lead), group=1.0)) - 0.5) < 0.1


def test_measure_strength_sees_the_two_beat_group_not_a_measure():
    s = C.measure_strength(stepping(16, 170, 0.0), C.Count(170, 0.0))
    assert s[1] > 3 and s[2] > 2 and s[8] < 2


def test_music_block_layout_and_values():
    b = Mu.music_block(np.array([0.0, 1.5]), np.array([3.0, 2.5]))
    assert b.shape == (2, Mu.MUSIC_SIZE) == (2, 53)
    now = list(Mu.MUSIC_OFFSETS).index(0)
    # on a whole even count: beat phase (sin 0, cos 1), two-beat phase (0, 1); tempo last
    np.testing.assert_allclose(b[0, 4 * now:4 * now + 4], [0, 1, 0, 1], atol=1e-12)
    np.testing.assert_allclose(b[1, 4 * now:4 * now + 4], [np.sin(3 * np.pi), np.cos(3 * np.pi), -1, 0], atol=1e-12)
    assert b[0, -1] == 3.0 and b[1, -1] == 2.5
    # a key a second ahead reads the count a second on
    ahead = list(Mu.MUSIC_OFFSETS).index(30)
    np.testing.assert_allclose(b[0, 4 * ahead:4 * ahead + 2], [np.sin(2 * np.pi * 3), np.cos(2 * np.pi * 3)], atol=1e-9)


def test_music_at_reads_the_tempo_from_the_count():
    beat = 0.2 + np.arange(100) * Mu.beats_per_step(176.0)
    np.testing.assert_allclose(Mu.music_at(beat, np.array([0, 50, 99])),
                               Mu.music_block(beat[[0, 50, 99]], np.full(3, 176.0 / 60)), atol=1e-9)


@needs_real_data
def test_the_recorded_takes_carry_a_steady_count():
    rows = report(str(REAL_DATA))
    assert len(rows) == 12
    assert all(162 <= r["bpm"] <= 188 for r in rows)
    assert sum(max(abs(r["beat_leader"]), abs(r["beat_follower"])) <= 0.15 for r in rows) >= 11
    assert all(r["window_beat"] <= 0.15 for r in rows)
    # the measure is not in the footwork: the leader's swing every 8 beats is at the noise
    assert np.median([r["leader_swing"][8] for r in rows]) < 1.2 < np.median([r["leader_swing"][2] for r in rows])
