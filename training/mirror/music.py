"""What the dancers hear: the count of the music as a feature block (web/mirror/music.ts mirrors it).

Salsa is danced on a count, and the music makes the count known in advance, as the steered path
is. Both networks read the count at the trajectory keys of the past second, now, and the next
second: per key the beat's phase and the two-beat group's phase as points on a circle, then the
tempo. The recording carries the beat and the two-beat group (training/data/count.py finds them in
the footwork), not the measure, so nothing here says which beat is the 1.

`beat` is the count in beats since the music started (float): whole numbers fall on the beats and
even ones start a two-beat group. In training it is the take's found count; in the page and the
evaluation it is the music's clock.
"""
from __future__ import annotations

import numpy as np

from .skeleton import FPS

MUSIC_OFFSETS = np.arange(-6, 7) * 5          # frames: t-30, t-25, ..., t, ..., t+30 (13 keys)
MUSIC_SIZE = len(MUSIC_OFFSETS) * 4 + 1       # 53: per key sin/cos of beat and two-beat phase, then tempo
# How the tempo (beats per second) is read by the networks: centred on 180 beats a minute with
# 18 beats a minute to a unit, so the 150-200 the couple dances to reads -1.7 to +1.1. Fixed, not
# the training data's spread: tempo copies and the recorded takes normalize alike.
TEMPO_MEAN = 3.0     # beats per second
TEMPO_STD = 0.3
# The page's tempo when the address names none: the middle of the recorded takes' (163-187,
# training/data/count.py), where the networks have seen the most.
DEFAULT_TEMPO = 170.0   # beats a minute
TEMPO_RANGE = (150.0, 200.0)   # what the page's tempo control offers (the networks trained 139-218)


def music_block(beat, beats_per_second) -> np.ndarray:
    """The count now [...] and the tempo [...] (beats per second) -> [..., 53]: per key of
    MUSIC_OFFSETS, sin and cos of 2 pi beat and of pi beat (the two-beat group), then the tempo."""
    beat = np.asarray(beat, float)
    bps = np.broadcast_to(np.asarray(beats_per_second, float), beat.shape)
    keys = beat[..., None] + bps[..., None] * MUSIC_OFFSETS / FPS
    per_key = np.stack([np.sin(2 * np.pi * keys), np.cos(2 * np.pi * keys),
                        np.sin(np.pi * keys), np.cos(np.pi * keys)], -1)
    flat = per_key.reshape(per_key.shape[:-2] + (per_key.shape[-2] * 4,))
    return np.concatenate([flat, bps[..., None]], -1)


def music_at(beat: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """The music block [N, 53] at `frames` of a take whose count per frame is `beat` [F] (the
    tempo read from the count over the frames around each one)."""
    frames = np.asarray(frames)
    lo, hi = np.maximum(frames - 1, 0), np.minimum(frames + 1, len(beat) - 1)
    bps = (beat[hi] - beat[lo]) * FPS / np.maximum(hi - lo, 1)
    return music_block(beat[frames], bps)


def beats_per_step(bpm: float) -> float:
    """How far the count moves in one step of the duet (1/30 s) at a tempo."""
    return bpm / 60.0 / FPS
