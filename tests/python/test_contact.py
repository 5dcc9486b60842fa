"""The interaction metrics, the training terms on the decoded body, and the run-time contact layer
(training/evaluation/metrics.py, partner_losses.py, footik.py, contact.py) on cases with a known answer."""
from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from training.evaluation import metrics as M
from training.learning import partner_losses as P
from training.mirror.contact import HIP_GLIDE, SEPARATION, ContactLayer, separate, spine_gap
from training.mirror.footik import ANKLE_FLOOR, MAX_LOCK_DISTANCE, MAX_STANCE, FootLock, cap_stance, two_bone_ik
from training.mirror.skeleton import FEET, PARENTS


def standing(x: float = 0.0, z: float = 0.0) -> np.ndarray:
    """A crude upright body [17, 3] at (x, z): spine up the y axis, arms out, legs down."""
    p = np.zeros((17, 3))
    p[:5, 1] = [0.95, 1.1, 1.3, 1.5, 1.65]
    p[5:8] = [[0.18, 1.45, 0], [0.42, 1.45, 0.2], [0.65, 1.45, 0]]      # elbows bent forward
    p[8:11] = [[-0.18, 1.45, 0], [-0.42, 1.45, 0.2], [-0.65, 1.45, 0]]
    p[11:14] = [[0.1, 0.95, 0], [0.1, 0.5, 0.1], [0.1, 0.08, 0]]     # knees a little bent
    p[14:17] = [[-0.1, 0.95, 0], [-0.1, 0.5, 0.1], [-0.1, 0.08, 0]]
    p[:, 0] += x
    p[:, 2] += z
    return p


def bone_lengths(p):
    return np.linalg.norm(p[1:] - p[PARENTS[1:]], axis=-1)


def test_segment_distance_matches_dense_sampling():
    rng = np.random.default_rng(0)
    p = rng.normal(size=(500, 4, 3))
    p[:50, 1] = p[:50, 0]            # p is a point
    p[50:100, 3] = p[50:100, 2]      # q is a point
    p[100:150, 3] = p[100:150, 2] + (p[100:150, 1] - p[100:150, 0])   # parallel
    d = M.segment_distance(p[:, 0], p[:, 1], p[:, 2], p[:, 3])
    s = np.linspace(0, 1, 201)[None, :, None]
    a = p[:, None, 0] + (p[:, 1] - p[:, 0])[:, None] * s
    b = p[:, None, 2] + (p[:, 3] - p[:, 2])[:, None] * s
    dense = np.linalg.norm(a[:, :, None] - b[:, None], axis=-1).min((1, 2))
    assert np.all(d <= dense + 1e-9) and np.all(d > dense - 0.01)


def test_interaction_counts_overlap_hands_and_skate():
    lead = np.stack([standing(0, 0)] * 4)
    # Overlapping (hands side by side too), 1.4 m apart (the leader's left hand at x 0.65 meets the
    # follower's right hand at x 0.75), then 3 m apart.
    close = np.stack([standing(0.1, 0)] * 2 + [standing(1.4, 0), standing(3.0, 0)])
    r = M.interaction(lead, close)
    assert r["interpenetration"] == 0.5
    assert r["hand_hold"] == 0.75
    assert r["skate_leader_cm"] == 0.0
    slide = lead.copy()
    slide[:, FEET, 0] += np.arange(4)[:, None] * 0.02     # 2 cm a frame, ankles low
    assert M.interaction(slide, close)["skate_leader_cm"] == pytest.approx(2.0)
    contacts = np.array([[1, 1], [1, 1], [0, 0], [0, 0]])
    r = M.interaction(slide, close, contacts, contacts)
    assert r["contact_skate_leader_cm"] == pytest.approx(2.0)   # only the step 0 -> 1 counts
    assert M.ratio_to({"a": 2.0, "b": 0.0}, {"a": 1.0, "b": 3.0}) == {"a": 0.5, "b": None}


def test_steering_response_time_and_speed():
    fps = 30
    root = np.zeros((240, 2))
    for f in range(1, 240):   # north at 0.5 m/s, then east from frame 120 on after a 0.5 s delay
        v = np.array([0, 0.5]) if f < 135 else np.array([0.5, 0])
        root[f] = root[f - 1] + v / fps
    r = M.steering_response(root, 120, np.array([1.0, 0.0]))
    assert r["speed"] == pytest.approx(0.5)
    assert 0.5 <= r["seconds"] <= 0.5 + 10 / fps


