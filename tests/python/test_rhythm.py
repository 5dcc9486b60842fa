"""Rhythm measures (training/evaluation/rhythm.py) on dancers made to step on a count or not."""
from __future__ import annotations

import numpy as np

from test_count import stepping
from training.evaluation import rhythm as R
from training.mirror.skeleton import FPS


def count(seconds, bpm, beat0=0.0):
    return beat0 + np.arange(int(seconds * FPS)) / FPS * bpm / 60


def test_a_dancer_on_the_count_has_a_pulse_at_two_beats_and_steps_on_the_beat():
    p = stepping(20, 170, 0.0)
    h, lag = R.pulse(R.footwork(p))
    assert h > 0.5 and abs(lag / (120 / 170) - 1) < 0.04
    assert R.on_the_beat(p, count(20, 170)) > 0.8
    # half a beat off the music: every step between beats
    assert R.on_the_beat(p, count(20, 170, 0.5)) < -0.8


def test_a_dancer_at_another_tempo_is_off_the_music():
    r = R.rhythm(stepping(20, 150, 0.0, seed=1), stepping(20, 150, 0.0, seed=2), count(20, 180), 180)
    assert r["leader_period_off"] > 0.1 and abs(r["leader_on_beat"]) < 0.4


def test_together_finds_partners_on_one_beat():
    a, b = stepping(20, 170, 0.0, seed=1), stepping(20, 170, 0.0, seed=2)
    late = stepping(20, 170, 0.5, seed=3)    # half a beat off
    assert R.together(a, b) > 0.8 > 0.3 > R.together(a, late)


def test_a_still_dancer_has_no_pulse():
    still = np.zeros((300, 17, 3))
    assert R.pulse(R.footwork(still)) [0] == 0.0
    assert R.on_the_beat(still, count(10, 170)) == 0.0


def test_summary_names_the_worst_seed_and_the_ratio():
    ref = {"leader_pulse": 0.3, "follower_pulse": 0.3, "together": 0.6, "leader_on_beat": 0.3,
           "follower_on_beat": 0.3, "leader_period_within": 0.8, "follower_period_within": 0.7}
    rows = [{"seed": s, "together": t, **{f"{r}_{k}": v for r in ("leader", "follower")
                                          for k, v in (("pulse", p), ("period_off", o), ("on_beat", b))}}
            for s, t, p, o, b in ((0, 0.6, 0.3, 0.01, 0.4), (7, 0.3, 0.1, 0.2, -0.1), (9, 0.9, 0.5, 0.0, 0.2))]
    s = R.summarize(rows, ref)
    assert s["leader"]["pulse_worst_seed"] == 7 and s["together"]["worst_seed"] == 7
    assert abs(s["leader"]["pulse_ratio"] - 0.3 / 0.3) < 1e-9 and s["leader"]["period_within"] == 2 / 3
