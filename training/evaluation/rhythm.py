"""Rhythm: do the dancers step on the count, as the recorded couple does?

    python -m training.evaluation.rhythm                       # 100 seeds x 60 s, steered and nobody steering,
                                                               # at the manifest's tempo and at 0.9x and 1.1x
    python -m training.evaluation.rhythm --seeds 4 --seconds 20 --tempo 170   # a quick look
    python -m training.evaluation.rhythm --tempos 150,170,200 --steer nobody

Measures, per dancer (footwork: the summed speed of both ankles at 30 fps, training/data/count.py):
- **pulse**: the height of the footwork's autocorrelation's strongest peak at lags 0.5-1.6 s, and
  **period** the lag of that peak (the recorded couples': two beats, 0.63-0.73 s);
- **period off**: how far that period is from the music's two beats, or four (a share; within 4 %
  counts): the recorded followers' strongest peak is at four beats in 7 of 12 takes, a whole
  multiple of the two-beat swing, not another tempo;
- **together**: the share of the follower's motion beats (local minima of her mean joint speed,
  smoothed) within 0.1 s of one of the leader's (the "beat echo");
- **on the beat**: the mean cosine of the count's phase at her or his steps (the footwork's local
  minima, where a foot lands): 1 when every step lands on a beat, 0 when steps ignore the beat, -1
  when every step lands between beats. The recording's is read against its found count.

Every figure is printed beside the recorded couples' (the training and test takes, each at its
own found count) as a ratio, with the worst seed. The rollouts are the soak's (the page's loop,
its guards and varieties from the manifest), steered by the soak's stick or by nobody.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from ..data.count import footwork, plot_footwork
from ..data.folders import add_folder
from ..mirror.skeleton import FPS

PULSE_LAGS = (0.5, 1.6)      # s: two beats to half a measure at 150-200 beats a minute
PERIOD_TOLERANCE = 0.04      # the period within 4 % of the music's two beats
ECHO_SECONDS = 0.1           # a follower's motion beat within this of a leader's is "together"
SMOOTH_FRAMES = 2.0          # Gaussian sigma of the mean joint speed before its minima are found


def autocorrelation(x: np.ndarray, max_lag: int) -> np.ndarray:
    """Normalized autocorrelation of x (mean removed) at lags 0..max_lag."""
    x = np.asarray(x, float) - np.mean(x)
    denom = float(np.dot(x, x)) or 1.0
    return np.array([np.dot(x[:len(x) - k], x[k:]) / denom for k in range(max_lag + 1)])


def pulse(x: np.ndarray, fps: float = FPS) -> tuple[float, float]:
    """(height, lag in s) of the autocorrelation's strongest local peak at PULSE_LAGS; (0, nan)
    when there is none (a still dancer), and a height of 0 when even the strongest is below 0
    (no swing repeats there at all)."""
    lo, hi = int(round(PULSE_LAGS[0] * fps)), int(round(PULSE_LAGS[1] * fps))
    if len(x) < 2 * hi or np.std(x) < 1e-9:
        return 0.0, float("nan")
    r = autocorrelation(x, hi + 1)
    peaks = [k for k in range(max(lo, 1), hi + 1) if r[k] >= r[k - 1] and r[k] >= r[k + 1]]
    if not peaks:
        return 0.0, float("nan")
    k = max(peaks, key=lambda i: r[i])
    # parabolic interpolation of the peak's lag: the period to a fraction of a frame
    a, b, c = r[k - 1], r[k], r[k + 1]
    shift = 0.5 * (a - c) / (a - 2 * b + c) if (a - 2 * b + c) != 0 else 0.0
    return float(max(b, 0.0)), float((k + np.clip(shift, -0.5, 0.5)) / fps)


def _smooth(x: np.ndarray, sigma: float) -> np.ndarray:
    r = int(np.ceil(3 * sigma))
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    return np.convolve(np.pad(x, r, mode="edge"), k / k.sum(), mode="valid")


def local_minima(x: np.ndarray) -> np.ndarray:
    """Frames where x is lower than both neighbours (the first and last frames never)."""
    return np.nonzero((x[1:-1] < x[:-2]) & (x[1:-1] <= x[2:]))[0] + 1


def motion_beats(positions: np.ndarray, fps: float = FPS) -> np.ndarray:
    """Frames of a dancer's motion beats: local minima of the mean joint speed, smoothed."""
    speed = np.linalg.norm(np.diff(positions, axis=0), axis=-1).mean(-1) * fps
    return local_minima(_smooth(speed, SMOOTH_FRAMES)) + 1


