"""training/data/led_figures.py: the figures a couple dances, labelled from world positions.

The synthetic couples (training/data/synthetic.py) are led through a known turn every 2-4 s: his
left hand up LEAD_SECONDS before she spins once round in TURN_SPIN seconds, either way. The labels
must find each of them, its way and his preparation; mirrored, the same figures the other way.
Where each ends is not checked here: the synthetic dancers' shoulders and hips swing fast enough
that their facing never settles between turns, so a figure can run on to the next."""
from __future__ import annotations

import numpy as np
import pytest

from training.data import led_figures as LF
from training.data import synthetic
from training.mirror.skeleton import FPS, mirror_motion, resample


def couple(seed: int, seconds: float = 20.0):
    """A synthetic couple built as synthetic_couple builds one, with the led turns it planted:
    (leader, follower) at 30 fps and her planted spin [F] (radians) at 30 fps."""
    fps = synthetic.CMU_FPS
    t = np.arange(int(seconds * fps)) / fps
    rng = np.random.default_rng(seed)
    lead = synthetic.procedural_dancer(rng, len(t), 0.6 * t, synthetic.OFFSETS, 0.45, fps)
    follow = synthetic.procedural_dancer(rng, len(t), 0.6 * t + np.pi, synthetic.OFFSETS * synthetic.FOLLOWER_SIZE, 0.45, fps)
    spin, lift = synthetic.led_turns(rng, t)
    lead, follow = synthetic.raise_hand(lead, lift), synthetic.spun(follow, spin)
    return resample(lead, FPS, 0), resample(follow, FPS, 0), spin[::fps // FPS]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_every_led_turn_is_found_with_its_way_his_preparation_and_her_finish(seed):
    lead, follow, spin = couple(seed)
    figures = LF.figures_of(lead.positions, follow.positions)
    hers = [f for f in figures if f.name == "her_turn"]
    # The synthetic leader never turns; she turns as many times as she was led, each once round.
    assert not [f for f in figures if f.name == "his_turn"]
    planted = int(np.sum(np.abs(np.diff(np.round(spin / (2 * np.pi)))) > 0))   # whole turns planted
    assert len(hers) == planted > 3
    moving = np.flatnonzero(np.abs(np.diff(spin)) > 1e-9)   # the frames her planted spins turn
    previous_end = -1
    for f in hers:
        total = spin[min(f.end + 5, len(spin) - 1)] - spin[max(f.start - 5, 0)]
        assert f.way == np.sign(total) and f.turns == 1
        # His hand went up for it (above HAND_RAISED partway through its LEAD_SECONDS) before she
        # spins: the figure begins with it.
        assert f.prepared
        spun = moving[(moving >= f.start) & (moving <= f.end)]
        assert len(spun) and f.start <= spun[0] and (spun[0] - f.start) / FPS <= synthetic.LEAD_SECONDS
        if f.start > previous_end + 1:   # not cut short by the figure before
            assert (spun[0] - f.start) / FPS > 0.3
        assert f.start < f.turned <= f.end
        previous_end = f.end


def test_mirrored_couples_dance_the_same_figures_the_other_way():
    lead, follow, _ = couple(3)
    plain = LF.figures_of(lead.positions, follow.positions)
    mirrored = LF.figures_of(mirror_motion(lead).positions, mirror_motion(follow).positions)
    assert len(plain) == len(mirrored) > 0
    for a, b in zip(plain, mirrored):
        assert (a.name, a.start, a.turned, a.end, a.prepared) == (b.name, b.start, b.turned, b.end, b.prepared)
        assert a.way == -b.way


def test_the_command_writes_the_table_per_take_and_refuses_a_missing_folder(couples, tmp_path, capsys):
    assert LF.main(["--data", str(couples), "--takes", "10,12", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "| 10 |" in out and "| 12 |" in out and "her turn" in out
    assert (tmp_path / "led_figures.json").exists() and (tmp_path / "led_figures.md").exists()
    assert LF.main(["--data", str(tmp_path / "none"), "--out", str(tmp_path)]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_a_spin_of_two_turns_is_one_figure():
    angle = np.concatenate([np.zeros(30), np.linspace(0, 4 * np.pi, 40), np.full(30, 4 * np.pi)])
    rate = LF.turning_rate(angle)
    first, last = LF.turn_span(rate, 50)
    assert 25 <= first <= 32 and 68 <= last <= 75
