"""Which of her recorded turn starts his body leads: a linear reader of the leader, for training.

A follower trained on every recorded turn start alike learns to start turns wherever the recording
has one, and the recording has many that nothing in the leader announces (the recorded follower
turns in 24 % of the 2.5 s windows in which his hand stays down: recorded_leads). Weighing only the
starts he leads (TrainConfig.unled_turn_weight) asks her to read him. Which starts those are, the
hand rule (train.led_onsets) reads from one number, his hand's height; this reader reads his whole
body as she sees it: the leader's blocks of her input (his past and planned path, his past key
joints and his pose, in her root space), the columns the detector of training.evaluation.turn_cues
calls "leader". It is a logistic regression of three classes (no start, a start to her left, to
her right) fitted on the recorded training samples; a start counts as led where the probability
of its own direction is among the highest `share` of the recorded starts'. In the page, his
network leads the asked way with that body in most requests (turn_cues: 85 %), while his hand
reaches the hand rule's height in few.

    reader = LeadReader.fit(x_raw, y_raw)      # the recorded training samples
    led = reader.led(x_raw, y_raw)             # bool [N]: a turn start his body leads
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from sklearn.linear_model import LogisticRegression

from ..mirror import features as feat
from ..mirror.on_count import planned_turn

LEADER_COLUMNS = slice(0, feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)["partner_pose"].stop)
SHARE = 0.5       # of the recorded turn starts, the ones most clearly led count as led
# Inverse L2 strength, strong: fitted on the training takes at turn_cues' 0.01 the reader finds
# half of their starts led but only 5 % of the validation take's and 20 % of the test takes' (it
# learns the training starts by heart). At 5e-5 the held-out takes have 42 % / 51 % of their starts
# led, it tells the direction of 92 % / 87 % of them, and it ranks starts above other samples with
# an area under the ROC curve of 0.76 / 0.81 (0.71 / 0.79 at 0.01).
C = 5e-5
FIT_SAMPLES = 40_000   # the reader is fitted on at most this many samples (an even subsample)


def start_direction(x_raw: np.ndarray, y_raw: np.ndarray) -> np.ndarray:
    """[N] int: 0 where no turn of hers starts (train.own_turn_onsets), 1 a start to her left
    (her heading grows), 2 to her right."""
    from .train import own_turn_onsets   # train reads this module: imported when called
    future = planned_turn(y_raw)
    onset = own_turn_onsets(x_raw, y_raw, "follower")
    return np.where(onset, np.where(future > 0, 1, 2), 0)


@dataclass
class LeadReader:
    model: LogisticRegression
    mean: np.ndarray
    std: np.ndarray
    threshold: float

    @classmethod
    def fit(cls, x_raw: np.ndarray, y_raw: np.ndarray, share: float = SHARE, seed: int = 0) -> "LeadReader":
        """Fit on a follower's samples (raw input [N, 713], raw output [N, 323]); the threshold
        makes `share` of their turn starts led."""
        if not 0.0 < share <= 1.0:
            raise ValueError(f"share {share}: a share of the turn starts, in (0, 1]")
        labels = start_direction(x_raw, y_raw)
        if not (labels == 1).any() or not (labels == 2).any():
            raise ValueError("the samples hold no turn start of each direction: nothing to read a lead from")
        idx = np.arange(len(x_raw))
        if len(idx) > FIT_SAMPLES:
            idx = np.sort(np.random.default_rng(seed).choice(idx, FIT_SAMPLES, replace=False))
        x = x_raw[idx, LEADER_COLUMNS].astype(np.float64)
        mean, std = x.mean(0), x.std(0) + 1e-6
        model = LogisticRegression(C=C, max_iter=300).fit((x - mean) / std, labels[idx])
        reader = cls(model, mean, std, 0.0)
        p = reader.own_direction(x_raw, labels)
        reader.threshold = float(np.quantile(p[labels > 0], 1.0 - share))
        return reader

    def own_direction(self, x_raw: np.ndarray, labels: np.ndarray) -> np.ndarray:
        """[N] the probability the reader gives the start of each sample's own direction (0 where
        none starts)."""
        p = self.model.predict_proba((x_raw[:, LEADER_COLUMNS] - self.mean) / self.std)
        col = {c: i for i, c in enumerate(self.model.classes_)}
        out = np.zeros(len(x_raw))
        for d in (1, 2):
            out[labels == d] = p[labels == d, col[d]]
        return out

    def led(self, x_raw: np.ndarray, y_raw: np.ndarray) -> np.ndarray:
        """bool [N]: her turn starts here and his body, read by this reader, leads it her way."""
        labels = start_direction(x_raw, y_raw)
        return (labels > 0) & (self.own_direction(x_raw, labels) >= self.threshold)