def together(leader_positions: np.ndarray, follower_positions: np.ndarray, fps: float = FPS) -> float:
    """Share of the follower's motion beats within ECHO_SECONDS of one of the leader's."""
    lb, fb = motion_beats(leader_positions, fps), motion_beats(follower_positions, fps)
    if len(lb) == 0 or len(fb) == 0:
        return 0.0
    nearest = np.abs(fb[:, None] - lb[None]).min(1)
    return float(np.mean(nearest <= ECHO_SECONDS * fps))


def steps(positions: np.ndarray, fps: float = FPS) -> np.ndarray:
    """Frames where a foot lands: local minima of the footwork (lightly smoothed), below its median."""
    w = _smooth(footwork(positions, fps), 1.0)
    m = local_minima(w)
    return m[w[m] < np.median(w)]


def on_the_beat(positions: np.ndarray, beat: np.ndarray, fps: float = FPS) -> float:
    """Mean cosine of the count's phase at the dancer's steps (1: every step on a beat)."""
    s = steps(positions, fps)
    if len(s) == 0:
        return 0.0
    return float(np.mean(np.cos(2 * np.pi * beat[s])))


def bpm_of(beat: np.ndarray, fps: float = FPS) -> float:
    """Beats a minute of a count given per frame (beats since the start)."""
    return float(np.median(np.diff(beat)) * fps * 60)


def rhythm(leader_positions: np.ndarray, follower_positions: np.ndarray, beat: np.ndarray,
           bpm: float, fps: float = FPS) -> dict:
    """Every rhythm figure of one duet (or one recorded take): per dancer pulse, period, its
    distance from the music's two beats and steps on the beat; the couple's together."""
    out = {"bpm": float(bpm), "together": together(leader_positions, follower_positions, fps)}
    two_beats = 2 * 60.0 / bpm
    for role, p in (("leader", leader_positions), ("follower", follower_positions)):
        h, lag = pulse(footwork(p, fps), fps)
        out[f"{role}_pulse"] = h
        out[f"{role}_period"] = lag
        out[f"{role}_period_off"] = (float(min(abs(lag / two_beats - 1), abs(lag / (2 * two_beats) - 1)))
                                     if np.isfinite(lag) else float("inf"))
        out[f"{role}_on_beat"] = on_the_beat(p, beat, fps)
    return out


def recorded(data: str) -> dict:
    """The recorded couples' rhythm: every take at its found count (training/data/count.py),
    pooled as means over takes, with each take's own figures under "takes"."""
    from ..data.dataset import discover_takes, load_pair, pair_tracks
    takes = {}
    for take in discover_takes(data):
        lead, follow = pair_tracks(*load_pair(take))
        takes[take.name] = rhythm(lead.positions, follow.positions, lead.beat, bpm_of(lead.beat))
    keys = [k for k in next(iter(takes.values())) if k != "bpm"]
    mean = {k: float(np.mean([t[k] for t in takes.values()])) for k in keys}
    for role in ("leader", "follower"):
        mean[f"{role}_period_within"] = float(np.mean([t[f"{role}_period_off"] <= PERIOD_TOLERANCE for t in takes.values()]))
    return {**mean, "takes": takes}


