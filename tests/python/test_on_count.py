"""mirror/on_count.py (the page's steps on the count) and its place in the upright guard and the options."""
import argparse

import numpy as np
import pytest

from training.evaluation import options as O
from training.mirror import features as feat
from training.mirror import music
from training.mirror import on_count as OC
from training.mirror.guard import POSE, UprightGuard, drawn_joints
from training.mirror.rollout import MIN_ANKLE_HEIGHT
from training.mirror.skeleton import FEET, FPS, HEAD

RANGES = {"hip_low": 0.7, "head_above_hip_low": 0.6, "feet_wide": 1.0, "angle_high": [3.0, 0.6]}
OFFSETS = np.zeros((feat.N_JOINTS, 3))
OFFSETS[1:, 1] = 0.2   # every bone 20 cm long, pointing up: a straight column


def input_at(role: str, beat: float, ankle_speed: float, bps: float = 2.9) -> np.ndarray:
    """A role's input whose ankles move at ankle_speed (m/s, each along x) and whose music is at `beat`."""
    x = np.zeros(feat.LEADER_INPUT_SIZE if role == "leader" else feat.INPUT_SIZE)
    for c in OC.ANKLE_VELOCITY_IN[role]:
        x[c] = ankle_speed
    x[OC.POSITION_IN[role]] = STANDING[OC.STEPPED]
    x[-music.MUSIC_SIZE:] = music.music_block(np.array(beat), np.array(bps))
    return x


def output(footwork: float, hip: float = 1.0) -> np.ndarray:
    """An upright body (hips at `hip`) carried forward by its root so that each ankle moves
    footwork / 2 (m/s) from where input_at has it."""
    out = np.zeros(feat.OUTPUT_SIZE)
    pose = out[POSE].reshape(feat.N_JOINTS, 12)
    pose[:, 1] = hip
    pose[HEAD, 1] = hip + 0.7
    pose[:, 6:9], pose[:, 9:12] = (0, 0, 1), (0, 1, 0)
    out[POSE] = pose.reshape(-1)
    out[ROOT_UPDATE.start] = footwork / 2 / FPS
    return out


ROOT_UPDATE = feat.block_slices(feat.OUTPUT_LAYOUT)["root_update"]
STANDING = drawn_joints(output(0.0)[None], OFFSETS)[0]   # the body output draws before its root moves


@pytest.mark.parametrize("role", ["leader", "follower"])
def test_it_reads_the_footwork_and_the_count_from_the_input(role):
    x = input_at(role, beat=7.3, ankle_speed=0.6, bps=3.0)
    assert OC.footwork_now(x, role) == pytest.approx(1.2)
    assert OC.count_next(x) % 1 == pytest.approx(0.3 + 3.0 / FPS)
    outs = np.stack([output(0.8), output(2.0)])
    steps = OC.drawn_steps(outs, drawn_joints(outs, OFFSETS), x, role)
    assert OC.drawn_footwork(steps) == pytest.approx([0.8, 2.0])


@pytest.mark.parametrize("role", ["leader", "follower"])
def test_the_drawn_steps_are_the_steps_the_dancer_takes(take_tracks, take_pair, role):
    """Given the recorded next frame as an output, drawn_steps gives the recorded move of the hips
    and ankles (seen from the root now): the footwork is the recorded ankles' speed, and the hips
    turn back on the frames jitter.py counts as reversals."""
    from training.evaluation.jitter import reversal_frames
    lead, follow = take_tracks
    me, partner, offsets = (lead, follow, take_pair[0].offsets) if role == "leader" else (follow, lead, take_pair[1].offsets)
    frames = np.arange(40, me.frames - 40)
    x = (feat.leader_input(partner, me, frames) if role == "leader" else feat.follower_input(partner, me, frames))
    outs = feat.output_features(me, frames)
    joints = drawn_joints(outs, offsets)
    kept = joints[:, FEET, 1].min(-1) > MIN_ANKLE_HEIGHT + 1e-9   # not lifted (the rollout lifts a body whose ankles sink)
    moved = me.positions[frames + 1][:, OC.STEPPED] - me.positions[frames][:, OC.STEPPED]
    seen = feat.to_root_space_directions(moved, me.heading[frames][:, None])
    steps = np.stack([OC.drawn_steps(outs[i:i + 1], joints[i:i + 1], x[i], role)[0] for i in range(len(frames))])
    np.testing.assert_allclose(steps[kept], seen[kept], atol=1e-5)
    speed = np.linalg.norm(moved[:, 1:], axis=-1).sum(-1) * FPS
    np.testing.assert_allclose(OC.drawn_footwork(steps)[kept], speed[kept], atol=1e-3)
    back = np.array([OC.hips_turn_back(steps[i:i + 1], x[i], role)[0] for i in range(len(frames))])
    counted = reversal_frames(me.positions)[frames - 1]   # its frame t - 1 is the turn into frame t + 1
    assert kept.mean() > 0.9 and back.sum() > 5
    assert (back == counted)[kept].mean() > 0.99


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


