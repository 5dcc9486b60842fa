"""training/evaluation/turn_cues.py (the detector that bounds how well a follower reading the leader's
body alone can time her turns) and turn_direction (which way)."""
from __future__ import annotations

import numpy as np

from training.evaluation import turn_cues as C


def test_labels_mark_the_frames_whose_turn_completes_lead_frames_later():
    s = {"frames": np.arange(30, 130), "turns": [(80, 1), (120, -1)]}
    y = C.labels(s, lead=15)
    # t + 15 within 3 frames of 80 (left) and of 120 (right): t in 62..68 and 102..108.
    assert set(np.flatnonzero(y == 1) + 30) == set(range(62, 69))
    assert set(np.flatnonzero(y == 2) + 30) == set(range(102, 109))
    assert (y == 0).sum() == 100 - 14


def test_detections_are_each_directions_peaks_above_the_threshold_moved_by_the_lead():
    frames = np.arange(200)
    p = np.zeros((200, 3))
    p[:, 0] = 1
    p[50, 1], p[52, 1] = 0.9, 0.7     # one left peak (52 is inside 50's +-0.75 s)
    p[150, 2] = 0.8                   # one right peak
    p[100, 1] = 0.2                   # below the threshold
    assert C.detections(p, frames, lead=10, threshold=0.5) == [(60, 1), (160, -1)]
    assert C.detections(p, frames, lead=10, threshold=0.85) == [(60, 1)]


def test_the_threshold_finds_as_many_turns_as_wanted():
    rng = np.random.default_rng(0)
    p = rng.dirichlet([8, 1, 1], size=3000)
    frames = np.arange(3000)
    th = C.threshold_for([p], [frames], 0, 40)
    assert abs(len(C.detections(p, frames, 0, th)) - 40) <= 1


def test_chance_of_detections_unrelated_to_the_recorded_turns_is_low_and_of_the_same_ones_is_not():
    rng = np.random.default_rng(1)
    recorded = [(int(f), 1) for f in np.arange(100, 3000, 90)]
    m = C.chance(recorded, recorded, 3100, rng)
    # Shifted at random, turns every 3 s match another within 0.75 s about half the time.
    assert 0.25 * len(recorded) < m < 0.75 * len(recorded)
    assert C.score(recorded, recorded) == (len(recorded), len(recorded), len(recorded))


def test_turn_direction_reads_the_leader_before_each_turn():
    """turn_direction.turn_samples: each recorded turn gives the row `lead` frames before it and its
    way; a turn too early to be read is left out."""
    import numpy as np
    from training.evaluation.turn_direction import HIS_HANDS, HIS_PATH, HIS_REST, turn_samples
    from training.mirror import features as feat
    frames = np.arange(30, 130)
    x = np.zeros((len(frames), feat.INPUT_SIZE))
    x[:, 0] = frames                                    # the first column says which frame a row is
    s = {"frames": frames, "input": x, "turns": [(40, 1), (100, -1), (120, 1)]}
    rows, ways = turn_samples(s, "leader", 15)
    assert list(rows[:, 0]) == [85, 105] and list(ways) == [-1, 1]
    # The parts of "leader" do not overlap and lie in his blocks of her input.
    parts = np.concatenate([HIS_HANDS, HIS_PATH, HIS_REST])
    assert len(np.unique(parts)) == len(parts)
    b = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)
    assert parts.min() >= b["partner_trajectory_past"].start and parts.max() < b["partner_pose"].stop