def turn_counts(data: str) -> dict:
    """Where on the count the recorded followers' turns start (her facing 30 degrees on its way) and
    complete (figures.turns: 300 degrees), per turn; and how concentrated they are: the mean
    resultant length R of their phase within the beat and within the two-beat group (0: spread
    evenly, 1: all at one phase), with the Rayleigh test's p (R that large by chance)."""
    from ..data.dataset import discover_takes, load_pair, pair_tracks
    from . import figures as Fg
    starts, ends = [], []
    for take in discover_takes(data):
        _, follow = pair_tracks(*load_pair(take))
        angle = Fg.facing(follow.positions)
        for t, _ in Fg.turns(angle):
            # back from the completed turn to where it had turned 30 degrees from its start
            k = t
            while k > 0 and t - k < 2 * FPS and abs(angle[t] - angle[k - 1]) < np.radians(330):
                k -= 1
            on_way = np.nonzero(np.abs(angle[k:t + 1] - angle[k]) >= np.radians(30))[0]
            starts.append(follow.beat[k + (int(on_way[0]) if len(on_way) else 0)])
            ends.append(follow.beat[t])
    out = {"turns": len(ends)}
    for name, b in (("start", np.array(starts)), ("end", np.array(ends))):
        for group in (1, 2):
            z = np.mean(np.exp(2j * np.pi * b / group))
            n, r = len(b), float(abs(z))
            out[f"{name}_{group}"] = {"R": r, "p": float(np.exp(-n * r * r)),
                                      "mean": float(np.mod(np.angle(z) / (2 * np.pi) * group, group))}
    return out


# ---------------------------------------------------------------- rollouts

FIGURES = ["pulse", "period_off", "on_beat"]


# Every rhythm figure is read on the bodies the page draws (after the contact layer) and on the
# networks' own: the layer's foot locks and hip glide can move when a foot lands.
BODIES = {"drawn": "as drawn (after the contact layer)", "networks": "the networks' bodies"}


def bodies_rhythm(record: dict, tempo: float, seed: int) -> dict[str, dict]:
    """A recorded duet's rhythm (duet.soak_one's `record`) as drawn and the networks' own, after
    the first second's standing start."""
    sl = slice(FPS, None)
    return {body: {"seed": seed, **rhythm(record["leader" + suffix][sl], record["follower" + suffix][sl],
                                          record["beat"][sl], tempo)}
            for body, suffix in (("drawn", "_shown"), ("networks", ""))}


def duet_rhythm(manifest, leader, follower, seed: int, frames: int, temperature: float,
                tempo: float, steered: bool) -> dict[str, dict]:
    """One of the soak's duets (steered by its stick, or by nobody), at a tempo: its rhythm as
    drawn (the bodies the page shows, after the contact layer) and the networks' own."""
    from .duet import soak_one
    from .options import restart_count
    record: dict = {}
    restart_count(leader, follower)   # each duet starts from its own footwork (on_count.OnCount)
    soak_one(manifest, leader, follower, seed, frames, temperature, record=record, tempo=tempo,
             steer=steered)
    return bodies_rhythm(record, tempo, seed)


def summarize(rows: list[dict], reference: dict) -> dict:
    """Per figure: the mean, the worst seed and its value, and the mean's ratio to the recording."""
    out = {"seeds": len(rows)}
    for role in ("leader", "follower"):
        p = np.array([r[f"{role}_pulse"] for r in rows])
        off = np.array([r[f"{role}_period_off"] for r in rows])
        beat = np.array([r[f"{role}_on_beat"] for r in rows])
        out[role] = {
            "pulse": float(p.mean()), "pulse_ratio": float(p.mean() / reference[f"{role}_pulse"]),
            "pulse_worst": float(p.min()), "pulse_worst_seed": int(rows[int(p.argmin())]["seed"]),
            "period_within": float(np.mean(off <= PERIOD_TOLERANCE)),
            "period_within_recorded": reference[f"{role}_period_within"],
            "period_worst_seed": int(rows[int(off.argmax())]["seed"]),
            "on_beat": float(beat.mean()), "on_beat_recorded": reference[f"{role}_on_beat"],
            "on_beat_worst": float(beat.min()), "on_beat_worst_seed": int(rows[int(beat.argmin())]["seed"]),
        }
    t = np.array([r["together"] for r in rows])
    out["together"] = {"mean": float(t.mean()), "ratio": float(t.mean() / reference["together"]),
                       "worst": float(t.min()), "worst_seed": int(rows[int(t.argmin())]["seed"])}
    return out


