"""The count of a recorded take, found in the couple's footwork (the recordings carry no audio).

A dancer's **footwork** is the summed speed of both ankles at 30 fps. Salsa steps on the beat, so
footwork swings once a beat (a foot lands, the next one lifts), and the steps of a two-beat group
differ (which foot, how far), so it also swings once every two beats. The count of a take is a
steady tempo and a phase: `beat(t) = beat0 + t * bpm / 60` beats after the take's first frame, t in
seconds. Whole beats fall where the footwork's beat swing is lowest (a foot lands), and even beats
where the two-beat swing is highest: the same rule in every take, so a network reads one count.

How it is found: the tempo that explains most of the couple's footwork at the beat and at half of
it (the sum of both Fourier magnitudes, searched from 140 to 220 beats a minute in 0.05 steps),
then the phases of both swings at that tempo. `python -m training.data.count` prints, per take,
the tempo and phase the couple, the leader alone and the follower alone give, and how far the count
found in 10 s windows is from the take's; `--plot FILE` draws footwork with the found beats.

The data carries the beat and the two-beat group, not the measure: his footwork's swing every four
and every eight beats is no stronger than its neighbouring frequencies (`measure_strength`), so the
"1" of the 8-count is not in the recording (docs/music.md). The count the networks hear is the beat
and the two-beat group; the page's music puts its 1 on an even beat.
"""
from __future__ import annotations

import argparse
import sys
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


def _normalized(x: np.ndarray) -> np.ndarray:
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
    signal = _normalized(footwork(leader_positions, fps))
    if follower_positions is not None:
        signal = signal + _normalized(footwork(follower_positions, fps))
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
        signal = _normalized(footwork(lp, fps)) + _normalized(footwork(fp, fps))
        here = Count(count.bpm, phase_at(signal, count.bpm, fps) - (start / fps) * count.bpm / 60.0)
        out.append({"tempo": tempo_of(signal, fps) / count.bpm - 1.0,
                    "beat": phase_gap(here, count, group=1.0), "group": phase_gap(here, count)})
    return out


def measure_strength(positions: np.ndarray, count: Count, fps: float = FPS) -> dict[int, float]:
    """How much of a dancer's footwork swings once every 1, 2, 4 and 8 beats, as a ratio to the
    median of its neighbouring frequencies (0.6-0.85x and 1.2-1.5x): about 1 is noise. The "1" of
    the measure would show as a swing every 8 beats (he breaks forward on 1, back on 5), the half
    measure every 4."""
    x = _normalized(footwork(positions, fps))
    f = count.bpm / 60.0
    around = np.concatenate([np.linspace(0.6, 0.85, 12), np.linspace(1.2, 1.5, 12)])
    out = {}
    for beats in (1, 2, 4, 8):
        amp = np.abs(_fourier(x, np.array([f / beats]), fps))[0]
        floor = np.median(np.abs(_fourier(x, f / beats * around, fps)))
        out[beats] = float(amp / max(floor, 1e-12))
    return out


# ---------------------------------------------------------------- the report

def _takes(data: str):
    from .dataset import discover_takes, load_pair, pair_tracks
    for take in discover_takes(data):
        lead, follow = pair_tracks(*load_pair(take))
        yield take.name, lead.positions, follow.positions


def report(data: str) -> list[dict]:
    rows = []
    for name, lp, fp in _takes(data):
        couple = find_count(lp, fp)
        lone = [find_count(p) for p in (lp, fp)]
        # each dancer alone, at the couple's tempo: does the beat fall at the same moments?
        alone_phase = [Count(couple.bpm, phase_at(_normalized(footwork(p)), couple.bpm)) for p in (lp, fp)]
        windows = window_gaps(lp, fp, couple)
        beat_gaps = [phase_gap(c, couple, group=1.0) for c in alone_phase]
        rows.append({
            "take": name, "seconds": len(lp) / FPS, "bpm": couple.bpm, "beat0": couple.beat0,
            "bpm_leader": lone[0].bpm, "bpm_follower": lone[1].bpm,
            "beat_leader": beat_gaps[0], "beat_follower": beat_gaps[1],
            "group_leader": abs(phase_gap(alone_phase[0], couple)) < 0.5,
            "group_follower": abs(phase_gap(alone_phase[1], couple)) < 0.5,
            "window_tempo": float(np.median([abs(w["tempo"]) for w in windows])),
            "window_beat": max(abs(w["beat"]) for w in windows),
            "window_group": sum(abs(w["group"]) < 0.5 for w in windows) / len(windows),
            "leader_swing": measure_strength(lp, couple), "follower_swing": measure_strength(fp, couple),
        })
    return rows


