"""training.learning.lead_reader: which of her turn starts his body leads, and the turn-start
weights that read it (train.onset_weights with led_by "body")."""
from __future__ import annotations

import numpy as np
import pytest

from training.learning import lead_reader as L
from training.learning import train as T
from training.mirror import features as feat
from training.mirror.features import KEYS

SI, SO = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT), feat.block_slices(feat.OUTPUT_LAYOUT)
CUE = SI["partner_pose"].start      # one column of his pose, in her input's leader blocks


def samples(directions: np.ndarray, cue: np.ndarray, rng: np.random.Generator):
    """Follower samples [N]: no turn behind her; ahead a turn of 300 degrees her `directions` way
    (+1 left, -1 right, 0 none); his pose's column CUE holds `cue`, the rest of his blocks noise."""
    n = len(directions)
    x, y = np.zeros((n, feat.INPUT_SIZE)), np.zeros((n, feat.OUTPUT_SIZE))
    x[:, L.LEADER_COLUMNS] = rng.normal(size=(n, L.LEADER_COLUMNS.stop))
    x[:, CUE] = cue
    x[:, SI["self_trajectory_past"]] = np.tile([0, 0, 0, 1], KEYS)
    fut = np.radians(300) * (np.arange(1, KEYS + 1) / KEYS)
    for i, d in enumerate(directions):
        h = d * fut
        y[i, SO["trajectory_future"]] = np.stack([0 * h, 0 * h, np.sin(h), np.cos(h)], -1).ravel()
    return x, y


def test_start_direction_reads_her_turn_start_and_its_way():
    x, y = samples(np.array([1, -1, 0]), np.zeros(3), np.random.default_rng(0))
    assert L.start_direction(x, y).tolist() == [1, 2, 0]
    turned = np.radians(200) * (np.arange(-KEYS, 0) / KEYS)     # a turn already under way behind her
    x[0, SI["self_trajectory_past"]] = np.stack([0 * turned, 0 * turned, np.sin(turned), np.cos(turned)], -1).ravel()
    assert L.start_direction(x, y).tolist() == [0, 2, 0]


def test_the_reader_finds_the_starts_his_body_announces_her_way():
    """Half of the starts come with his cue pointing their way (+3 left, -3 right), half with
    none; samples without a start carry no cue. The reader's led starts are the announced ones,
    about `share` of the starts, and the direction counts: a cue pointing the other way is not a lead."""
    rng = np.random.default_rng(1)
    n = 6000
    d = rng.choice([0, 0, 0, 1, -1], n)
    announced = (d != 0) & (rng.random(n) < 0.5)
    x, y = samples(d, np.where(announced, 3.0 * d, 0.0), rng)
    reader = L.LeadReader.fit(x, y, share=0.5)
    led = reader.led(x, y)
    starts = d != 0
    assert not led[~starts].any()
    assert abs(led[starts].mean() - 0.5) < 0.02
    assert (led & announced).sum() >= 0.9 * announced.sum()
    wrong_way = x.copy()
    wrong_way[:, CUE] *= -1
    assert reader.led(wrong_way, y)[announced].mean() < 0.1


def test_a_bad_share_or_no_starts_is_a_clear_error():
    rng = np.random.default_rng(2)
    x, y = samples(np.array([1, -1] * 20), np.zeros(40), rng)
    with pytest.raises(ValueError, match="share"):
        L.LeadReader.fit(x, y, share=0.0)
    x, y = samples(np.zeros(40, int), np.zeros(40), rng)
    with pytest.raises(ValueError, match="no turn start"):
        L.LeadReader.fit(x, y)


def test_onset_weights_by_his_body_weigh_only_the_led_starts():
    rng = np.random.default_rng(3)
    d = rng.choice([0, 1, -1], 3000)
    announced = (d != 0) & (rng.random(3000) < 0.5)
    x, y = samples(d, np.where(announced, 3.0 * d, 0.0), rng)
    j = np.zeros((len(d), feat.INTENTION_SIZE))        # his hands never up: the hand rule leads none
    reader = L.LeadReader.fit(x, y)
    cfg = T.TrainConfig(turn_weight=8.0, unled_turn_weight=1.0, led_by="body")
    w = T.onset_weights(cfg, x, y, j, "follower", reader).numpy()
    assert set(np.unique(w)) == {1.0, 8.0}
    assert np.array_equal(w == 8.0, reader.led(x, y))
    hand = T.onset_weights(T.TrainConfig(turn_weight=8.0, unled_turn_weight=1.0), x, y, j, "follower").numpy()
    assert (hand == 1.0).all()
    with pytest.raises(T.TrainError, match="reader"):
        T.onset_weights(cfg, x, y, j, "follower")
    with pytest.raises(T.TrainError, match="led_by"):
        T.onset_weights(T.TrainConfig(turn_weight=8.0, unled_turn_weight=1.0, led_by="feet"), x, y, j, "follower", reader)
