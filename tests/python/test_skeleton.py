"""training/mirror/skeleton.py: 17-joint reduction, metres, resampling, root/heading, mirroring."""
from __future__ import annotations

import numpy as np
import pytest

from training.mirror.bvh import BvhError, forward_kinematics, local_transforms, parse_bvh
from training.mirror.skeleton import (FPS, JOINT_NAMES, MIRROR, PARENTS, SCALE, Motion, forward_kinematics_reduced,
                               gaussian_smooth, mirror_motion, reduce_bvh, resample, root_from_motion)


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


# ---------------------------------------------------------------- reduction of a real take

def test_reduce_keeps_forward_kinematics_exact(take_bvh):
    m = reduce_bvh(take_bvh)
    assert m.positions.shape == (take_bvh.frames, 17, 3) and m.rotations.shape == (take_bvh.frames, 17, 3, 3)
    assert m.fps == pytest.approx(120, rel=1e-3)
    # Full-skeleton FK (43 joints + End Sites), independent of the reduction.
    world_rot, world_pos = forward_kinematics(take_bvh.parents, *local_transforms(take_bvh))
    index = [take_bvh.names.index(n) for n in JOINT_NAMES]
    full = world_pos[:, index] * SCALE
    hip = world_pos[:, index[0]] * SCALE
    reduced = forward_kinematics_reduced(m.offsets, hip, world_rot[:, index])
    err = np.linalg.norm(reduced - full, axis=-1).max()
    assert err < 1e-6, f"reduced FK is {err:.2e} m off the full skeleton"
    np.testing.assert_allclose(m.positions, full, atol=1e-9)
    np.testing.assert_allclose(m.rotations, world_rot[:, index], atol=1e-12)
    # FK from the Motion's own rotations and hip, as the run time does it.
    np.testing.assert_allclose(forward_kinematics_reduced(m.offsets, m.positions[:, 0], m.rotations),
                               m.positions, atol=1e-6)


def test_reduced_motion_is_in_metres(take_pair):
    """SCALE puts the head joint of a standing adult at ~1.5-1.9 m and the ankles near the floor."""
    for m in take_pair:
        head = m.positions[:, JOINT_NAMES.index("head"), 1]
        assert 1.4 < np.median(head) < 1.9, np.median(head)
        feet = m.positions[:, [JOINT_NAMES.index("lFoot"), JOINT_NAMES.index("rFoot")], 1]
        assert 0.0 < np.percentile(feet, 5) < 0.2, np.percentile(feet, 5)
        bones = np.linalg.norm(m.offsets[1:], axis=-1)
        assert 0.05 < bones.min() and bones.max() < 0.6, bones


def test_local_rotations_compose_back(take_pair):
    m = resample(take_pair[0], FPS)
    local = m.local_rotations()
    for j, p in enumerate(PARENTS):
        expect = m.rotations[:, j] if p < 0 else m.rotations[:, p] @ local[:, j]
        np.testing.assert_allclose(expect, m.rotations[:, j], atol=1e-10)


def test_missing_joint_is_named(couples):
    text = (couples / "60_10.bvh").read_text().replace("lFoot", "lToe")
    with pytest.raises(BvhError) as e:
        reduce_bvh(parse_bvh(text, "60_10.bvh"), "60_10.bvh")
    msg = str(e.value)
    assert "lFoot" in msg and "60_10.bvh" in msg and "\n" not in msg, msg


def test_rotating_dropped_joint_is_refused(take_bvh):
    """rCollar is dropped (folded into rShldr's offset); that is only exact if it never rotates."""
    j = take_bvh.names.index("rCollar")
    col = sum(len(c) for c in take_bvh.channels[:j])
    motion = take_bvh.motion.copy()
    motion[10:, col] += 20.0
    bad = type(take_bvh)(take_bvh.names, take_bvh.parents, take_bvh.offsets, take_bvh.channels,
                         take_bvh.frame_time, motion)
    with pytest.raises(BvhError, match="rCollar"):
        reduce_bvh(bad, "x.bvh")


# ---------------------------------------------------------------- mirroring

def test_mirror_twice_is_identity(take_pair):
    m = take_pair[1]
    mm = mirror_motion(mirror_motion(m))
    np.testing.assert_allclose(mm.positions, m.positions, atol=1e-12)
    np.testing.assert_allclose(mm.rotations, m.rotations, atol=1e-12)
    np.testing.assert_allclose(mm.offsets, m.offsets, atol=1e-12)


def test_mirror_swaps_sides_and_stays_a_skeleton(take_pair):
    m = resample(take_pair[0], FPS)
    mi = mirror_motion(m)
    assert sorted(MIRROR) == list(range(17)) and all(MIRROR[MIRROR[j]] == j for j in range(17))
    L, R = JOINT_NAMES.index("lHand"), JOINT_NAMES.index("rHand")
    np.testing.assert_allclose(mi.positions[:, L], m.positions[:, R] * [-1, 1, 1])
    # Still proper rotations ...
    np.testing.assert_allclose(np.linalg.det(mi.rotations), 1.0, atol=1e-9)
    # ... and FK with the mirrored offsets reproduces the mirrored positions.
    np.testing.assert_allclose(forward_kinematics_reduced(mi.offsets, mi.positions[:, 0], mi.rotations),
                               mi.positions, atol=1e-6)


# ---------------------------------------------------------------- resampling