def format_summary(title: str, s: dict, reference: dict) -> str:
    lines = [f"{title} ({s['seeds']} seeds)"]
    for role in ("leader", "follower"):
        r = s[role]
        lines.append(f"  {role:<8} pulse {r['pulse']:.2f} ({r['pulse_ratio']:.2f}x the recording's "
                     f"{reference[f'{role}_pulse']:.2f}; worst seed {r['pulse_worst_seed']}: {r['pulse_worst']:.2f}) | "
                     f"period within 4 % of the music's two or four beats: {100 * r['period_within']:.0f} % of seeds "
                     f"(recorded takes {100 * r['period_within_recorded']:.0f} %; worst seed {r['period_worst_seed']}) | on the beat {r['on_beat']:+.2f} "
                     f"(recorded {r['on_beat_recorded']:+.2f}; worst seed {r['on_beat_worst_seed']}: {r['on_beat_worst']:+.2f})")
    t = s["together"]
    lines.append(f"  together {t['mean']:.2f} ({t['ratio']:.2f}x the recording's {reference['together']:.2f}; "
                 f"worst seed {t['worst_seed']}: {t['worst']:.2f})")
    return "\n".join(lines)


def plot(path: str, data: str, manifest, leader, follower, temperature: float, tempo: float,
         take: str = "07", seed: int = 0, start: float = 6.0, seconds: float = 5.0) -> None:
    """Footwork against the beat: a recorded take at its found count above a duet of the shipped
    dancers as the page draws them (nobody steering, `seed`) at `tempo`; vertical lines are the beats."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ..data.dataset import discover_takes, load_pair, pair_tracks, select_takes
    (t,) = select_takes(discover_takes(data), [take])
    lead, follow = pair_tracks(*load_pair(t))
    from .duet import soak_one
    rec: dict = {}
    frames = int((start + seconds) * FPS) + FPS
    soak_one(manifest, leader, follower, seed, frames, temperature, record=rec, tempo=tempo, steer=False)
    rows = [(f"recorded take {take}, its found count", lead.positions, follow.positions, lead.beat),
            (f"the shipped dancers as the page draws them, nobody steering (seed {seed}), music at {tempo:g} beats a minute",
             rec["leader_shown"], rec["follower_shown"], rec["beat"])]
    fig, axes = plt.subplots(2, 1, figsize=(10, 4.2), sharex=True)
    for ax, (title, lp, fp, beat) in zip(axes, rows):
        x, sl = plot_footwork(ax, lp, fp, start, seconds)
        b = beat[sl]
        for k in range(int(np.ceil(b[0])), int(np.floor(b[-1])) + 1):
            i = np.searchsorted(b, k)
            ax.axvline(x[min(i, len(x) - 1)], color="k", lw=0.8, alpha=0.45)
        ax.set_title(title, fontsize=9, loc="left")
        ax.set_ylabel("m/s")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[1].set_xlabel("seconds (footwork: summed ankle speed; lines: the beats; on the count, a foot lands at each line)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    print(f"wrote {path}")


def load_dancers(args):
    """The manifest and both dancers' policies as the page runs them (evaluation.options)."""
    from . import options as O
    from ..mirror.rollout import OnnxPolicy
    path = Path(args.models) / "manifest.json"
    if not path.exists():
        raise SystemExit(f"error: {path} not found (python -m training.learning.export writes it)")
    manifest = json.loads(path.read_text())
    error = O.resolve(args, manifest)
    if error:
        raise SystemExit(f"error: {path}: {error}")
    leader = OnnxPolicy(Path(args.models) / manifest["models"]["leader"]["file"])
    follower = OnnxPolicy(Path(args.models) / manifest["models"][args.follower]["file"])
    return (manifest, O.leader_policy(leader, manifest, args),
            O.follower_policy(follower, manifest, args, args.temperature), args.temperature)


