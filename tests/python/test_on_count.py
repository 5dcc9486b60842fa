"""mirror/on_count.py (the page's steps on the count) and its place in the upright guard and the options."""
import argparse

import numpy as np
import pytest

from training.evaluation import options as O
from training.mirror import features as feat
from training.mirror import music
from training.mirror import on_count as OC
from training.mirror.guard import POSE, UprightGuard
from training.mirror.skeleton import FEET, FPS, HEAD

RANGES = {"hip_low": 0.7, "head_above_hip_low": 0.6, "feet_wide": 1.0, "angle_high": [3.0, 0.6]}
OFFSETS = np.zeros((feat.N_JOINTS, 3))
OFFSETS[1:, 1] = 0.2   # every bone 20 cm long, pointing up: a straight column


def input_at(role: str, beat: float, ankle_speed: float, bps: float = 2.9) -> np.ndarray:
    """A role's input whose ankles move at ankle_speed (m/s, each along x) and whose music is at `beat`."""
    x = np.zeros(feat.LEADER_INPUT_SIZE if role == "leader" else feat.INPUT_SIZE)
    for c in OC.ANKLE_VELOCITY_IN[role]:
        x[c] = ankle_speed
    x[-music.MUSIC_SIZE:] = music.music_block(np.array(beat), np.array(bps))
    return x


def output(footwork: float, hip: float = 1.0) -> np.ndarray:
    """An upright body (hips at `hip`) whose next step's ankles move footwork / 2 each."""
    out = np.zeros(feat.OUTPUT_SIZE)
    pose = out[POSE].reshape(feat.N_JOINTS, 12)
    pose[:, 1] = hip
    pose[HEAD, 1] = hip + 0.7
    pose[:, 6:9], pose[:, 9:12] = (0, 0, 1), (0, 1, 0)
    for j in FEET:
        pose[j, 3] = footwork / 2
    out[POSE] = pose.reshape(-1)
    return out


@pytest.mark.parametrize("role", ["leader", "follower"])
def test_it_reads_the_footwork_and_the_count_from_the_input(role):
    x = input_at(role, beat=7.3, ankle_speed=0.6, bps=3.0)
    assert OC.footwork_now(x, role) == pytest.approx(1.2)
    assert OC.count_next(x) % 1 == pytest.approx(0.3 + 3.0 / FPS)
    assert OC.footwork_next(np.stack([output(0.8), output(2.0)])) == pytest.approx([0.8, 2.0])


def test_the_target_swings_with_the_beat_around_the_dancers_own_mean():
    chooser = OC.OnCount("follower", strength=0.5)
    step = 2.9 / FPS
    on = chooser.target(input_at("follower", -step, 0.5))          # the next step falls on the beat
    assert on == pytest.approx(0.5)                                 # lowest: a foot lands
    between = chooser.target(input_at("follower", 0.5 - step, 0.5))
    assert between == pytest.approx(1.5)                            # highest: between the beats
    # The mean moves a thirtieth of the way toward each step's footwork (about a second's mean).
    chooser.target(input_at("follower", 0.25 - step, 2.0))
    assert chooser.mean == pytest.approx(1.0 + 3.0 / (OC.MEAN_SECONDS * FPS))
    with pytest.raises(ValueError, match="role"):
        OC.OnCount("partner")
    with pytest.raises(ValueError, match="at least 2"):
        OC.OnCount("leader", samples=1)


def test_nearest_count_takes_the_standing_sample_nearest_the_target():
    outs = np.stack([output(0.2), output(1.0), output(1.4)])
    assert OC.nearest_count(outs, 1.3, np.array([1.0, 1.0, 1.0]), 0.05) == 2
    assert OC.nearest_count(outs, 1.3, np.array([1.0, 1.0, -0.2]), 0.05) == 1   # the nearest falls
    assert OC.nearest_count(outs, 1.3, np.array([0.0, 0.01, -0.2]), 0.05) == -1


