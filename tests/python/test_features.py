"""training/mirror/features.py: layouts, root-space conventions, invariance, round trips, normalization."""
from __future__ import annotations

import numpy as np
import pytest

from training.mirror.music import music_block
from training.mirror import features as F
from training.data.dataset import samples
from training.mirror.rollout import rotations_from_vectors
from training.mirror.skeleton import FPS, Motion, forward_kinematics_reduced

FEATURE_FUNCTIONS = ("follower_input", "leader_input", "output_features", "intention_target")


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def all_features(lead: F.Track, follow: F.Track) -> dict[str, np.ndarray]:
    frames = F.valid_frames(lead.frames)
    return {
        "follower_input": F.follower_input(lead, follow, frames),
        "leader_input": F.leader_input(follow, lead, frames),
        "follower_output": F.output_features(follow, frames),
        "leader_output": F.output_features(lead, frames),
        "follower_intention": F.intention_target(lead, follow, frames),
        "leader_intention": F.intention_target(follow, lead, frames),
    }


def moved(track: F.Track, angle: float, shift) -> F.Track:
    """Turn a dancer about the vertical axis through the origin, then shift it on the floor, and
    recompute its root from the moved joints (as training would for such a recording)."""
    R = rot_y(angle)
    m = Motion(track.positions @ R.T + np.asarray(shift, float), R @ track.rotations, np.zeros((17, 3)), FPS)
    return F.Track.from_motion(m, track.beat)   # the music does not move with the dancer


# ---------------------------------------------------------------- sizes and layout

def test_block_sizes():
    assert F.INPUT_SIZE == sum(s for _, s in F.FOLLOWER_INPUT_LAYOUT) == 817   # + the figure, the music
    assert sum(s for _, s in F.LEADER_INPUT_LAYOUT) == F.LEADER_INPUT_SIZE == 854   # + the figure, the hands plan, the music
    assert F.OUTPUT_SIZE == sum(s for _, s in F.OUTPUT_LAYOUT) == 323
    assert F.INTENTION_SIZE == sum(s for _, s in F.INTENTION_LAYOUT) == 90
    sizes = dict(F.FOLLOWER_INPUT_LAYOUT + F.LEADER_INPUT_LAYOUT + F.OUTPUT_LAYOUT)
    assert sizes["partner_trajectory_past"] == 24 and sizes["self_key_joints_past"] == 90
    assert sizes["self_pose"] == 204 and sizes["root_update"] == 3 and sizes["contacts"] == 2
    for layout in (F.FOLLOWER_INPUT_LAYOUT, F.LEADER_INPUT_LAYOUT, F.OUTPUT_LAYOUT):
        sl = list(F.block_slices(layout).values())
        assert sl[0].start == 0 and all(a.stop == b.start for a, b in zip(sl, sl[1:]))
        assert sl[-1].stop == sum(s for _, s in layout)


def test_real_feature_arrays_have_the_layout_widths(take_tracks):
    s = samples(*take_tracks)
    n = len(s["frame"])
    assert n == len(F.valid_frames(take_tracks[0].frames)) > 200
    for role in ("follower", "leader"):
        assert s[f"{role}_input"].shape == (n, F.INPUT_SIZES[role])
        assert s[f"{role}_output"].shape == (n, 323)
        assert s[f"{role}_intention"].shape == (n, 90)
        assert s[f"{role}_input"].dtype == np.float32
        assert np.isfinite(s[f"{role}_input"]).all() and np.isfinite(s[f"{role}_output"]).all()
    contacts = s["follower_output"][:, F.block_slices(F.OUTPUT_LAYOUT)["contacts"]]
    assert set(np.unique(contacts)) <= {0.0, 1.0} and 0.05 < contacts.mean() < 0.95


def test_valid_frames_leave_a_second_each_side():
    v = F.valid_frames(100)
    assert v[0] == 30 and v[-1] + 1 + 30 == 99


