"""mirror/view.py: the follower reads her leader no lower than the partner floor, and the evaluation
commands read that floor from the manifest as the page does."""
import argparse

import numpy as np

from training.evaluation import options as O
from training.mirror import features as feat
from training.mirror import view as V
from training.mirror.guard import UprightGuard

RANGES = {"hip_low": 0.7, "head_above_hip_low": 0.6, "feet_wide": 1.0, "angle_high": [3.0, 0.6]}
OFFSETS = np.zeros((17, 3)).tolist()


def follower_input(hips: float) -> np.ndarray:
    """A follower input whose leader pose has its hips at `hips` and every other height 1 m above."""
    rng = np.random.default_rng(0)
    x = rng.normal(size=feat.INPUT_SIZE)
    pose = x[V.PARTNER_POSE].reshape(feat.N_JOINTS, V.POSE_WIDTH)
    pose[:, 1] = hips + 1.0
    pose[0, 1] = hips
    x[V.PARTNER_POSE] = pose.ravel()
    return x


def test_a_low_leader_is_lifted_whole_and_a_standing_one_left_alone():
    low, high = follower_input(0.75), follower_input(0.95)
    both = np.stack([low, high])
    np.testing.assert_allclose(V.partner_lift(both, 0.9), [0.15, 0.0], atol=1e-12)
    lifted = V.lift_partner(both, 0.9)
    np.testing.assert_array_equal(lifted[1], high)                      # above the floor: as it is
    diff = lifted[0] - low
    pose = diff[V.PARTNER_POSE].reshape(feat.N_JOINTS, V.POSE_WIDTH)
    keys = diff[V.PARTNER_KEY_JOINTS].reshape(-1, V.KEY_WIDTH)
    np.testing.assert_allclose(pose[:, 1], 0.15, atol=1e-12)            # every joint's height
    np.testing.assert_allclose(keys[:, 1], 0.15, atol=1e-12)            # every past key joint's
    assert np.count_nonzero(diff) == feat.N_JOINTS + len(keys)          # nothing else: no path, velocity, direction
    assert lifted[0][V.PARTNER_POSE.start + 1] == 0.9
    np.testing.assert_array_equal(V.lift_partner(low, 0.9), lifted[0])  # one input alike
    np.testing.assert_array_equal(both[0], low)                         # the caller's input is not touched


def test_the_view_wraps_the_policy_under_the_guard_and_counts_its_lifts():
    seen = []

    def policy(x, temperature, rng):
        seen.append(np.atleast_2d(x)[:, V.PARTNER_POSE.start + 1].copy())
        return {"output": np.zeros((len(np.atleast_2d(x)), feat.OUTPUT_SIZE))}

    m = {"defaultTemperature": 0.5, "plausibility": RANGES, "guard": {"samples": 4, "margin": 0.05},
         "followerView": {"partnerHipFloor": 0.9}, "skeleton": {"offsets": {"follower": OFFSETS, "leader": OFFSETS}}}
    ap = argparse.ArgumentParser()
    O.add_options(ap)
    args = ap.parse_args([])
    assert O.resolve(args, m) is None and args.partner_floor == 0.9
    f = O.follower_policy(policy, m, args, args.temperature)
    assert isinstance(f, UprightGuard) and isinstance(f.policy, V.PartnerView)
    rng = np.random.default_rng(0)
    f(follower_input(0.7), 0.5, rng)   # the zero output is far outside the range: the guard's batch runs too
    assert [s.tolist() for s in seen] == [[0.9], [0.9] * 4]             # both read him at the floor
    f(follower_input(1.0), 0.5, rng)
    assert O.lifted_count(f) == 1
    O.restart_count(f)
    assert O.lifted_count(f) == 0 and f.guarded == 0
    # --partner-floor 0 reads him as he is; a manifest without the field does too; a negative one is refused.
    args = ap.parse_args(["--partner-floor", "0"])
    O.resolve(args, m)
    assert not isinstance(O.follower_policy(policy, m, args, args.temperature).policy, V.PartnerView)
    args = ap.parse_args([])
    O.resolve(args, {k: v for k, v in m.items() if k != "followerView"})
    assert args.partner_floor == 0 and O.lifted_count(O.follower_policy(policy, m, args, 0.5)) == 0
    assert "--partner-floor" in O.resolve(ap.parse_args(["--partner-floor", "-1"]), m)
