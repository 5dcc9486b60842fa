"""training/evaluation/figures.py on dancers whose turns are known by construction: a body made of
the four joints the facing reads (shoulders, thighs) plus a hip, turned by a chosen facing curve."""
from __future__ import annotations

import numpy as np
import pytest

from training.evaluation import figures as Fg
from training.mirror.features import N_JOINTS
from training.mirror.skeleton import FPS, JOINT_NAMES


def body(facing: np.ndarray, root: np.ndarray | None = None) -> np.ndarray:
    """[T] facing angles (radians, θ = 0 faces +Z) -> [T, 17, 3] positions whose shoulder and hip
    lines face that way (every other joint at the hip)."""
    t = len(facing)
    root = np.zeros((t, 2)) if root is None else root
    p = np.zeros((t, N_JOINTS, 3))
    p[:, :, 0], p[:, :, 1], p[:, :, 2] = root[:, None, 0], 1.0, root[:, None, 1]
    # Facing (sin θ, cos θ) has its left side at (cos θ, -sin θ) in this convention (features.md).
    left = np.stack([np.cos(facing), np.zeros(t), -np.sin(facing)], -1)
    for name, side, height in (("lShldr", 1, 1.4), ("rShldr", -1, 1.4), ("lThigh", 1, 0.9), ("rThigh", -1, 0.9)):
        j = JOINT_NAMES.index(name)
        p[:, j] = p[:, 0] + side * 0.18 * left
        p[:, j, 1] = height
    return p


def test_facing_reads_the_heading_back():
    angles = np.linspace(-3, 3, 50)
    assert np.allclose(Fg.facing(body(angles)), angles, atol=1e-9)


def test_a_spin_of_two_full_turns_in_two_seconds_is_two_turns():
    # Still for 2 s, then 720 degrees over 2 s (360 deg/s), then still again.
    f = np.concatenate([np.zeros(60), np.linspace(0, 4 * np.pi, 60), np.full(60, 4 * np.pi)])
    turns = Fg.turns(Fg.facing(body(f)))
    assert [d for _, d in turns] == [1, 1]
    # The first is timed where 300 degrees are reached: 300/720 of the way through the spin.
    assert turns[0][0] == pytest.approx(60 + 60 * 300 / 720, abs=1.5)
    spin = Fg.spin_frames(Fg.facing(body(f)))
    assert spin[62:118].all() and not spin[:58].any() and not spin[122:].any()


def test_a_slow_turn_is_not_a_turn_and_the_other_way_counts_left():
    slow = np.linspace(0, np.radians(350), 150)            # 350 degrees over 5 s: never 300 in 2.5 s
    assert Fg.turns(slow) == []
    assert not Fg.spin_frames(slow).any()
    back = np.linspace(0, -2 * np.pi, 45)                    # a full turn the other way in 1.5 s
    assert [d for _, d in Fg.turns(back)] == [-1]


def test_body_motion_and_travel():
    t = np.arange(90) / FPS
    walk = body(np.zeros(90), np.stack([0.8 * t, np.zeros(90)], -1))
    assert Fg.travel(walk) == pytest.approx(0.8, rel=1e-6)
    assert Fg.body_motion(walk) == pytest.approx(0.0, abs=1e-9)     # a body carried along, not moving
    spin = body(np.linspace(0, 2 * np.pi, 90))
    assert Fg.travel(spin) == pytest.approx(0.0, abs=1e-9)
    # Shoulders and thighs 0.18 m from the hip, each frame a chord of 2π/89 rad; 4 of 16 joints move.
    chord = 2 * 0.18 * np.sin(np.pi / 89)
    assert Fg.body_motion(spin) == pytest.approx(4 / 16 * chord * FPS, rel=1e-9)


def test_turns_match_within_the_window_and_by_direction():
    ref = [(100, 1), (200, -1), (300, 1)]
    found = [(110, 1), (205, 1), (500, -1)]
    assert Fg.match(found, ref) == 1                        # 205 turns the wrong way, 500 is too late
    assert Fg.match(found, ref, same_direction=False) == 2
    assert Fg.match([(100 + int(0.8 * FPS), 1)], ref) == 0  # 0.8 s late is outside ±0.75 s
    assert Fg.match([(99, 1), (101, 1)], ref) == 1          # one recorded turn matches once


def test_summarize_pools_minutes_and_counts():
    f = np.concatenate([np.zeros(60), np.linspace(0, 2 * np.pi, 30), np.full(90, 2 * np.pi)])
    a = {**Fg.dancer(body(f)), **Fg.against(body(f), body(f))}
    still = body(np.zeros(180))
    b = {**Fg.dancer(still), **Fg.against(still, body(f))}
    s = Fg.summarize([a, b])
    assert s["minutes"] == pytest.approx(2 * 180 / FPS / 60)
    assert s["turns_per_min"] == pytest.approx(1 / s["minutes"])
    assert s["recall"] == pytest.approx(0.5) and s["precision"] == pytest.approx(1.0)


def test_the_way_counts_her_turns_that_meet_a_recorded_one_and_go_its_way():
    """summarize's direction: of her turns that meet a recorded one either way, the share that go
    the recorded way (a turn the other way meets it but does not count)."""
    turn = np.concatenate([np.zeros(60), np.linspace(0, 2 * np.pi, 30), np.full(90, 2 * np.pi)])
    same = {**Fg.dancer(body(turn)), **Fg.against(body(turn), body(turn))}
    other = {**Fg.dancer(body(-turn)), **Fg.against(body(-turn), body(turn))}
    assert Fg.summarize([same])["direction"] == pytest.approx(1.0)
    assert Fg.summarize([other])["direction"] == pytest.approx(0.0)
    assert Fg.summarize([same, other])["direction"] == pytest.approx(0.5)


def test_hip_jitter_counts_reversals_and_speed_change():
    """A hip walking a straight line at a steady speed never turns back; one that steps back and
    forth turns back every frame, and its velocity changes by twice its speed each frame."""
    from training.evaluation.jitter import hip_jitter
    t = np.arange(FPS * 2)
    straight = np.zeros((len(t), N_JOINTS, 3))
    straight[:, 0, 0] = 0.01 * t
    assert hip_jitter(straight) == {"reversals_per_s": 0.0, "speed_change_cm": pytest.approx(0.0, abs=1e-9)}
    zigzag = np.zeros((len(t), N_JOINTS, 3))
    zigzag[:, 0, 0] = 0.01 * (t % 2)
    j = hip_jitter(zigzag)
    assert j["reversals_per_s"] == pytest.approx((len(t) - 2) / 2.0)
    assert j["speed_change_cm"] == pytest.approx(2.0)
    # Standing still (steps under 2 mm) is not turning back.
    shiver = np.zeros((len(t), N_JOINTS, 3))
    shiver[:, 0, 0] = 0.001 * (t % 2)
    assert hip_jitter(shiver)["reversals_per_s"] == 0.0