def main(argv=None) -> int:
    from . import options as O
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.rhythm", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "read (the recorded couples' rhythm)")
    add_folder(ap, "models", "read")
    ap.add_argument("--follower", default="follower", help="follower model name in the manifest")
    ap.add_argument("--seeds", type=int, default=100, help="duets per condition (seeds 0..N-1)")
    ap.add_argument("--seconds", type=float, default=60.0, help="length of each duet")
    ap.add_argument("--tempos", default=None, metavar="BPM,BPM...",
                    help="tempos to dance at (default: --tempo, else the manifest's, and 0.9x and 1.1x of it)")
    ap.add_argument("--steer", choices=["both", "steered", "nobody"], default="both")
    ap.add_argument("--out", default=None, help="write every seed's figures and the summaries as JSON")
    ap.add_argument("--plot", metavar="FILE", help="only draw footwork against the beat: a recorded take above "
                                                  "one duet of the networks (PNG)")
    ap.add_argument("--recorded", action="store_true",
                    help="only the recorded couples: each take's rhythm and where on the count her turns start and end")
    O.add_options(ap)
    args = ap.parse_args(argv)
    if args.seeds < 1 or args.seconds < 5:
        ap.error("--seeds must be at least 1 and --seconds at least 5 (a pulse needs a few seconds)")
    if args.recorded:
        reference = recorded(args.data)
        print("take    bpm  pulse L  F   period L  F (s)  on the beat L  F   together")
        for name, t in reference["takes"].items():
            print(f"{name:>4} {t['bpm']:6.1f}  {t['leader_pulse']:.2f} {t['follower_pulse']:.2f}   "
                  f"{t['leader_period']:.2f} {t['follower_period']:.2f}       {t['leader_on_beat']:+.2f} "
                  f"{t['follower_on_beat']:+.2f}     {t['together']:.2f}")
        tc = turn_counts(args.data)
        print(f"her {tc['turns']} recorded turns on the count (R: 0 spread evenly, 1 all at one phase; p: by chance):")
        for name in ("start", "end"):
            for group, what in ((1, "within the beat"), (2, "within the two-beat group")):
                q = tc[f"{name}_{group}"]
                print(f"  {name}s {what}: R {q['R']:.2f} (p {q['p']:.2f}), mean at count {q['mean']:.2f}")
        return 0
    asked_tempo = args.tempo
    manifest, leader, follower, temperature = load_dancers(args)
    if args.plot:
        plot(args.plot, args.data, manifest, leader, follower, temperature, args.tempo)
        return 0
    base = args.tempo   # resolved: --tempo, else the manifest's
    try:
        tempos = ([base] if asked_tempo is not None else [base, 0.9 * base, 1.1 * base]) if args.tempos is None \
            else [float(t) for t in args.tempos.split(",") if t]
    except ValueError:
        ap.error(f"--tempos: expected beats a minute such as 153,170,187, got {args.tempos!r}")
    if not tempos or any(not 60 <= t <= 300 for t in tempos):
        ap.error(f"--tempos: each tempo must be 60-300 beats a minute, got {args.tempos}")
    reference = recorded(args.data)
    print(f"the recorded couples ({len(reference['takes'])} takes, each at its found count): "
          f"pulse leader {reference['leader_pulse']:.2f} follower {reference['follower_pulse']:.2f}, "
          f"together {reference['together']:.2f}, on the beat leader {reference['leader_on_beat']:+.2f} "
          f"follower {reference['follower_on_beat']:+.2f}")
    frames = int(args.seconds * FPS) + FPS
    modes = {"both": [True, False], "steered": [True], "nobody": [False]}[args.steer]
    report = {"reference": reference, "runs": []}
    t0 = time.time()
    for tempo in tempos:
        for steered in modes:
            rows = []
            for seed in range(args.seeds):
                rows.append(duet_rhythm(manifest, leader, follower, seed, frames, temperature, tempo, steered))
                print(f"\r  {tempo:.0f} bpm, {'steered' if steered else 'nobody steering'}: seed {seed + 1}/{args.seeds} "
                      f"({time.time() - t0:.0f} s)", end="", file=sys.stderr, flush=True)
            print(file=sys.stderr)
            for body, what in BODIES.items():
                b_rows = [r[body] for r in rows]
                s = summarize(b_rows, reference)
                title = f"{tempo:.1f} beats a minute, {'steered (the soak stick)' if steered else 'nobody steering'}, {what}"
                print(format_summary(title, s, reference), flush=True)
                report["runs"].append({"tempo": tempo, "steered": steered, "bodies": body, "summary": s, "seeds": b_rows})
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(report, indent=1, default=float))
        print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
