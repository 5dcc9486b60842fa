"""training/evaluation/turn_cues.py (the detector that bounds how well a follower reading the leader
can time her turns) and the led turn a follower's intention may forecast (prepared.load_split)."""
from __future__ import annotations

import numpy as np
import torch

from training.data.prepared import LED_TURN_SCALE, load_split, load_stats, with_led_turn
from training.evaluation import turn_cues as C
from training.mirror import features as feat


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


def test_the_led_turn_is_the_leaders_figure_beside_the_follower_intention(prepared3):
    plain = load_split(str(prepared3), "train", "follower")
    led = load_split(str(prepared3), "train", "follower", led_turn=True)
    leader = load_split(str(prepared3), "train", "leader")
    assert led["intention"].shape[1] == feat.INTENTION_SIZE + feat.KEYS
    np.testing.assert_array_equal(led["intention"][:, :feat.INTENTION_SIZE], plain["intention"])
    fig = feat.block_slices(feat.LEADER_INPUT_LAYOUT)["figure"]
    np.testing.assert_array_equal(led["intention"][:, feat.INTENTION_SIZE:], leader["input"][:, fig][:, 1:])
    # Somewhere in the takes the follower turns: the label is not all zeros.
    assert np.abs(led["intention"][:, -1]).max() > 0.5
    stats = with_led_turn(load_stats(str(prepared3), "follower"), feat.KEYS)
    assert stats["intention_mean"].shape == (feat.INTENTION_SIZE + feat.KEYS,)
    assert torch.all(stats["intention_std"][-feat.KEYS:] == LED_TURN_SCALE)
    assert with_led_turn(stats, 0) is stats


def test_a_follower_whose_intention_forecasts_the_led_turn_trains_and_keeps_the_page_contract(prepared3, tmp_path):
    """Smoke-sized `follower_led_turn` with its own rollouts: the predictor forecasts key joints and
    the led turn (96 numbers), the step model still answers the page's 90."""
    from dataclasses import replace

    from training.learning import train as T
    from training.learning.runs import load_run
    shipped = T.MODELS["follower"]   # follower_led_turn: the shipped recipe, its intention forecasting the led turn
    led_turn = replace(shipped, model=replace(shipped.model, turn_keys=feat.KEYS), tempo_copies=False)
    cfg = replace(T.smoke(led_turn), own_rollouts_from=1, own_rollouts_stride=40)
    T.train_model("led", cfg, str(prepared3), str(tmp_path), quiet=True)
    run = load_run(tmp_path / "led", str(prepared3))
    assert run.predictor.net[-1].out_features == feat.INTENTION_SIZE + feat.KEYS
    x = torch.from_numpy(load_split(str(prepared3), "validation", "follower")["input"][:3])
    out, intention, code = run.model(x, torch.tensor([0.5]), torch.full((3, cfg.model.latent), 0.5))
    assert out.shape == (3, feat.OUTPUT_SIZE) and intention.shape == (3, feat.INTENTION_SIZE)


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
