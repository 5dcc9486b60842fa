"""training/mirror/bvh.py: parsing, channel order, forward kinematics, user-facing errors.

The hand-written file below has 4 joints and 2 End Sites with four different rotation channel
orders. Its world positions were worked out on paper with 90-degree rotations:
    Rx(90): (x, y, z) -> (x, -z, y)    Ry(90): (x, y, z) -> (z, y, -x)    Rz(90): (x, y, z) -> (-y, x, z)
and the BVH rule that channels apply in the order written (outermost first): "Xrotation
Yrotation Zrotation" with values (a, b, c) is Rx(a) @ Ry(b) @ Rz(c).
"""
from __future__ import annotations

import numpy as np
import pytest

from training.mirror.bvh import BvhError, axis_rotation, forward_kinematics, local_transforms, parse_bvh, read_bvh

TINY = """HIERARCHY
ROOT hip
{
\tOFFSET 0 0 0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
\tJOINT spine
\t{
\t\tOFFSET 0 1 0
\t\tCHANNELS 3 Xrotation Yrotation Zrotation
\t\tJOINT arm
\t\t{
\t\t\tOFFSET 1 0 0
\t\t\tCHANNELS 3 Yrotation Zrotation Xrotation
\t\t\tEnd Site
\t\t\t{
\t\t\t\tOFFSET 0 0 2
\t\t\t}
\t\t}
\t}
\tJOINT leg
\t{
\t\tOFFSET 0 -1 0
\t\tCHANNELS 3 Zrotation Xrotation Yrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 0 1
\t\t}
\t}
}
MOTION
Frames: 2
Frame Time: 0.5
0 1 0 0 0 0   0 0 0    0 0 0    0 0 0
1 2 3 90 0 0  90 0 90  90 90 0  0 0 90
"""

NAMES = ["hip", "spine", "arm", "arm_end", "leg", "leg_end"]
PARENTS = [-1, 0, 1, 2, 0, 4]

# Frame 0: no rotation, root at (0, 1, 0): offsets simply add up.
EXPECTED_F0 = [(0, 1, 0), (0, 2, 0), (1, 2, 0), (1, 2, 2), (0, 0, 0), (0, 0, 1)]
# Frame 1, by hand:
#   hip   = (1, 2, 3)                      R_hip = Rz90
#   spine = hip + Rz90 (0,1,0) = hip + (-1,0,0) = (0, 2, 3)
#           R_spine = Rz90 Rx90 Rz90  (local "X Y Z" = (90, 0, 90) -> Rx90 Rz90)
#   arm   = spine + Rz90 Rx90 Rz90 (1,0,0) = spine + (0,0,1) = (0, 2, 4)
#           R_arm = R_spine Ry90 Rz90  (local "Y Z X" = (90, 90, 0))
#   arm_end = arm + R_arm (0,0,2): Rz90 -> (0,0,2), Ry90 -> (2,0,0), Rz90 -> (0,2,0),
#             Rx90 -> (0,0,2), Rz90 -> (0,0,2); = (0, 2, 6)
#   leg   = hip + Rz90 (0,-1,0) = hip + (1,0,0) = (2, 2, 3)        R_leg = Rz90 Ry90
#   leg_end = leg + Rz90 Ry90 (0,0,1) = leg + Rz90 (1,0,0) = leg + (0,1,0) = (2, 3, 3)
# Applying any of the two-rotation joints in the reverse order moves arm / arm_end elsewhere
# ((-1, 2, 3) and (0, 0, 4)), so these numbers pin the channel order.
EXPECTED_F1 = [(1, 2, 3), (0, 2, 3), (0, 2, 4), (0, 2, 6), (2, 2, 3), (2, 3, 3)]

RZ90 = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]], float)
RX90 = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float)
RY90 = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], float)


def fk(bvh):
    return forward_kinematics(bvh.parents, *local_transforms(bvh))


def test_tiny_hierarchy_is_parsed():
    b = parse_bvh(TINY)
    assert b.names == NAMES
    assert b.parents == PARENTS
    assert b.channels[0] == ["Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation"]
    assert b.channels[1] == ["Xrotation", "Yrotation", "Zrotation"]
    assert b.channels[3] == [] and b.channels[5] == []          # End Sites have no channels
    np.testing.assert_array_equal(b.offsets[3], [0, 0, 2])
    np.testing.assert_array_equal(b.offsets[4], [0, -1, 0])
    assert b.frames == 2 and b.motion.shape == (2, 15)
    assert b.frame_time == 0.5 and b.fps == 2.0


def test_axis_rotations_are_right_handed():
    np.testing.assert_allclose(axis_rotation("X", np.array([90.0]))[0], RX90, atol=1e-12)
    np.testing.assert_allclose(axis_rotation("Y", np.array([90.0]))[0], RY90, atol=1e-12)
    np.testing.assert_allclose(axis_rotation("Z", np.array([90.0]))[0], RZ90, atol=1e-12)