def test_the_guard_chooses_on_the_count_every_step_and_guards_when_none_stands():
    batches = iter([[0.2, 1.9, 1.0], [0.3, 1.2, 1.8], [1.0, 1.0, 1.0], [1.5]])   # footwork of each sample
    hips = iter([[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.4, 0.4, 0.4], [0.75, 0.5, 0.72, 0.8]])
    calls = []

    def policy(x, temperature, rng):
        n = len(np.atleast_2d(x))
        calls.append(n)
        fw = next(batches) if n == 3 else [1.0] * n
        return {"output": np.stack([output(f, h) for f, h in zip(fw, next(hips))]), "code": np.arange(n)[:, None]}

    chooser = OC.OnCount("follower", samples=3, strength=1.0)
    guard = UprightGuard(policy, RANGES, samples=4, margin=0.05, offsets=OFFSETS, on_count=chooser)
    rng = np.random.default_rng(0)
    step = 2.9 / FPS
    # Between the beats (target 2 x her mean of 1 m/s): the fastest of the three.
    got = guard(input_at("follower", 0.5 - step, 0.5), 1.0, rng)
    assert got["code"][0, 0] == 1 and guard.guarded == 0
    # Just before a beat (target about 0): the slowest.
    got = guard(input_at("follower", -step, 0.5), 1.0, rng)
    assert got["code"][0, 0] == 0 and guard.guarded == 0
    # None of the three stands (hips 0.4 m, under the range): the guard's own 4, the most upright.
    got = guard(input_at("follower", -step, 0.5), 1.0, rng)
    assert got["code"][0, 0] == 3 and guard.guarded == 1
    assert calls == [3, 3, 3, 4]
    with pytest.raises(ValueError, match="bones"):
        UprightGuard(policy, RANGES, samples=4, on_count=chooser)


def parse(*argv):
    ap = argparse.ArgumentParser()
    O.add_options(ap)
    return ap.parse_args(list(argv))


def test_options_take_it_from_the_manifest_and_refuse_what_cannot_choose():
    m = {"defaultTemperature": 1.0, "leaderTemperature": 0.5, "plausibility": RANGES,
         "skeleton": {"offsets": {"follower": OFFSETS.tolist(), "leader": OFFSETS.tolist()}},
         "guard": {"samples": 32, "margin": 0.05}, "leaderGuard": {"samples": 8, "margin": 0.07},
         "onCount": {"samples": 8, "strength": 0.9}}
    args = parse()
    assert O.resolve(args, m) is None and (args.on_count, args.on_count_strength) == (8, 0.9)
    lead, follow = O.leader_policy(policy_stub, m, args), O.follower_policy(policy_stub, m, args, 0.5)
    assert (lead.on_count.role, lead.on_count.samples, lead.on_count.strength) == ("leader", 8, 0.9)
    assert follow.on_count.role == "follower" and follow.on_count is not lead.on_count
    lead.on_count.mean = 2.0
    O.restart_count(lead)
    assert lead.on_count.mean is None
    off = parse("--on-count", "0")
    assert O.resolve(off, m) is None and O.leader_policy(policy_stub, m, off).on_count is None
    assert "--on-count 1" in O.resolve(parse("--on-count", "1"), m)
    assert "--on-count-strength" in O.resolve(parse("--on-count-strength", "2"), m)
    assert "needs --guard" in O.resolve(parse("--guard", "0", "--leader-guard", "0"), m)
    older = {k: v for k, v in m.items() if k != "onCount"}
    args = parse()
    assert O.resolve(args, older) is None and args.on_count == 0


def policy_stub(x, temperature, rng):
    return {"output": np.zeros((len(np.atleast_2d(x)), feat.OUTPUT_SIZE))}


def test_a_turn_is_left_to_the_network():
    """Turning faster than TURNING (her facing 0.8 rad round in 5 frames: 4.8 rad/s), the chooser
    aims at nothing and the guard takes the network's one sample, as on any unguarded step."""
    x = input_at("follower", 0.3, 0.5)
    c = OC.LAST_FACING["follower"]
    x[c:c + 2] = np.sin(0.8), np.cos(0.8)
    assert OC.turn_rate(x, "follower") == pytest.approx(0.8 * FPS / feat.KEY_STEP)
    chooser = OC.OnCount("follower", samples=3)
    assert chooser.target(x) is None and chooser.mean == pytest.approx(1.0)   # the mean still moves on
    calls = []

    def policy(x, temperature, rng):
        calls.append(len(np.atleast_2d(x)))
        return {"output": np.stack([output(1.0)] * len(np.atleast_2d(x)))}

    guard = UprightGuard(policy, RANGES, samples=4, margin=0.05, offsets=OFFSETS, on_count=chooser)
    guard(x, 1.0, np.random.default_rng(0))
    x[c:c + 2] = 0.0, 1.0                       # facing as 5 frames ago: the count chooses again
    guard(x, 1.0, np.random.default_rng(0))
    assert calls == [1, 3] and guard.guarded == 0
