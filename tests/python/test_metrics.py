"""training/evaluation/metrics.py on cases whose answer is known by hand, and the evaluation encoder's
determinism and cache."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from training.evaluation import metrics as M
from training.mirror.features import CONTACT_HEIGHT, Track
from training.mirror.skeleton import FEET, FPS


def test_fid_of_a_set_with_itself_is_zero(rng):
    x = rng.normal(size=(300, 8)) @ rng.normal(size=(8, 8))
    assert M.fid(x, x) == pytest.approx(0.0, abs=1e-9)


def test_fid_matches_the_closed_form(rng):
    scipy_linalg = pytest.importorskip("scipy.linalg")
    a = rng.normal(size=(400, 5)) @ rng.normal(size=(5, 5))
    b = rng.normal(size=(500, 5)) * 2 + 3
    sa, sb = np.cov(a, rowvar=False), np.cov(b, rowvar=False)
    ref = (((a.mean(0) - b.mean(0)) ** 2).sum() + np.trace(sa + sb)
           - 2 * np.trace(scipy_linalg.sqrtm(sa @ sb).real))
    assert M.fid(a, b) == pytest.approx(ref, rel=1e-6)
    assert M.fid(a, b) == pytest.approx(M.fid(b, a), rel=1e-9)


def test_fid_of_a_shifted_set_is_the_squared_shift(rng):
    x = rng.normal(size=(200, 4))
    shift = np.array([1.0, -2.0, 0.5, 0.0])
    assert M.fid(x, x + shift) == pytest.approx((shift ** 2).sum(), rel=1e-9)


def test_mpjpe_of_a_shifted_pose_is_the_shift(rng):
    pose = rng.normal(size=(10, 17, 3))
    d = np.array([0.03, 0.0, -0.04])          # 5 cm
    assert M.mpjpe_cm(pose + d, pose) == pytest.approx(5.0)
    assert M.mpjpe_cm(pose, pose) == 0.0


def walking_feet(frames: int, foot_speed: float, height: float) -> np.ndarray:
    """17 joints; both ankles at `height`, moving along x at foot_speed m/s; the rest above."""
    p = np.zeros((frames, 17, 3))
    p[:, :, 1] = 1.0
    p[:, FEET, 1] = height
    p[:, FEET, 0] = (np.arange(frames) * foot_speed / FPS)[:, None]
    return p


def test_foot_skating_of_a_planted_foot_is_zero():
    assert M.foot_skate_cm(walking_feet(20, 0.0, 0.08)) == 0.0


def test_foot_skating_measures_a_sliding_planted_foot():
    # 0.3 m/s on the floor: 1 cm per frame at 30 fps.
    assert M.foot_skate_cm(walking_feet(20, 0.3, 0.08)) == pytest.approx(1.0)
    # The same motion in the air is a step, not a slide.
    assert M.foot_skate_cm(walking_feet(20, 0.3, CONTACT_HEIGHT + 0.1)) == 0.0
    # Given contacts take precedence over the height rule.
    contacts = np.zeros((19, 2), bool)
    contacts[:5, 0] = True
    assert M.foot_skate_cm(walking_feet(20, 0.3, 0.5), contacts) == pytest.approx(1.0)


def test_jitter_of_constant_velocity_and_acceleration_is_zero(rng):
    t = np.arange(30)[:, None, None] / FPS
    v, a = rng.normal(size=(1, 17, 3)), rng.normal(size=(1, 17, 3))
    assert M.jitter(v * t) == pytest.approx(0.0, abs=1e-6)
    assert M.jitter(v * t + a * t ** 2) == pytest.approx(0.0, abs=1e-6)


def test_jitter_of_a_cubic_is_its_jerk():
    # x = s^3 (s in seconds) has jerk 6 m/s^3; the third difference of a cubic is exact.
    s = np.arange(20) / FPS
    p = np.zeros((20, 17, 3))
    p[..., 0] = (s ** 3)[:, None]
    assert M.jitter(p) == pytest.approx(6.0, rel=1e-6)


def test_hand_distance_takes_the_closest_pair():
    a, b = np.zeros((3, 17, 3)), np.zeros((3, 17, 3))
    a[:, M.HANDS[0]] = [0, 1, 0]
    a[:, M.HANDS[1]] = [5, 1, 0]
    b[:, M.HANDS[0]] = [9, 1, 0]
    b[:, M.HANDS[1]] = [0.3, 1, 0.4]           # 0.5 m from a's left hand
    assert M.hand_distance(a, b) == pytest.approx(0.5)


def test_codebook_error_counts_wrong_channels():
    target = M.one_hot(np.array([[0, 3], [1, 1]]), 4)
    assert target.shape == (2, 8)
    assert M.codebook_error(target, target) == 0.0
    # Row 0 wrong in one channel: 2 of 8 entries differ; row 1 right: mean over 16 = 2/16.
    est = M.one_hot(np.array([[2, 3], [1, 1]]), 4)
    assert M.codebook_error(target, est) == pytest.approx(2 / 16)


def test_diversity_is_the_mean_pair_distance(rng):
    assert M.diversity(np.array([[0.0, 0.0], [3.0, 4.0]])) == pytest.approx(5.0)
    assert M.diversity(np.ones((10, 3))) == 0.0
    x = rng.normal(size=(100, 6))
    assert M.diversity(x) == M.diversity(x)              # fixed seed
    assert M.diversity(x * 2) == pytest.approx(2 * M.diversity(x))


def test_windows_and_motion_features(take_tracks):
    _, follow = take_tracks
    f = M.motion_features(follow, np.arange(1, 40))
    assert f.shape == (39, M.FRAME_FEATURES)
    w = M.windows(f)
    assert w.shape == (39 - M.WINDOW + 1, M.WINDOW * M.FRAME_FEATURES)
    np.testing.assert_array_equal(w[1, :M.FRAME_FEATURES], f[1])
    assert M.windows(f[:5]).shape == (0, M.WINDOW * M.FRAME_FEATURES)


def test_motion_features_of_a_still_dancer():
    """A dancer that stands still: zero velocity and zero root update in every frame."""
    frames = 5
    track = Track(np.tile(np.arange(51.0).reshape(1, 17, 3) / 50, (frames, 1, 1)),
                  np.tile(np.eye(3), (frames, 17, 1, 1)), np.zeros((frames, 2)), np.zeros(frames))
    f = M.motion_features(track, np.arange(1, frames))
    pose = f[:, :204].reshape(-1, 17, 12)
    np.testing.assert_allclose(pose[..., 3:6], 0)
    np.testing.assert_allclose(f[:, 204:], 0)


# ---------------------------------------------------------------- evaluation encoder

SMALL = M.EncoderConfig(hidden=16, latent=4, epochs=3, batch_size=16)


def small_windows(seed=0):
    return np.random.default_rng(seed).normal(size=(64, 30)).astype(np.float32)


def test_encoder_training_is_deterministic():
    a, b = M.train_encoder(small_windows(), SMALL), M.train_encoder(small_windows(), SMALL)
    for part in ("encoder", "decoder"):
        for k in a[part]:
            assert torch.equal(a[part][k], b[part][k]), f"{part}.{k} differs between two trainings"
    assert a["reconstruction"] == b["reconstruction"]


def test_encoder_training_leaves_torch_settings_alone():
    threads, det = torch.get_num_threads(), torch.are_deterministic_algorithms_enabled()
    state = torch.random.get_rng_state()
    M.train_encoder(small_windows(), SMALL)
    assert torch.get_num_threads() == threads
    assert torch.are_deterministic_algorithms_enabled() == det
    assert torch.equal(torch.random.get_rng_state(), state)


def test_encoder_cache(tmp_path):
    w = small_windows()
    enc1, trained1 = M.load_or_train_encoder(tmp_path, w, SMALL)
    enc2, trained2 = M.load_or_train_encoder(tmp_path, w, SMALL)
    assert trained1 and not trained2
    z1, z2 = enc1(w), enc2(w)
    assert z1.shape == (64, SMALL.latent)
    np.testing.assert_array_equal(z1, z2)
    # Other training windows: the cache does not apply, the encoder is trained again.
    _, trained3 = M.load_or_train_encoder(tmp_path, small_windows(1), SMALL)
    assert trained3