# ---------------------------------------------------------------- root space conventions

def test_root_space_is_facing_forward_along_plus_z(rng):
    for heading in (0.0, 0.4, -2.0, 3.0):
        root = np.array([2.0, -1.0])
        fwd = np.array([np.sin(heading), 0.0, np.cos(heading)])
        p = np.array([2.0, 0.7, -1.0]) + 1.5 * fwd
        np.testing.assert_allclose(F.to_root_space_points(p, root, np.float64(heading)), [0, 0.7, 1.5], atol=1e-12)
        np.testing.assert_allclose(F.to_root_space_directions(fwd, np.float64(heading)), [0, 0, 1], atol=1e-12)
    pts = rng.normal(size=(50, 3)) * 3
    roots, headings = rng.normal(size=(50, 2)), rng.uniform(-4, 4, 50)
    back = F.from_root_space_points(F.to_root_space_points(pts, roots, headings), roots, headings)
    np.testing.assert_allclose(back, pts, atol=1e-12)
    back = F.from_root_space_directions(F.to_root_space_directions(pts, headings), headings)
    np.testing.assert_allclose(back, pts, atol=1e-12)


def test_root_update_and_heading_wrap():
    h = np.array([3.1])
    root, nxt = np.array([[1.0, 2.0]]), np.array([[1.0 + np.sin(3.1) / 30, 2.0 + np.cos(3.1) / 30]])
    ru = F.root_update(root, h, nxt, np.array([-3.1]))
    # One 30th of a metre straight ahead; turning from 3.1 to -3.1 rad is +0.083 rad, not -6.2.
    np.testing.assert_allclose(ru, [[0, 1 / 30, 2 * np.pi - 6.2]], atol=1e-12)


def test_foot_contacts():
    pos = np.zeros((3, 17, 3))
    prev = np.zeros((3, 17, 3))
    l, r = 13, 16
    pos[0, [l, r], 1] = 0.08                       # both planted
    prev[0, [l, r], 1] = 0.08
    pos[1, l, 1], prev[1, l, 1] = 0.30, 0.30       # left lifted, right planted
    pos[1, r, 1], prev[1, r, 1] = 0.08, 0.08
    pos[2, [l, r], 1] = 0.08                       # both low but sliding at 1.5 m/s
    prev[2, [l, r], 1] = 0.08
    prev[2, [l, r], 0] = -1.5 / 30
    np.testing.assert_array_equal(F.foot_contacts(pos, prev), [[1, 1], [0, 1], [0, 0]])


def straight_walker(frames, start, heading, speed):
    """A Track whose root walks straight along its heading; joints stand at the root."""
    t = np.arange(frames) / FPS
    fwd = np.array([np.sin(heading), np.cos(heading)])
    root = np.asarray(start, float) + speed * t[:, None] * fwd
    positions = np.zeros((frames, 17, 3))
    positions[..., 0] = root[:, None, 0]
    positions[..., 2] = root[:, None, 1]
    positions[..., 1] = np.linspace(0.1, 1.7, 17)
    beat = 0.25 + t * 170 / 60    # music at 170 beats a minute, a quarter beat in at the first frame
    return F.Track(positions, np.tile(np.eye(3), (frames, 17, 1, 1)), root, np.full(frames, heading), beat)