def test_two_bone_ik_keeps_bones_and_reaches():
    p = standing()
    before = bone_lengths(p)
    two_bone_ik(p, 11, 12, 13, np.array([0.2, 0.2, 0.1]), (0, 0, 1))
    assert np.allclose(bone_lengths(p), before)
    assert np.allclose(p[13], [0.2, 0.2, 0.1], atol=1e-6)


def test_two_bone_ik_keeps_the_least_bend_short_of_an_unreachable_target():
    p = standing()
    before = bone_lengths(p)
    two_bone_ik(p, 11, 12, 13, np.array([0.1, -2.0, 0.0]), (0, 0, 1), 0.2)
    assert np.allclose(bone_lengths(p), before)
    u, v = p[12] - p[11], p[13] - p[12]
    assert np.arccos(u @ v / np.linalg.norm(u) / np.linalg.norm(v)) == pytest.approx(0.2, abs=1e-6)


def test_foot_lock_holds_a_planted_foot_and_never_sinks():
    lock = FootLock()
    p = standing()
    lock.apply(p, [1, 0], 0.0)
    planted = p[FEET[0]].copy()
    moved = standing(0.05, 0)          # the model slides the body 5 cm
    lock.apply(moved, [1, 0], 0.0)
    assert np.allclose(moved[FEET[0]], planted, atol=1e-6)
    low = standing()
    low[FEET[1], 1] = 0.0
    FootLock().apply(low, [0, 0], 0.0)
    assert low[FEET[1], 1] >= ANKLE_FLOOR - 1e-9


def test_a_glide_during_a_contact_never_slides_the_lock():
    """The network's body stays; the contact layer's glide moves the drawn body 0.3 m (more than
    MAX_LOCK_DISTANCE). Told of the glide, the lock stays where the foot was planted and the leg
    reaches back to it; not told, it slides to MAX_LOCK_DISTANCE behind the drawn foot (as
    web/mirror/footik.test.ts)."""
    told, blind = FootLock(), FootLock()
    told.apply(standing(), [1, 0], 0.0, (0.0, 0.0))
    blind.apply(standing(), [1, 0], 0.0)
    planted = standing()[FEET[0]].copy()
    glided, slid = standing(-0.3, 0), standing(-0.3, 0)
    told.apply(glided, [1, 0], 0.0, (-0.3, 0.0))
    blind.apply(slid, [1, 0], 0.0)
    np.testing.assert_allclose(told.target[0], [planted[0], max(planted[1], ANKLE_FLOOR), planted[2]])
    np.testing.assert_allclose(blind.target[0], [0.1 - 0.3 + MAX_LOCK_DISTANCE, max(planted[1], ANKLE_FLOOR), 0.0])
    assert glided[FEET[0], 0] > slid[FEET[0], 0] + 0.01


def test_a_lock_never_holds_the_feet_wider_than_max_stance():
    """A lock trailing 1.5 m from the other foot comes back along the line to the model's foot until
    the stance is MAX_STANCE (0.4 of the way: the distance is 0.5 at the foot); a foot already wider
    locks where it is. web/mirror/footik.test.ts checks capStance on the same numbers."""
    target, foot, other = np.array([1.0, 0.1, 0.0]), np.array([0.0, 0.1, 0.0]), np.array([-0.5, 0.1, 0.0])
    cap_stance(target, foot, other)
    assert MAX_STANCE == 0.9
    np.testing.assert_allclose(target, [0.4, 0.1, 0.0], atol=1e-12)
    assert np.linalg.norm(target - other) == pytest.approx(MAX_STANCE)
    wide = np.array([2.0, 0.1, 0.0])
    cap_stance(wide, np.array([1.5, 0.1, 0.0]), other)
    np.testing.assert_allclose(wide, [1.5, 0.1, 0.0], atol=1e-12)
    near = np.array([0.2, 0.1, 0.0])
    cap_stance(near, foot, other)                      # within the stance: untouched
    np.testing.assert_allclose(near, [0.2, 0.1, 0.0])