def test_nearest_count_takes_the_standing_sample_nearest_the_target_its_hips_going_on():
    footwork, back = np.array([0.2, 1.0, 1.4]), np.array([False, False, False])
    assert OC.nearest_count(footwork, back, 1.3, np.array([1.0, 1.0, 1.0]), 0.05) == 2
    assert OC.nearest_count(footwork, back, 1.3, np.array([1.0, 1.0, -0.2]), 0.05) == 1   # the nearest falls
    assert OC.nearest_count(footwork, back, 1.3, np.array([0.0, 0.01, -0.2]), 0.05) == -1
    # The nearest's hips would turn back: the next nearest is taken unless it misses by `hips` more.
    back = np.array([False, False, True])
    assert OC.nearest_count(footwork, back, 1.3, np.ones(3), 0.05, hips=1.0) == 1
    assert OC.nearest_count(footwork, back, 1.3, np.ones(3), 0.05, hips=0.2) == 2
    assert OC.nearest_count(footwork, np.ones(3, bool), 1.3, np.ones(3), 0.05, hips=1.0) == 2


def test_the_hips_turn_back_when_their_step_reverses_the_last_one():
    x = input_at("follower", 0.3, 0.5)
    v = OC.HIP_VELOCITY_IN["follower"]
    steps = np.zeros((4, 3, 3))
    steps[:, 0] = [[0.01, 0, 0], [-0.01, 0, 0], [0, 0, 0.01], [-0.001, 0, 0]]   # on, back, sideways, nearly still
    x[v] = 0.3, 0.0, 0.0    # 1 cm a frame along x into this frame
    assert OC.hips_turn_back(steps, x, "follower").tolist() == [False, True, False, False]
    x[v] = 0.03, 0.0, 0.0   # 1 mm a frame: standing, no way to turn back from
    assert not OC.hips_turn_back(steps, x, "follower").any()


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


CONTACTS = feat.block_slices(feat.OUTPUT_LAYOUT)["contacts"]


def planting(footwork: float, contacts=(0.9, 0.9)) -> np.ndarray:
    """output(footwork), its network calling both feet planted (where the contact layer locks them)."""
    out = output(footwork)
    out[CONTACTS] = contacts
    return out


@pytest.mark.parametrize("role", ["leader", "follower"])
def test_planted_feet_count_still_as_the_page_draws_them(role):
    """Just before a beat (target about 0), of a sample gliding its feet at 0.9 m/s and one at 1.0
    m/s whose network plants both feet, the dancer takes the planted one: the contact layer holds
    its feet still. The feet of the step taken count still in the footwork now (OnCount.took)."""
    def policy(x, temperature, rng):
        return {"output": np.stack([output(0.9), planting(1.0)]), "code": np.arange(2)[:, None]}

    chooser = OC.OnCount(role, samples=2, strength=1.0)
    guard = UprightGuard(policy, RANGES, samples=4, margin=0.05, offsets=OFFSETS, on_count=chooser)
    got = guard(input_at(role, -2.9 / FPS, 0.5), 1.0, np.random.default_rng(0))
    assert got["code"][0, 0] == 1
    assert chooser.feet.tolist() == [True, True]
    # read where the network draws them (no foot planted), the slower glide is nearer
    assert OC.drawn_footwork(np.zeros((1, 3, 3)) + 0.01, OC.planted(output(0.9))).tolist() == pytest.approx(
        [2 * np.sqrt(3) * 0.01 * FPS])
    # the footwork now leaves the planted feet out; a foot at the threshold is free (the layer locks above it)
    x = input_at(role, 0.0, 0.5)
    assert OC.footwork_now(x, role, np.array([True, False])) == pytest.approx(0.5)
    assert OC.planted(planting(1.0, (0.5, 0.51))).tolist() == [[False, True]]
    chooser.took(planting(1.0, (0.9, 0.2)))
    chooser.mean = 1.0
    chooser.target(x)
    assert chooser.mean == pytest.approx(1.0 + (0.5 - 1.0) / (OC.MEAN_SECONDS * FPS))
    # a new duet forgets both (each seed of `seeds` and rollout of `soak` dances as if alone)
    O.restart_count(guard)
    assert chooser.mean is None and chooser.feet is None


def parse(*argv):
    ap = argparse.ArgumentParser()
    O.add_options(ap)
    return ap.parse_args(list(argv))


