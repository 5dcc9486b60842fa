"""The count of a recorded take, found in the couple's footwork (the recordings carry no audio).

A dancer's **footwork** is the summed speed of both ankles at 30 fps. Salsa steps on the beat, so
footwork swings once a beat (a foot lands, the next one lifts), and the steps of a two-beat group
differ (which foot, how far), so it also swings once every two beats. The count of a take is a
steady tempo and a phase: `beat(t) = beat0 + t * bpm / 60` beats after the take's first frame, t in
seconds. Whole beats fall where the footwork's beat swing is lowest (a foot lands), and even beats
where the two-beat swing is highest: the same rule in every take, so a network reads one count.

How it is found: the tempo that explains most of the couple's footwork at the beat and at half of
it (the sum of both Fourier magnitudes, searched from 140 to 220 beats a minute in 0.05 steps),
then the phases of both swings at that tempo. `python -m training.data.count_report` prints, per
take, what this module finds (count_report.py).

The data carries the beat and the two-beat group, not the measure: his footwork's swing every four
and every eight beats is no stronger than its neighbouring frequencies (`measure_strength`), so the
"1" of the 8-count is not in the recording (docs/music.md). The count the networks hear is the beat
and the two-beat group; the page's music puts its 1 on an even beat.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mirror.skeleton import FEET, FPS

BPM_RANGE = (140.0, 220.0)   # salsa is danced from about 150 to 210 beats a minute
BPM_STEP = 0.05
WINDOW_SECONDS = 10.0        # the windows that show the count holds through a take


@dataclass(frozen=True)
class Count:
    bpm: float     # beats a minute
    beat0: float   # the count at the take's first frame (beats)

    def beats(self, seconds: np.ndarray) -> np.ndarray:
        """The count (beats since the start of the music) at these times (s from the first frame)."""
        return self.beat0 + np.asarray(seconds, float) * self.bpm / 60.0


def footwork(positions: np.ndarray, fps: float = FPS) -> np.ndarray:
    """[F, 17, 3] world joints -> [F] summed ankle speed, m/s (the first frame repeats the second)."""
    feet = positions[:, FEET]
    speed = np.linalg.norm(np.diff(feet, axis=0), axis=-1).sum(-1) * fps
    return np.concatenate([speed[:1], speed])


def _fourier(x: np.ndarray, hz: np.ndarray, fps: float) -> np.ndarray:
    """Complex amplitude of x (mean removed) at each frequency: x ~ |c| cos(2 pi f t + arg c)."""
    t = np.arange(len(x)) / fps
    x = x - x.mean()
    return 2.0 * (np.exp(-2j * np.pi * np.asarray(hz)[:, None] * t[None]) @ x) / len(x)


def normalized(x: np.ndarray) -> np.ndarray:
    return x / max(float(x.std()), 1e-9)


def tempo_of(signal: np.ndarray, fps: float = FPS, bpm_range=BPM_RANGE, step: float = BPM_STEP) -> float:
    """The tempo (bpm) whose beat and two-beat swings together explain most of a footwork signal."""
    bpm = np.arange(bpm_range[0], bpm_range[1] + step / 2, step)
    score = np.abs(_fourier(signal, bpm / 60, fps)) + np.abs(_fourier(signal, bpm / 120, fps))
    return float(bpm[np.argmax(score)])


def phase_at(signal: np.ndarray, bpm: float, fps: float = FPS) -> float:
    """beat0 (in [0, 2)) of the count at a given tempo: whole beats where the beat swing is lowest,
    even ones where the two-beat swing is highest."""
    f = bpm / 60.0
    beat_swing, pair_swing = _fourier(signal, np.array([f, f / 2]), fps)
    # |c| cos(2 pi f t + arg c) is lowest where 2 pi f t + arg c = pi: there the count is whole.
    beat0 = (np.angle(beat_swing) - np.pi) / (2 * np.pi)          # count at t = 0, up to whole beats
    # The two-beat swing peaks where pi f t + arg c2 = 0 (mod 2 pi), i.e. at count beat0 - arg c2 / pi.
    # Of the two parities, take the one that puts that peak nearest an even count.
    peak = beat0 - np.angle(pair_swing) / np.pi
    if int(np.round(peak)) % 2:      # the whole beat nearest that peak made even by moving the count a beat
        beat0 += 1.0
    return float(np.mod(beat0, 2.0))


def find_count(leader_positions: np.ndarray, follower_positions: np.ndarray | None = None,
               fps: float = FPS) -> Count:
    """The count of a take from both dancers' footwork (each scaled to unit spread so neither
    outweighs the other), or from one dancer's alone."""
    signal = normalized(footwork(leader_positions, fps))
    if follower_positions is not None:
        signal = signal + normalized(footwork(follower_positions, fps))
    bpm = tempo_of(signal, fps)
    return Count(bpm, phase_at(signal, bpm, fps))