def test_separate_pushes_overlapping_spines_apart_horizontally():
    a, b = standing(0, 0), standing(0.1, 0)
    push = separate(a, b)
    assert push == pytest.approx((SEPARATION - 0.1) / 2)
    assert spine_gap(a, b)[0] == pytest.approx(SEPARATION)
    assert a[0, 1] == 0.95                              # heights unchanged
    assert separate(standing(0, 0), standing(1, 0)) == 0.0


def test_contact_layer_brings_near_hands_together_and_keeps_bones():
    lead, follow = standing(0, 0), standing(1.4, 0)   # hands 0.1 m apart: within HAND_FULL
    lengths = bone_lengths(follow)
    layer = ContactLayer()
    for _ in range(20):
        a, b = lead.copy(), follow.copy()
        layer.apply(a, b, [0, 0], [0, 0], 0.0, 0.0)
    assert layer.hold > 0.6
    gap = np.linalg.norm(a[7] - b[10])
    assert gap < 0.1 * (1 - 0.6) + 0.06
    far = standing(1.75, 0)                            # 0.45 m apart: out of reach, left alone
    b = far.copy()
    ContactLayer().apply(standing(0, 0), b, [0, 0], [0, 0], 0.0, 0.0)
    assert np.allclose(b, far)
    assert np.allclose(bone_lengths(b), lengths)


def test_contact_layer_glides_each_body_over_the_floor():
    """The first step shows each body where its network put it; the shown hips step by a running
    mean of the network's steps: a jump over the floor is shown a HIP_GLIDE share at once and the
    rest over the next steps, never past it, the body above the knees together, its height
    unchanged, planted feet or not; the free feet go where the network put them, as far as the legs
    reach (a small glide: exactly there); clear() shows it where it is again."""
    legs = list(FEET) + [PARENTS[f] for f in FEET]
    body = [j for j in range(17) if j not in legs]
    layer = ContactLayer()
    lead, follow = standing(0, 0), standing(3, 0)
    a, b = lead.copy(), follow.copy()
    layer.apply(a, b, [0, 0], [0, 0], 0.0, 0.0)
    assert np.allclose(b, follow)
    moved = standing(3, 1.0)
    b = moved.copy()
    layer.apply(lead.copy(), b, [0, 0], [0, 0], 0.0, 0.0)
    assert np.allclose(b[body, 2] - moved[body, 2], HIP_GLIDE - 1.0)
    assert np.allclose(b[body][:, [0, 1]], moved[body][:, [0, 1]])
    # The free feet reach on toward the network's, further than the glided body carried them.
    assert np.all(b[FEET, 2] - moved[FEET, 2] > HIP_GLIDE - 1.0 + 0.05)
    shown, step = HIP_GLIDE, HIP_GLIDE
    for contacts in ([0, 0], [1, 0], [1, 1]):
        b = moved.copy()
        layer.apply(lead.copy(), b, [0, 0], contacts, 0.0, 0.0)
        step *= 1 - HIP_GLIDE
        shown += step
        assert np.isclose(b[0, 2] - moved[0, 2], shown - 1.0) and shown < 1.0   # the hips (a planted foot is locked)
    layer.clear()
    b = moved.copy()
    layer.apply(lead.copy(), b, [0, 0], [0, 0], 0.0, 0.0)
    assert np.allclose(b, moved)
    near = standing(3, 1.05)                          # a 5 cm step: the hips glide 1.5 cm of it
    b = near.copy()
    layer.apply(lead.copy(), b, [0, 0], [0, 0], 0.0, 0.0)
    assert np.isclose(b[0, 2] - near[0, 2], (HIP_GLIDE - 1.0) * 0.05)
    assert np.allclose(b[FEET], near[FEET], atol=1e-9)