def test_blocks_describe_a_known_scene():
    """Self stands at the origin facing +Z; the partner stands 0.8 m in front, facing self, and
    walks to the self's left (+X) at 1 m/s. Each block must show exactly that."""
    n = 100
    me = straight_walker(n, [0, 0], 0.0, 0.0)
    partner = straight_walker(n, [0, 0.8], np.pi, 0.0)
    partner.root[:, 0] = np.arange(n) / FPS          # moves sideways (+X) while facing -Z
    partner.positions[..., 0] = partner.root[:, None, 0]
    t = np.array([50])
    x = F.follower_input(partner, me, t)[0]
    b = {k: x[s] for k, s in F.block_slices(F.FOLLOWER_INPUT_LAYOUT).items()}
    keys_future = b["partner_trajectory_future"].reshape(6, 4)
    np.testing.assert_allclose(keys_future[:, 0], 50 / 30 + np.arange(1, 7) * 5 / 30, atol=1e-12)
    np.testing.assert_allclose(keys_future[:, 1], 0.8, atol=1e-12)
    np.testing.assert_allclose(keys_future[:, 2:], np.tile([0, -1], (6, 1)), atol=1e-12)
    keys_past = b["partner_trajectory_past"].reshape(6, 4)
    np.testing.assert_allclose(keys_past[:, 0], 50 / 30 + np.arange(-6, 0) * 5 / 30, atol=1e-12)
    np.testing.assert_allclose(b["self_trajectory_past"].reshape(6, 4), np.tile([0, 0, 0, 1], (6, 1)), atol=1e-12)
    pose = b["partner_pose"].reshape(17, 12)
    np.testing.assert_allclose(pose[:, 3:6], np.tile([1.0, 0, 0], (17, 1)), atol=1e-9)   # velocity
    np.testing.assert_allclose(pose[:, 1], np.linspace(0.1, 1.7, 17), atol=1e-12)        # heights
    # The partner's facing (R ez with identity rotations is +Z in world) seen from self: +Z.
    np.testing.assert_allclose(pose[:, 6:9], np.tile([0, 0, 1.0], (17, 1)), atol=1e-12)
    # The music: the count at frame 50 and 170 beats a minute, as music_block writes them.
    np.testing.assert_allclose(b["music"], music_block(np.array(me.beat[50]), np.array(170 / 60)), atol=1e-9)
    intention = F.intention_target(partner, me, t)[0].reshape(6, 5, 3)
    np.testing.assert_allclose(intention[:, :, 0], np.repeat((50 / 30 + np.arange(1, 7) * 5 / 30)[:, None], 5, 1), atol=1e-12)
    np.testing.assert_allclose(intention[:, :, 2], 0.8, atol=1e-12)
    # The leader's control block is its own future path: a walker at 1 m/s straight ahead.
    walker = straight_walker(n, [3, 3], 1.0, 1.0)
    xl = F.leader_input(partner, walker, t)[0]
    control = xl[F.block_slices(F.LEADER_INPUT_LAYOUT)["control"]].reshape(6, 4)
    np.testing.assert_allclose(control, np.stack([np.zeros(6), np.arange(1, 7) * 5 / 30, np.zeros(6), np.ones(6)], -1), atol=1e-12)
    out = F.output_features(walker, t)[0]
    np.testing.assert_allclose(out[:3], [0, 1 / 30, 0], atol=1e-12)


# ---------------------------------------------------------------- invariance

@pytest.mark.parametrize("angle,shift", [(2.2, (4.0, 0.0, -7.5)), (-0.9, (0.0, 0.0, 0.0)), (0.0, (-30.0, 0.0, 12.0))])
def test_features_ignore_where_the_couple_stands(take_tracks, angle, shift):
    lead, follow = take_tracks
    a = all_features(F.Track.from_motion(Motion(lead.positions, lead.rotations, np.zeros((17, 3)), FPS), lead.beat),
                     F.Track.from_motion(Motion(follow.positions, follow.rotations, np.zeros((17, 3)), FPS), follow.beat))
    b = all_features(moved(lead, angle, shift), moved(follow, angle, shift))
    for k in a:
        err = np.abs(a[k] - b[k]).max()
        assert err < 1e-5, f"{k} changed by {err:.2e} when the couple was turned {angle} rad and moved {shift}"


