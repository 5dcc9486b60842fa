"""Steps on the count: of a few samples of the next step, the one whose feet follow the beat
(web/mirror/on_count.ts mirrors it name for name).

Both networks hear the music (music.py), yet the last second of motion says more about when the
next step falls than the count does, so left to their own samples each keeps a tempo of its own
(docs/music.md). A dancer on the count moves the feet between beats and lands them on the beat:
the recorded footwork (the summed speed of both ankles, training/data/count.py) swings once a
beat, lowest where a foot lands. So each step the dancer's guard draws SAMPLES of the network's
next step from the same input, as it does when it guards (guard.py), and takes the standing one
whose footwork is nearest

    mean * (1 - STRENGTH * cos(2 pi * the count at the next step))

where `mean` is the dancer's own footwork over about the last MEAN_SECONDS. Every candidate is the
network's own reaction from the same state: nothing jumps, nobody's input changes, and the follower
still reads the leader and hears the music with no command. The choice only nudges, step by step,
when each dancer's feet speed up and slow down.

While a dancer turns faster than TURNING, the network's own sample is taken: a spin moves the
ankles fast whatever the count, so the pull broke her turns off (0.84x to 0.69x the recorded
follower's turns a minute, 10 seeds of `lead`); left to the network, they stay (0.75x).

Measured (python -m training.evaluation.rhythm, docs/music.md): with 8 samples at strength 1 the
steps land on the beat about as the recorded ones do; fewer samples or a weaker pull land fewer.
"""
from __future__ import annotations

import numpy as np

from . import features as feat
from .music import MUSIC_OFFSETS, MUSIC_SIZE
from .skeleton import FEET, FPS

SAMPLES = 8           # candidates each step (one batched run of the network)
STRENGTH = 1.0        # 0: the footwork's own mean; 1: from still on the beat to twice the mean between
MEAN_SECONDS = 1.0    # how long the dancer's own footwork is averaged over (about three steps)
TURNING = 3.0         # rad/s: faster than this the dancer is in a turn, left to the network (a spin: 6-9)

# Where each role's input holds its own ankles' velocity (pose block: position, velocity, forward,
# up per joint), and where the output holds the next step's; the count now is the music block's key
# at offset 0 (sin, cos of 2 pi count), the tempo (beats a second) the block's last number.
_POSE_JOINT = feat.POSE_SIZE // feat.N_JOINTS
_NOW_KEY = int(np.nonzero(MUSIC_OFFSETS == 0)[0][0]) * 4
ANKLE_VELOCITY_IN = {
    role: [feat.block_slices(layout)["self_pose"].start + _POSE_JOINT * j + 3 for j in FEET]
    for role, layout in (("leader", feat.LEADER_INPUT_LAYOUT), ("follower", feat.FOLLOWER_INPUT_LAYOUT))}
# The facing of the dancer's newest past trajectory key (KEY_STEP frames ago) in its root space now.
LAST_FACING = {
    role: feat.block_slices(layout)["self_trajectory_past"].start + (feat.KEYS - 1) * 4 + 2
    for role, layout in (("leader", feat.LEADER_INPUT_LAYOUT), ("follower", feat.FOLLOWER_INPUT_LAYOUT))}
ANKLE_VELOCITY_OUT = [feat.block_slices(feat.OUTPUT_LAYOUT)["pose"].start + _POSE_JOINT * j + 3 for j in FEET]


def footwork_now(x: np.ndarray, role: str) -> float:
    """The dancer's footwork now (m/s: the summed speed of both ankles) from its input [I]."""
    return float(sum(np.linalg.norm(x[c:c + 3]) for c in ANKLE_VELOCITY_IN[role]))


def footwork_next(outputs: np.ndarray) -> np.ndarray:
    """The footwork each output [B, 323] would draw at the next step [B]."""
    outputs = np.atleast_2d(outputs)
    return sum(np.linalg.norm(outputs[:, c:c + 3], axis=-1) for c in ANKLE_VELOCITY_OUT)


def turn_rate(x: np.ndarray, role: str) -> float:
    """How fast the dancer turns now (rad/s, unsigned) from its input [I]: its facing KEY_STEP frames
    ago, seen from its root now."""
    c = LAST_FACING[role]
    return float(abs(np.arctan2(x[c], x[c + 1])) * FPS / feat.KEY_STEP)


def count_next(x: np.ndarray) -> float:
    """The count at the next step (beats, its fraction only) from the music block ending input x."""
    music = x[len(x) - MUSIC_SIZE:]
    now = np.arctan2(music[_NOW_KEY], music[_NOW_KEY + 1]) / (2 * np.pi)
    return float(now + music[-1] / FPS)


class OnCount:
    """One dancer's footwork mean, kept across steps, and the footwork its next step aims at."""

    def __init__(self, role: str, samples: int = SAMPLES, strength: float = STRENGTH):
        if role not in ANKLE_VELOCITY_IN:
            raise ValueError(f"role must be 'leader' or 'follower', got {role!r}")
        if samples < 2:
            raise ValueError("choosing on the count needs at least 2 samples")
        self.role, self.samples, self.strength = role, samples, strength
        self.mean: float | None = None

    def target(self, x: np.ndarray) -> float | None:
        """The footwork the next step aims at, for input x [I] (this step's: it moves the mean on);
        None while the dancer turns faster than TURNING (the network's own sample is taken)."""
        x = np.atleast_2d(x)[0]
        now = footwork_now(x, self.role)
        self.mean = now if self.mean is None else self.mean + (now - self.mean) / (MEAN_SECONDS * FPS)
        if turn_rate(x, self.role) > TURNING:
            return None
        return self.mean * (1.0 - self.strength * np.cos(2 * np.pi * count_next(x)))


def nearest_count(outputs: np.ndarray, target: float, standing: np.ndarray, margin: float) -> int:
    """The index of the output [B, 323] whose footwork is nearest the target among those standing
    [B] (their upright margins, guard.py) at least `margin` inside the range; -1 when none does."""
    ok = np.asarray(standing) >= margin
    if not ok.any():
        return -1
    return int(np.argmin(np.where(ok, np.abs(footwork_next(outputs) - target), np.inf)))