def test_partner_terms_are_zero_on_the_recording_and_bite_on_error(prepared3):
    """On recorded samples the decoded body is the recorded one: no penetration beyond the
    recording's, matched hand distances; shifting the output root into the partner costs."""
    # The offsets in stats.npz are the first take's (prepare): read that take's samples, wherever
    # the split put it (synthetic couples vary their skeletons from take to take).
    for split in ("train", "validation", "test"):
        with np.load(prepared3 / f"{split}.npz") as z:
            rows = np.nonzero(z["take"] == 0)[0][:256]
            if len(rows):
                x = torch.tensor(z["follower_input"][rows], dtype=torch.float64)
                y = torch.tensor(z["follower_output"][rows], dtype=torch.float64)
                mirror = z["mirror"][rows]
                break
    from training.data.prepared import load_offsets
    offsets = load_offsets(str(prepared3), "follower", "cpu").double()[torch.from_numpy(mirror).long()]
    exact = P.partner_terms(y, y, x, offsets, "follower")
    assert float(exact["interaction"]) == 0.0
    # FK of the decoded rotations reproduces the pose block's positions.
    pose = y[:, P.OUT["pose"]].reshape(-1, 17, 12)[..., :3]
    still = torch.cat([torch.zeros(len(y), 3, dtype=y.dtype), y[:, 3:]], 1)
    assert torch.allclose(P.decoded_positions(still, offsets), pose, atol=1e-4)
    # Move the decoded dancer onto the partner's hip: penetration and interaction both grow.
    partner_hip = P.block_positions(x, P.input_slices("follower")["partner_pose"])[:, 0]
    onto = y.clone()
    onto[:, 0], onto[:, 1] = partner_hip[:, 0], partner_hip[:, 2]
    worse = P.partner_terms(onto, y, x, offsets, "follower")
    assert float(worse["penetration"]) > float(exact["penetration"]) + 1e-3
    assert float(worse["interaction"]) > 0.0


def test_foot_contact_term_spares_turning_samples(prepared3):
    """contact_spare_turning: the samples whose recorded heading turns faster than the threshold
    leave the foot-contact term (a pivot on a planted foot), the others weigh as before."""
    with np.load(prepared3 / "train.npz") as z:
        rows = np.nonzero(z["take"] == z["take"][0])[0][:256]
        x = torch.tensor(z["leader_input"][rows], dtype=torch.float64)
        y = torch.tensor(z["leader_output"][rows], dtype=torch.float64)
        mirror = z["mirror"][rows]
    from training.data.prepared import load_offsets
    offsets = load_offsets(str(prepared3), "leader", "cpu").double()[torch.from_numpy(mirror).long()]
    slid = y.clone()
    slid[:, 0] += 0.05                  # every decoded body 5 cm off: planted feet slide
    turn = y[:, P.HEADING_CHANGE].abs()
    threshold = float(turn.median())
    full = float(P.partner_terms(slid, y, x, offsets, "leader", True)["foot_contact"])
    spared = float(P.partner_terms(slid, y, x, offsets, "leader", True, spare_turning=threshold)["foot_contact"])
    assert full > 0.0
    assert 0.0 < spared < full
    keep = turn <= threshold            # the term by hand over the samples that turn slowly
    me = P.decoded_positions(slid, offsets)
    before = P.block_positions(x, P.input_slices("leader")["self_pose"])
    slide = (me[:, P.FEET][..., [0, 2]] - before[:, P.FEET][..., [0, 2]]).pow(2).sum(-1)
    contacts = y[:, P.OUT["contacts"]].clamp(0, 1) * keep[:, None]
    assert spared == pytest.approx(float((contacts * slide).mean()), rel=1e-9)
    huge = float(P.partner_terms(slid, y, x, offsets, "leader", True, spare_turning=10.0)["foot_contact"])
    assert huge == pytest.approx(full, rel=1e-12)


def test_interaction_command_on_fresh_models(exported, data3, tmp_path, capsys):
    from training.evaluation.interaction import main
    rc = main(["--data", str(data3), "--takes", "06", "--models", str(exported["models"]), "--seeds", "1",
               "--seconds", "2", "--out", str(tmp_path), "--quiet"])
    assert rc == 0
    res = json.loads((tmp_path / "interaction.json").read_text())
    assert set(res["methods"]) >= {"ours", "ccm", "motion_matching"}
    for row in res["methods"].values():
        for proto in ("teacher_forced", "free_running", "free_running_layer", "steered", "steered_layer"):
            assert 0.0 <= row[proto]["interpenetration"] <= 1.0
            for who in ("leader", "follower"):   # plausibility against the manifest's range
                assert 0.0 <= row[proto][f"implausible_{who}"] <= 1.0
                assert 0.0 <= row[proto][f"angles_out_{who}"] <= 1.0
        assert row["steering"]["trials"] == 8
    assert 0.0 <= res["recording"]["implausible_follower"] <= 1.0
    assert "recording" in (tmp_path / "interaction.md").read_text()