def test_moving_one_dancer_changes_only_partner_blocks(take_tracks):
    """Guard against the invariance test passing for a trivial reason: moving the leader alone
    0.5 m must change what the follower sees of it, and nothing of the follower's self blocks."""
    lead, follow = take_tracks
    frames = F.valid_frames(lead.frames)
    a = F.follower_input(lead, follow, frames)
    b = F.follower_input(moved(lead, 0.0, (0.5, 0.0, 0.0)), follow, frames)
    for name, sl in F.block_slices(F.FOLLOWER_INPUT_LAYOUT).items():
        diff = np.abs(a[:, sl] - b[:, sl]).max()
        if name.startswith("self"):
            assert diff < 1e-9, name
        elif name in ("partner_trajectory_past", "partner_trajectory_future", "partner_key_joints_past"):
            assert diff > 0.4, name


# ---------------------------------------------------------------- round trip

def test_pose_block_round_trips_through_the_world(take_tracks, take_pair):
    """features -> world pose -> features: read the follower's self pose at frame t, rebuild the
    world joints and rotations (as the run time does), and compute the block again."""
    lead, follow = take_tracks
    offsets = take_pair[1].offsets
    for t in (40, 120, follow.frames - 40):
        x = F.follower_input(lead, follow, np.array([t]))[0]
        block = x[F.block_slices(F.FOLLOWER_INPUT_LAYOUT)["self_pose"]]
        pose = block.reshape(17, 12)
        root, heading = follow.root[t], follow.heading[t]
        world = F.from_root_space_points(pose[:, :3], root, heading)
        rot = rotations_from_vectors(F.from_root_space_directions(pose[:, 6:9], heading),
                                     F.from_root_space_directions(pose[:, 9:12], heading))
        previous = world - F.from_root_space_directions(pose[:, 3:6], heading) / FPS
        np.testing.assert_allclose(world, follow.positions[t], atol=1e-9)
        np.testing.assert_allclose(rot, follow.rotations[t], atol=1e-9)
        again = F.pose_block(world, previous, rot, root, heading)
        np.testing.assert_allclose(again, block, atol=1e-9)
        # The rebuilt rotations place the joints through FK with the dancer's bone offsets.
        np.testing.assert_allclose(forward_kinematics_reduced(offsets, world[0], rot), world, atol=1e-6)


def test_output_root_update_integrates_to_the_next_root(take_tracks):
    lead = take_tracks[0]
    frames = F.valid_frames(lead.frames)
    out = F.output_features(lead, frames)
    ru = out[:, :3]
    nxt = F.from_root_space_points(np.stack([ru[:, 0], np.zeros(len(ru)), ru[:, 1]], -1),
                                   lead.root[frames], lead.heading[frames])
    np.testing.assert_allclose(nxt[:, [0, 2]], lead.root[frames + 1], atol=1e-9)
    np.testing.assert_allclose(np.angle(np.exp(1j * (lead.heading[frames] + ru[:, 2] - lead.heading[frames + 1]))),
                               0, atol=1e-9)


# ---------------------------------------------------------------- normalization

def test_normalization_std_floor(rng):
    x = np.stack([rng.normal(3.0, 2.0, 1000), np.full(1000, 1.0), rng.normal(0, 1e-4, 1000),
                  rng.choice([0.0, 1.0], 1000)], -1)
    mean, std = F.normalization(x)
    assert mean.dtype == np.float32 and std.dtype == np.float32
    np.testing.assert_allclose(mean, x.mean(0), rtol=1e-5, atol=1e-6)
    assert std[0] == pytest.approx(x[:, 0].std(), rel=1e-5)
    assert std[1] == pytest.approx(F.STD_FLOOR) and std[2] == pytest.approx(F.STD_FLOOR)
    assert std[3] == pytest.approx(x[:, 3].std(), rel=1e-5)
    _, std = F.normalization(x, floor=0.5)
    assert std[1] == pytest.approx(0.5) and std[3] == pytest.approx(0.5) and std[0] > 1.5
    assert np.isfinite((x - mean) / std).all()
