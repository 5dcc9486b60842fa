"""training/evaluation/motion_matching.py: feature groups, exact accelerated search, the policy contract."""
from __future__ import annotations

import json

import numpy as np
import pytest

from training.mirror import features as feat
from training.evaluation import motion_matching as MM
from training.mirror.features import FUTURE_OFFSETS, KEYS


def synthetic(rng, n=700, role="follower", **kw):
    """A database of smooth random walks (consecutive rows close, as in motion) plus a few
    exact duplicates, so ties are exercised."""
    x = np.cumsum(rng.normal(scale=0.05, size=(n, feat.INPUT_SIZE)), 0)
    fut = np.cumsum(rng.normal(scale=0.05, size=(n, 24)), 0)
    x[500:510], fut[500:510] = x[100:110], fut[100:110]
    y = rng.normal(size=(n, feat.OUTPUT_SIZE))
    return MM.MotionMatching(x, fut, y, role, **kw), x, fut, y


def test_groups_cover_the_query_and_are_balanced(rng):
    mm, x, fut, _ = synthetic(rng)
    raw = MM.query_features(x, fut, "follower")
    sizes = MM.group_sizes("follower")
    assert raw.shape[1] == sum(sizes) == mm.db.shape[1]
    assert len(sizes) == len(MM.FOLLOWER_GROUPS)
    # Per group, the summed variance of the scaled features is about weight^2 (here 1): no group
    # outweighs another because it has more numbers.
    scaled = (raw - mm.mean) / mm.scale
    start = 0
    for n in sizes:
        total = scaled[:, start:start + n].var(0).sum()
        assert 0.3 < total < 3.0
        start += n
    # The rotation onto principal axes keeps distances.
    a, b = scaled[3], scaled[400]
    assert np.linalg.norm(mm.db[3] - mm.db[400]) == pytest.approx(np.linalg.norm(a - b))


def test_weights_scale_their_group(rng):
    mm1, x, fut, y = synthetic(rng)
    mm2 = MM.MotionMatching(x, fut, y, weights={"self_position": 2.0})
    sl = slice(sum(MM.group_sizes("follower")[:6]), sum(MM.group_sizes("follower")[:7]))
    np.testing.assert_allclose(mm1.scale[sl] / mm2.scale[sl], 2.0)


@pytest.mark.parametrize("role", ["follower", "leader"])
def test_accelerated_search_returns_the_brute_force_frame(rng, role):
    mm, x, fut, _ = synthetic(rng, role=role)
    queries = np.concatenate([
        mm.db[rng.integers(0, len(mm), 50)] + rng.normal(scale=0.01, size=(50, mm.db.shape[1])),  # near
        mm.db[rng.integers(0, len(mm), 50)] + rng.normal(scale=1.0, size=(50, mm.db.shape[1])),   # far
        rng.normal(scale=5.0, size=(20, mm.db.shape[1])),                                        # nowhere
        mm.db[[100, 105, 500, 505]],                                                             # ties
    ])
    for q in queries:
        assert mm.boxes.nearest(q)[0] == MM.brute_force(mm.db, q)[0]
    # Duplicated rows: both searches answer the first copy.
    assert mm.boxes.nearest(mm.db[505])[0] == 105
    r = MM.bench(mm, queries[:20])
    assert r["agree"] == 20


def test_a_database_frame_finds_itself(rng):
    mm, x, fut, y = synthetic(rng)
    out = mm(x[[7, 300]], 0.0, None, self_future=fut[[7, 300]])
    np.testing.assert_array_equal(out["index"], [7, 300])
    np.testing.assert_allclose(out["output"], y[[7, 300]].astype(np.float32))
    assert out["output"].dtype == np.float32 and out["output"].shape == (2, feat.OUTPUT_SIZE)


def test_extrapolation_continues_a_straight_path():
    x = np.zeros((1, feat.INPUT_SIZE))
    v = np.array([0.01, 0.02])                          # metres per frame in root space
    past = np.zeros((KEYS, 4))
    past[:, :2] = v * feat.PAST_OFFSETS[:, None]
    past[:, 3] = 1.0
    x[0, MM.FOLLOWER_IN["self_trajectory_past"]] = past.ravel()
    fut = MM.extrapolate_future(x).reshape(KEYS, 4)
    np.testing.assert_allclose(fut[:, :2], v * FUTURE_OFFSETS[:, None])
    np.testing.assert_allclose(fut[:, 2:], [[0, 1]] * KEYS)


def test_plan_mode_uses_the_previous_match(rng):
    mm, x, fut, y = synthetic(rng)
    out = mm(x[[10]])
    np.testing.assert_allclose(mm.plan[0], y[out["index"][0], MM.OUT["trajectory_future"]], rtol=1e-6)
    mm.reset()
    assert mm.plan is None


# ---------------------------------------------------------------- on real data

@pytest.fixture(scope="module")
def real_mm(take_tracks):
    return {role: MM.build([take_tracks], role) for role in ("follower", "leader")}


def test_real_database_frame_finds_itself(take_tracks, real_mm):
    lead, follow = take_tracks
    frames = feat.valid_frames(lead.frames)[[0, 50, 120]]
    x = feat.follower_input(lead, follow, frames)
    out = real_mm["follower"](x, self_future=MM.own_future(follow, frames))
    np.testing.assert_array_equal(out["index"], [0, 50, 120])
    np.testing.assert_allclose(out["output"], feat.output_features(follow, frames), atol=1e-5)


def test_real_queries_agree_with_brute_force(take_tracks, real_mm):
    mm = real_mm["follower"]
    lead, follow = take_tracks
    frames = feat.valid_frames(lead.frames)[::9]
    x = feat.follower_input(lead, follow, frames) + 0.05   # off the database
    q = mm.normalize(MM.query_features(x, MM.extrapolate_future(x), "follower"))
    r = MM.bench(mm, q)
    assert r["agree"] == r["queries"]


def test_policy_drives_the_rollout_loop(real_mm, exported):
    """MotionMatching stands in for an OnnxPolicy in rollout.step, for either dancer."""
    from training.mirror import rollout as R
    manifest = json.loads((exported["models"] / "manifest.json").read_text())
    duet = R.start_duet(manifest)
    rng = np.random.default_rng(0)
    start = duet.follower.root.copy()
    for _ in range(20):
        R.step(duet, real_mm["leader"], real_mm["follower"], [0.0, 1.0], 0.5, rng)
    assert duet.frame == 20
    assert np.all(np.isfinite(duet.follower.positions)) and np.all(np.isfinite(duet.leader.positions))
    assert duet.follower.resets == 0 and duet.leader.resets == 0
    assert np.linalg.norm(duet.follower.root - start) > 0.01
    # The onnx follower and MM leader mix too.
    onnx = R.OnnxPolicy(exported["models"] / "follower.onnx")
    R.step(duet, real_mm["leader"], onnx, [0.0, 0.0], 0.5, rng)
    assert duet.frame == 21