def test_options_take_it_from_the_manifest_and_refuse_what_cannot_choose():
    m = {"defaultTemperature": 1.0, "leaderTemperature": 0.5, "plausibility": RANGES,
         "skeleton": {"offsets": {"follower": OFFSETS.tolist(), "leader": OFFSETS.tolist()}},
         "guard": {"samples": 32, "margin": 0.05}, "leaderGuard": {"samples": 8, "margin": 0.07},
         "onCount": {"samples": 8, "strength": 0.9, "hips": 0.7}}
    args = parse()
    assert O.resolve(args, m) is None and (args.on_count, args.on_count_strength, args.on_count_hips) == (8, 0.9, 0.7)
    lead, follow = O.leader_policy(policy_stub, m, args), O.follower_policy(policy_stub, m, args, 0.5)
    assert (lead.on_count.role, lead.on_count.samples, lead.on_count.strength, lead.on_count.hips) == ("leader", 8, 0.9, 0.7)
    assert follow.on_count.role == "follower" and follow.on_count is not lead.on_count
    lead.on_count.mean = 2.0
    O.restart_count(lead)
    assert lead.on_count.mean is None
    off = parse("--on-count", "0")
    assert O.resolve(off, m) is None and O.leader_policy(policy_stub, m, off).on_count is None
    assert "--on-count 1" in O.resolve(parse("--on-count", "1"), m)
    assert "--on-count-strength" in O.resolve(parse("--on-count-strength", "2"), m)
    assert "--on-count-hips" in O.resolve(parse("--on-count-hips", "-1"), m)
    args = parse("--on-count-hips", "0")
    assert O.resolve(args, m) is None and O.follower_policy(policy_stub, m, args, 0.5).on_count.hips == 0.0
    assert "needs --guard" in O.resolve(parse("--guard", "0", "--leader-guard", "0"), m)
    older = {k: v for k, v in m.items() if k != "onCount"}
    args = parse()
    assert O.resolve(args, older) is None and args.on_count == 0
    args = parse()   # a manifest that does not say: on_count.HIPS, as the page takes it
    assert O.resolve(args, {**m, "onCount": {"samples": 8, "strength": 0.9}}) is None and args.on_count_hips == OC.HIPS


def policy_stub(x, temperature, rng):
    return {"output": np.zeros((len(np.atleast_2d(x)), feat.OUTPUT_SIZE))}


def test_a_turn_leaves_the_footwork_to_the_network_and_keeps_the_hips_going():
    """Turning faster than her TURNING (her facing 1.2 rad round in 5 frames: 7.2 rad/s), the chooser
    aims at no footwork: the guard takes the first standing sample whose hips go on, whatever its
    feet do; with `hips` 0, the network's one sample, as on any unguarded step."""
    x = input_at("follower", 0.3, 0.5)
    c = OC.LAST_FACING["follower"]
    x[c:c + 2] = np.sin(1.2), np.cos(1.2)
    x[OC.HIP_VELOCITY_IN["follower"]] = 0.3, 0.0, 0.0   # her hips came in along x, 1 cm a frame
    assert OC.turn_rate(x, "follower") == pytest.approx(1.2 * FPS / feat.KEY_STEP)
    chooser = OC.OnCount("follower", samples=3)
    assert chooser.target(x) is None and chooser.mean == pytest.approx(1.0)   # the mean still moves on
    calls = []

    def policy(x, temperature, rng):   # the first sample's root steps back along x, the others on
        n = len(np.atleast_2d(x))
        calls.append(n)
        return {"output": np.stack([output(-0.6 if i == 0 else 0.6 * i) for i in range(n)]), "code": np.arange(n)[:, None]}

    guard = UprightGuard(policy, RANGES, samples=4, margin=0.05, offsets=OFFSETS, on_count=chooser)
    assert guard(x, 1.0, np.random.default_rng(0))["code"][0, 0] == 1   # the first going on, not the nearest footwork
    x[c:c + 2] = 0.0, 1.0                       # facing as 5 frames ago: the count chooses again
    guard(x, 1.0, np.random.default_rng(0))
    assert calls == [3, 3] and guard.guarded == 0
    x[c:c + 2] = np.sin(1.2), np.cos(1.2)
    calls.clear()
    plain = UprightGuard(policy, RANGES, samples=4, margin=0.05, offsets=OFFSETS, on_count=OC.OnCount("follower", 3, hips=0.0))
    assert plain(x, 1.0, np.random.default_rng(0))["code"][0, 0] == 0 and calls == [1]