def phase_gap(a: Count, b: Count, seconds: float = 0.0, group: float = 2.0) -> float:
    """How far apart two counts are at a moment, in beats, wrapped to [-group/2, group/2): with
    group 2 the two-beat groups must agree too, with group 1 only the beats."""
    d = a.beats(np.array(seconds)) - b.beats(np.array(seconds))
    return float(np.mod(d + group / 2, group) - group / 2)


def window_gaps(leader_positions: np.ndarray, follower_positions: np.ndarray, count: Count,
                fps: float = FPS, seconds: float = WINDOW_SECONDS, hop: float = 2.5) -> list[dict]:
    """Per 10 s window (every 2.5 s): the tempo found in it as a ratio to the take's less 1, and at
    the take's tempo, how far its beat and its two-beat group are from the take's (beats)."""
    n, w = len(leader_positions), int(round(seconds * fps))
    out = []
    for start in range(0, max(1, n - w + 1), int(round(hop * fps))):
        sl = slice(start, start + w)
        lp, fp = leader_positions[sl], follower_positions[sl]
        signal = normalized(footwork(lp, fps)) + normalized(footwork(fp, fps))
        here = Count(count.bpm, phase_at(signal, count.bpm, fps) - (start / fps) * count.bpm / 60.0)
        out.append({"tempo": tempo_of(signal, fps) / count.bpm - 1.0,
                    "beat": phase_gap(here, count, group=1.0), "group": phase_gap(here, count)})
    return out


def measure_strength(positions: np.ndarray, count: Count, fps: float = FPS) -> dict[int, float]:
    """How much of a dancer's footwork swings once every 1, 2, 4 and 8 beats, as a ratio to the
    median of its neighbouring frequencies (0.6-0.85x and 1.2-1.5x): about 1 is noise. The "1" of
    the measure would show as a swing every 8 beats (he breaks forward on 1, back on 5), the half
    measure every 4."""
    x = normalized(footwork(positions, fps))
    f = count.bpm / 60.0
    around = np.concatenate([np.linspace(0.6, 0.85, 12), np.linspace(1.2, 1.5, 12)])
    out = {}
    for beats in (1, 2, 4, 8):
        amp = np.abs(_fourier(x, np.array([f / beats]), fps))[0]
        floor = np.median(np.abs(_fourier(x, f / beats * around, fps)))
        out[beats] = float(amp / max(floor, 1e-12))
    return out


def plot_footwork(ax, leader_positions: np.ndarray, follower_positions: np.ndarray, start: float,
                  seconds: float, fps: float = FPS) -> tuple[np.ndarray, slice]:
    """Both dancers' footwork from `start` for `seconds` on a matplotlib axis (the count report's
    and the rhythm plot's picture); returns the times drawn (s) and the frames they are."""
    lw, fw = footwork(leader_positions, fps), footwork(follower_positions, fps)
    # A take shorter than start + seconds is drawn to its end.
    sl = slice(int(start * fps), min(int((start + seconds) * fps), len(lw), len(fw)))
    t = np.arange(sl.start, sl.stop) / fps
    lw, fw = lw[sl], fw[sl]
    ax.plot(t, lw, color="#2a6fdb", lw=1.2, label="leader")
    ax.plot(t, fw, color="#d62f3a", lw=1.2, label="follower")
    # a marker glitch (an ankle jumping for a frame) would flatten the rest: clip the view
    ax.set_ylim(0, 1.1 * np.percentile(np.concatenate([lw, fw]), 98))
    return t, sl