def print_report(rows: list[dict]) -> None:
    print("take    s    bpm | alone: tempo (bpm) L F | beat off (beats) L F | same group L F | "
          "10 s windows: tempo off (median), beat off (worst), same group | leader swing every 1/2/4/8 beats (x noise)")
    yes = {True: "yes", False: " no"}
    for r in rows:
        s = r["leader_swing"]
        print(f"{r['take']:>4} {r['seconds']:5.1f} {r['bpm']:6.1f} | {r['bpm_leader']:6.1f} {r['bpm_follower']:6.1f} | "
              f"{r['beat_leader']:+.2f} {r['beat_follower']:+.2f} | {yes[r['group_leader']]} {yes[r['group_follower']]} | "
              f"{100 * r['window_tempo']:4.1f} % {r['window_beat']:.2f} {100 * r['window_group']:4.0f} % | "
              f"{s[1]:.1f} {s[2]:.1f} {s[4]:.1f} {s[8]:.1f}")
    agree = sum(abs(r["bpm_leader"] / r["bpm"] - 1) <= 0.02 and abs(r["bpm_follower"] / r["bpm"] - 1) <= 0.02 for r in rows)
    same = sum(max(abs(r["beat_leader"]), abs(r["beat_follower"])) <= 0.15 for r in rows)
    group = sum(r["group_leader"] and r["group_follower"] for r in rows)
    steady = sum(r["window_beat"] <= 0.15 for r in rows)
    windows_group = float(np.mean([r["window_group"] for r in rows]))
    med = {b: float(np.median([r["leader_swing"][b] for r in rows])) for b in (1, 2, 4, 8)}
    print(f"each dancer alone finds the couple's tempo within 2 %: {agree} of {len(rows)} takes; at the couple's "
          f"tempo, the beat within 0.15 beats: {same} of {len(rows)}, the same two-beat group: {group} of {len(rows)}")
    print(f"every 10 s window's beat within 0.15 beats of its take's: {steady} of {len(rows)} takes; "
          f"windows in the take's two-beat group: {100 * windows_group:.0f} %")
    print("the leader's footwork swing (median over takes, x its neighbouring frequencies): "
          + ", ".join(f"every {b} beats {v:.1f}" for b, v in med.items()))


def plot(data: str, out: str, takes: list[str], start: float = 6.0, seconds: float = 5.0) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [(n, lp, fp) for n, lp, fp in _takes(data) if n in takes]
    fig, axes = plt.subplots(len(rows), 1, figsize=(10, 1.9 * len(rows)), sharex=True, squeeze=False)
    for ax, (name, lp, fp) in zip(axes[:, 0], rows):
        c = find_count(lp, fp)
        sl = slice(int(start * FPS), int((start + seconds) * FPS))
        t = np.arange(sl.start, sl.stop) / FPS
        lw, fw = footwork(lp)[sl], footwork(fp)[sl]
        ax.plot(t, lw, color="#2a6fdb", lw=1.2, label="leader")
        ax.plot(t, fw, color="#d62f3a", lw=1.2, label="follower")
        # a marker glitch (an ankle jumping for a frame) would flatten the rest: clip the view
        ax.set_ylim(0, 1.1 * np.percentile(np.concatenate([lw, fw]), 98))
        b = c.beats(t)
        for k in range(int(np.ceil(b[0])), int(np.floor(b[-1])) + 1):
            x = (k - c.beat0) * 60.0 / c.bpm
            ax.axvline(x, color="k", lw=1.4 if k % 2 == 0 else 0.6, alpha=0.6 if k % 2 == 0 else 0.35)
        ax.set_ylabel("m/s")
        ax.set_title(f"take {name}: {c.bpm:.1f} beats a minute (lines: found beats, bold: even)", fontsize=9, loc="left")
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("seconds from the take's start (footwork: summed ankle speed; a foot lands at its lows)")
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    print(f"wrote {out}")


def main(argv=None) -> int:
    from .dataset import DataError
    from .folders import add_folder
    ap = argparse.ArgumentParser(prog="python -m training.data.count", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "read")
    ap.add_argument("--plot", metavar="FILE", help="draw footwork with the found beats (PNG)")
    ap.add_argument("--takes", default="01,07,09,13", help="takes to plot (comma-separated)")
    args = ap.parse_args(argv)
    try:
        print_report(report(args.data))
        if args.plot:
            plot(args.data, args.plot, [t for t in args.takes.split(",") if t])
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