def test_every_option_reaches_the_seeds_workers():
    """seeds builds its dancers in worker processes from a dict of the resolved options: it takes
    every option add_options adds, so a new one cannot be left out."""
    names = O.option_names()
    assert {"on_count_hips", "on_count_strength", "leader_guard", "tempo"} <= set(names)
    args = parse("--on-count-hips", "0.5")
    m = {"defaultTemperature": 1.0, "leaderTemperature": 0.5, "plausibility": RANGES,
         "skeleton": {"offsets": {"follower": OFFSETS.tolist(), "leader": OFFSETS.tolist()}},
         "guard": {"samples": 32, "margin": 0.05}, "leaderGuard": {"samples": 8, "margin": 0.07},
         "onCount": {"samples": 8, "strength": 1.0}}
    assert O.resolve(args, m) is None
    again = argparse.Namespace(**{k: getattr(args, k) for k in names})   # what a worker gets
    assert O.follower_policy(policy_stub, m, again, 0.5).on_count.hips == 0.5


def turning_output(footwork: float, degrees: float, hip: float = 1.0) -> np.ndarray:
    """output(footwork), its planned path turning `degrees` evenly over the next second."""
    out = output(footwork, hip)
    h = np.radians(degrees) * np.arange(1, feat.KEYS + 1) / feat.KEYS
    keys = out[FUTURE].reshape(feat.KEYS, 4)
    keys[:, 2], keys[:, 3] = np.sin(h), np.cos(h)
    out[FUTURE] = keys.ravel()
    return out


FUTURE = feat.block_slices(feat.OUTPUT_LAYOUT)["trajectory_future"]


def test_outside_a_spin_she_takes_the_turn_the_figure_leads():
    """With figure_turn, while her turn to her left runs in the figure she reads, outside a spin the
    standing samples whose planned path turns figure_turn degrees or more her left (a whole turn
    counted whole) are aimed at the count before the others; none standing that turns so: the choice
    is the one without it. No figure running or coming: those that start no turn either way. In a
    spin the network's spin holds; without figure_turn nothing is preferred."""
    outs = np.stack([turning_output(2.0, 0.0), turning_output(0.3, 300.0), turning_output(1.9, 200.0),
                     turning_output(2.0, -200.0)])
    assert OC.planned_turn(outs) == pytest.approx([0.0, 300.0, 200.0, -200.0])
    assert OC.starts_turn(outs, 180.0).tolist() == [False, True, True, True]
    x = input_at("follower", 0.5 - 2.9 / FPS, 0.5)   # between the beats: her target is 2x her mean of 1 m/s
    her_left = feat.FIGURE_KINDS.index(("her_turn", 1))
    x[OC.FIGURE_IN["follower"]:OC.FIGURE_IN["follower"] + feat.FIGURE_SIZE] = feat.figure_block(
        np.array([[her_left, 20, 60]]), np.array([30]))[0]
    assert OC.figure_way(x, "follower") == 1
    chooser = OC.OnCount("follower", samples=4, figure_turn=180.0)
    assert chooser.target(x) == pytest.approx(2.0) and not chooser.turning
    assert chooser.prefers(outs, x).tolist() == [False, True, True, False]

    def policy(xx, temperature, rng):
        n = len(np.atleast_2d(xx))
        return {"output": np.stack([outs[i % 4] for i in range(n)]), "code": np.arange(n)[:, None]}

    guard = UprightGuard(policy, RANGES, samples=4, margin=0.05, offsets=OFFSETS, on_count=chooser)
    assert guard(x, 1.0, np.random.default_rng(0))["code"][0, 0] == 2      # her way's turn nearest the count
    plain = UprightGuard(policy, RANGES, samples=4, margin=0.05, offsets=OFFSETS, on_count=OC.OnCount("follower", 4))
    assert plain(x, 1.0, np.random.default_rng(0))["code"][0, 0] == 0      # without it: the nearest
    unled = x.copy()
    unled[OC.FIGURE_IN["follower"]:OC.FIGURE_IN["follower"] + feat.FIGURE_SIZE] = 0.0
    assert chooser.prefers(outs, unled).tolist() == [True, False, False, False]   # no figure: no turn started
    outs[1] = turning_output(0.3, 300.0, hip=0.4)
    outs[2] = turning_output(1.9, 200.0, hip=0.4)                           # her way's turns fall: none preferred
    assert guard(x, 1.0, np.random.default_rng(0))["code"][0, 0] == 0
    c = OC.LAST_FACING["follower"]
    x[c:c + 2] = np.sin(1.2), np.cos(1.2)                                     # spinning
    chooser.target(x)
    assert chooser.turning and chooser.prefers(outs, x) is None
    assert OC.OnCount("follower", 4).prefers(outs, x) is None
    with pytest.raises(ValueError, match="figure_turn"):
        OC.OnCount("follower", figure_turn=0.0)