def test_forward_kinematics_matches_hand_computation():
    rot, pos = fk(parse_bvh(TINY))
    np.testing.assert_allclose(pos[0], EXPECTED_F0, atol=1e-9)
    np.testing.assert_allclose(pos[1], EXPECTED_F1, atol=1e-9)
    # World rotations, also by hand.
    np.testing.assert_allclose(rot[1, 0], RZ90, atol=1e-9)
    np.testing.assert_allclose(rot[1, 1], RZ90 @ RX90 @ RZ90, atol=1e-9)
    np.testing.assert_allclose(rot[1, 2], RZ90 @ RX90 @ RZ90 @ RY90 @ RZ90, atol=1e-9)
    np.testing.assert_allclose(rot[1, 4], RZ90 @ RY90, atol=1e-9)
    np.testing.assert_allclose(rot[0], np.tile(np.eye(3), (6, 1, 1)), atol=1e-12)


def test_windows_line_endings_and_extra_whitespace_parse_the_same():
    a = parse_bvh(TINY)
    b = parse_bvh("\n\n" + TINY.replace("\n", "\r\n").replace("\t", "    ") + "\r\n\r\n")
    assert a.names == b.names and a.parents == b.parents
    np.testing.assert_array_equal(a.motion, b.motion)


def test_read_bvh_from_file(tmp_path):
    p = tmp_path / "tiny.bvh"
    p.write_text(TINY)
    np.testing.assert_allclose(fk(read_bvh(p))[1][1], EXPECTED_F1, atol=1e-9)


# ---------------------------------------------------------------- errors

def assert_user_error(excinfo, *words):
    """A BvhError whose message is one line, names the source and contains every word."""
    msg = str(excinfo.value)
    assert isinstance(excinfo.value, BvhError)
    assert "\n" not in msg, msg
    assert msg.startswith("tiny.bvh") or "tiny.bvh" in msg, msg
    for w in words:
        assert w.lower() in msg.lower(), f"{w!r} not in {msg!r}"


def test_not_a_bvh():
    with pytest.raises(BvhError) as e:
        parse_bvh("Frame,x,y,z\n0,1,2,3\n", "tiny.bvh")
    assert_user_error(e, "not a BVH")


def test_empty_file(tmp_path):
    p = tmp_path / "tiny.bvh"
    p.write_text("")
    with pytest.raises(BvhError) as e:
        read_bvh(p)
    msg = str(e.value)
    assert "tiny.bvh" in msg and ("empty" in msg.lower() or "not a bvh" in msg.lower()), msg


def test_missing_file(tmp_path):
    with pytest.raises(BvhError) as e:
        read_bvh(tmp_path / "tiny.bvh")
    assert_user_error(e, "cannot read")


def test_wrong_number_count():
    text = TINY.rstrip().rsplit(" ", 1)[0] + "\n"   # drop the last number: 29 instead of 30
    with pytest.raises(BvhError) as e:
        parse_bvh(text, "tiny.bvh")
    assert_user_error(e, "2 frames", "15 channels", "29")


def test_too_many_numbers():
    with pytest.raises(BvhError) as e:
        parse_bvh(TINY + "0 0 0\n", "tiny.bvh")
    assert_user_error(e, "2 frames", "15 channels", "33")


def test_non_numeric_value():
    with pytest.raises(BvhError) as e:
        parse_bvh(TINY.replace("90 90 0", "90 ninety 0"), "tiny.bvh")
    assert_user_error(e, "ninety")


def test_missing_motion_section():
    """A file cut after its HIERARCHY (no MOTION keyword at all) must say that MOTION is missing,
    not leak an internal IndexError."""
    text = TINY.split("MOTION")[0]
    with pytest.raises(BvhError) as e:
        parse_bvh(text, "tiny.bvh")
    assert_user_error(e, "MOTION")


def test_motion_without_frame_header():
    text = TINY.replace("Frames: 2\nFrame Time: 0.5\n", "")
    with pytest.raises(BvhError) as e:
        parse_bvh(text, "tiny.bvh")
    assert_user_error(e, "Frames")


def test_non_positive_frame_time():
    with pytest.raises(BvhError) as e:
        parse_bvh(TINY.replace("Frame Time: 0.5", "Frame Time: 0"), "tiny.bvh")
    assert_user_error(e, "Frame Time")


def test_unknown_channel_name_is_rejected():
    """A channel that is neither [XYZ]position nor [XYZ]rotation is read as a Z rotation
    (local_transforms takes name[0] and treats anything not X/Y as Z): silently wrong FK."""
    with pytest.raises(BvhError) as e:
        parse_bvh(TINY.replace("Yrotation Zrotation Xrotation", "Yrotation Wrotation Xrotation"), "tiny.bvh")
    assert_user_error(e, "Wrotation")