def test_resample_keeps_duration_and_real_frames(take_pair):
    m = take_pair[0]
    F = m.frames
    for phase in range(4):
        r = resample(m, FPS, phase)
        assert r.fps == FPS
        assert abs((F - 1) / 120 - (r.frames - 1) / 30) <= 1 / 30 + 1e-9, (phase, F, r.frames)
        # Every 30 fps frame is a recorded 120 fps frame, 4 apart, starting at the phase.
        for k in (0, 1, r.frames // 2, r.frames - 1):
            np.testing.assert_array_equal(r.positions[k], m.positions[phase + 4 * k])
            np.testing.assert_array_equal(r.rotations[k], m.rotations[phase + 4 * k])
    frames = sum(resample(m, FPS, p).frames for p in range(4))
    assert frames == F


def test_resample_refuses_impossible_rates(take_pair):
    m = take_pair[0]
    with pytest.raises(ValueError, match="whole multiple"):
        resample(m, 50)
    with pytest.raises(ValueError, match="phase"):
        resample(m, FPS, 4)


# ---------------------------------------------------------------- root and heading

def procedural_body(frames=40):
    """A stick figure in rest pose (identity rotations), facing +Z: its left side is +X."""
    offsets = np.zeros((17, 3))
    for name, off in {"abdomen": (0, .12, 0), "chest": (0, .2, 0), "neck": (0, .2, 0), "head": (0, .13, 0),
                      "lShldr": (.18, .05, 0), "lForeArm": (0, -.3, 0), "lHand": (0, -.25, 0),
                      "rShldr": (-.18, .05, 0), "rForeArm": (0, -.3, 0), "rHand": (0, -.25, 0),
                      "lThigh": (.1, -.05, 0), "lShin": (0, -.42, 0), "lFoot": (0, -.4, 0),
                      "rThigh": (-.1, -.05, 0), "rShin": (0, -.42, 0), "rFoot": (0, -.4, 0)}.items():
        offsets[JOINT_NAMES.index(name)] = off
    rotations = np.tile(np.eye(3), (frames, 17, 1, 1))
    hip = np.tile([0.0, 0.95, 0.0], (frames, 1))
    return Motion(forward_kinematics_reduced(offsets, hip, rotations), rotations, offsets, FPS)


@pytest.mark.parametrize("angle", [0.0, 0.7, np.pi / 2, -2.5, np.pi - 1e-3])
def test_root_heading_of_rotated_body(angle):
    body = procedural_body()
    R = rot_y(angle)
    shift = np.array([1.5, 0.0, -2.0])
    moved = Motion(body.positions @ R.T + shift, R @ body.rotations, body.offsets, FPS)
    # FK still agrees after turning the whole body (rotations and positions moved together).
    np.testing.assert_allclose(forward_kinematics_reduced(moved.offsets, moved.positions[:, 0], moved.rotations),
                               moved.positions, atol=1e-9)
    root, heading = root_from_motion(moved)
    np.testing.assert_allclose(root, np.tile([1.5, -2.0], (body.frames, 1)), atol=1e-9)
    err = np.angle(np.exp(1j * (heading - angle)))
    np.testing.assert_allclose(err, 0.0, atol=1e-9)
    # Facing direction = R_y(angle) applied to +Z.
    np.testing.assert_allclose(R @ [0, 0, 1], [np.sin(angle), 0, np.cos(angle)], atol=1e-12)


def test_root_follows_a_turning_body_without_lag():
    """A body spinning at a constant rate: the smoothed heading stays on the true angle in the
    middle of the clip (Gaussian smoothing of a linear signal does not shift it)."""
    body = procedural_body(60)
    angles = np.linspace(0, 2.0, 60)
    pos = np.stack([body.positions[i] @ rot_y(a).T for i, a in enumerate(angles)])
    rots = np.stack([rot_y(a) @ body.rotations[i] for i, a in enumerate(angles)])
    _, heading = root_from_motion(Motion(pos, rots, body.offsets, FPS))
    np.testing.assert_allclose(heading[10:-10], angles[10:-10], atol=2e-3)


def test_gaussian_smooth_keeps_length_and_lines():
    x = np.stack([np.full(50, 3.0), np.linspace(-1, 4, 50)], -1)
    y = gaussian_smooth(x, 2.0)
    assert y.shape == x.shape
    np.testing.assert_allclose(y[:, 0], 3.0)
    np.testing.assert_allclose(y[8:-8, 1], x[8:-8, 1], atol=1e-12)
    np.testing.assert_array_equal(gaussian_smooth(x, 0), x)


def test_time_warp_at_tempo_1_is_resample_and_keeps_rotations_rotations(take_pair):
    from training.mirror.skeleton import FPS, resample, time_warp
    lead = take_pair[0]
    for phase in (0, 3):
        a, b = time_warp(lead, 1.0, FPS, phase), resample(lead, FPS, phase)
        assert a.frames == b.frames
        np.testing.assert_allclose(a.positions, b.positions, atol=1e-12)
        np.testing.assert_allclose(a.rotations, b.rotations, atol=1e-9)
    fast = time_warp(lead, 1.1)
    assert abs(fast.frames - lead.frames / (lead.fps / FPS) / 1.1) <= 1
    r = fast.rotations
    np.testing.assert_allclose(r @ np.swapaxes(r, -1, -2), np.broadcast_to(np.eye(3), r.shape), atol=1e-9)
    assert np.allclose(np.linalg.det(r), 1.0)
    # 1.1x as fast: frame k of the warped motion is source time 1.1 k / 30 s (linear blend).
    t = 1.1 * 10 * round(lead.fps / FPS)   # the file says 120.0048 fps; resample reads 120 too
    i = int(t)
    expect = lead.positions[i] + (t - i) * (lead.positions[i + 1] - lead.positions[i])
    np.testing.assert_allclose(fast.positions[10], expect, atol=1e-9)
    with pytest.raises(ValueError, match="tempo"):
        time_warp(lead, 0.0)
