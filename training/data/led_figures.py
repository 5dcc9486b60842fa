"""The figures the recorded couples dance, labelled from the recording: `python -m training.data.led_figures`.

A figure is a stretch of the dance that the leader leads and both dancers dance. The labels read
world joint positions only (training/evaluation/figures.py's facing and turn rule), so they hold
for any couple, recorded, mirrored or synthetic:

- **her turn** (`her_turn`), way +1 to her left (counterclockwise seen from above, as the heading)
  or -1 to her right: her facing turns TURN_DEGREES within TURN_SECONDS. It begins at his
  preparation, where his higher hand goes up above HAND_RAISED for it (when it is up between
  PREPARE_SECONDS before she starts to turn and her first full turn; not before the figure before
  ends), else where she starts to turn; it ends where she has finished: her facing turns slower
  than SETTLED_DEG_PER_S again. Turns of one spin without a pause are one figure.
- **his turn** (`his_turn`): the same rule on his facing, from where he starts to where he has
  finished (a leader's own turn is seldom prepared with a raised hand).

Where she starts to turn is the last frame before the turn's completion that turns slower than
SETTLED_DEG_PER_S. A mirrored couple dances the same figures the other way (mirror_motion swaps
left and right), which `figures_of(..., mirror=True)` gives.

The count of a take (training/data/count.py) says where on the count each figure begins: the data
carries the beat and the two-beat group, not the 8-count's measure, so a start is placed within
its two beats (0 on an even beat, 1 on the odd beat between).
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..evaluation.figures import HAND_RAISED, TURN_DEGREES, TURN_SECONDS, facing, turns
from ..mirror.features import FIGURE_KINDS
from ..mirror.skeleton import FPS, HANDS
from .folders import default_data

SETTLED_DEG_PER_S = 120.0   # a facing turning slower than this has not begun / has finished a turn
PREPARE_SECONDS = 1.5       # his hand up at most this long before her turn begins prepares it
SMOOTH_FRAMES = 5           # frames the turning rate is averaged over (one noisy shoulder line is not a turn)
NAMES = ("her_turn", "his_turn")


@dataclass(frozen=True)
class Figure:
    name: str      # her_turn or his_turn
    way: int       # +1 counterclockwise seen from above (her / his left), -1 clockwise
    start: int     # frame (30 fps) the figure begins: his preparation, or the turn's first frame
    turned: int    # frame its first turn reaches TURN_DEGREES (figures.turns)
    end: int       # frame the dancer has finished turning
    prepared: bool  # his hand went up for it (her turns only)
    turns: int = 1  # the turns of TURN_DEGREES it holds: a spin of two turns is one figure

    def beats(self, beat: np.ndarray) -> float:
        return float(beat[self.end] - beat[self.start])


def turning_rate(angle: np.ndarray, fps: int = FPS) -> np.ndarray:
    """[T] |d facing / dt| in degrees a second, averaged over SMOOTH_FRAMES."""
    rate = np.abs(np.degrees(np.gradient(angle))) * fps
    return np.convolve(rate, np.ones(SMOOTH_FRAMES) / SMOOTH_FRAMES, "same")


def turn_span(rate: np.ndarray, turned: int) -> tuple[int, int]:
    """(first, last) frame of the turn that completes at `turned`: the frames around it that turn
    faster than SETTLED_DEG_PER_S."""
    slow = rate < SETTLED_DEG_PER_S
    before = np.flatnonzero(slow[:turned + 1])
    after = np.flatnonzero(slow[turned:])
    first = int(before[-1]) + 1 if len(before) else 0
    last = turned + int(after[0]) - 1 if len(after) else len(rate) - 1
    return min(first, turned), max(last, turned)


def preparation(hand: np.ndarray, begins: int, turned: int, fps: int = FPS) -> int | None:
    """The frame his hand goes up for a turn that begins at `begins` and completes at `turned`:
    the start of the stretch of frames with it above HAND_RAISED that reaches into
    [begins - PREPARE_SECONDS, turned]; None when it is down all that time."""
    earliest = max(0, begins - int(round(PREPARE_SECONDS * fps)))
    up = np.flatnonzero(hand[earliest:turned + 1] > HAND_RAISED)
    if len(up) == 0:
        return None
    at = earliest + int(up[0])
    while at > 0 and hand[at - 1] > HAND_RAISED:
        at -= 1
    return at


def dancer_turns(positions: np.ndarray, name: str, hand: np.ndarray | None) -> list[Figure]:
    angle = facing(positions)
    rate = turning_rate(angle)
    out = []
    for turned, way in turns(angle, TURN_DEGREES, TURN_SECONDS):
        first, last = turn_span(rate, turned)
        if out and out[-1].way == way and first <= out[-1].end:
            # The same spin goes on: one figure of more turns.
            f = out[-1]
            out[-1] = Figure(name, f.way, f.start, f.turned, max(f.end, last), f.prepared, f.turns + 1)
            continue
        prep = preparation(hand, first, turned) if hand is not None else None
        start = first if prep is None else min(prep, first)
        if out:   # a hand kept up from the figure before prepares this one from that one's end on
            start = max(start, min(first, out[-1].end + 1))
        out.append(Figure(name, int(way), start, turned, last, prep is not None))
    return out


def figures_of(lead_positions: np.ndarray, follow_positions: np.ndarray) -> list[Figure]:
    """Every figure of one couple (30 fps world positions [T, 17, 3] each), in time order."""
    hand = lead_positions[:, HANDS, 1].max(-1)
    found = dancer_turns(follow_positions, "her_turn", hand) + dancer_turns(lead_positions, "his_turn", None)
    return sorted(found, key=lambda f: (f.start, f.name))


def figure_spans(lead_positions: np.ndarray, follow_positions: np.ndarray) -> np.ndarray:
    """[M, 3] int (kind, start, end) of every figure of one couple, kind an index into
    features.FIGURE_KINDS: the figures both networks read (features.figure_block), labelled from
    the recording for training and evaluation."""
    spans = [(FIGURE_KINDS.index((f.name, f.way)), f.start, f.end) for f in figures_of(lead_positions, follow_positions)]
    return np.array(spans, dtype=np.int64).reshape(-1, 3)


def take_figures(data: str, names: list[str] | None = None, mirror: bool = False) -> dict[str, dict]:
    """{take: {"seconds", "beat" [T], "figures" [Figure]}} of the recorded takes at 30 fps."""
    # Imported here: dataset labels its samples with figure_spans.
    from .dataset import discover_takes, load_pair, pair_tracks, select_takes
    out = {}
    for take in select_takes(discover_takes(data), names):
        lead, follow = pair_tracks(*load_pair(take), mirror=mirror)
        out[take.name] = {"seconds": lead.frames / FPS, "beat": lead.beat,
                          "figures": figures_of(lead.positions, follow.positions)}
    return out


def on_the_count(beat: float) -> float:
    """Where in its two beats a figure begins: 0 on an even beat, 1 on the odd beat, in [0, 2)."""
    return float(beat % 2.0)


def summary(takes: dict[str, dict]) -> dict:
    """Counts per take and name/way, lengths in beats and starts on the count, pooled."""
    rows, pooled = [], {n: {"ways": {"+1": 0, "-1": 0}, "beats": [], "starts": [], "prepared": 0, "turns": 0} for n in NAMES}
    for name, t in takes.items():
        row = {"take": name, "seconds": t["seconds"]}
        for n in NAMES:
            fs = [f for f in t["figures"] if f.name == n]
            row[n] = {"+1": sum(f.way > 0 for f in fs), "-1": sum(f.way < 0 for f in fs)}
            p = pooled[n]
            for f in fs:
                p["ways"]["+1" if f.way > 0 else "-1"] += 1
                p["beats"].append(f.beats(t["beat"]))
                p["starts"].append(on_the_count(t["beat"][f.start]))
                p["prepared"] += f.prepared
                p["turns"] += f.turns
        rows.append(row)
    minutes = sum(t["seconds"] for t in takes.values()) / 60
    out = {"takes": rows, "minutes": minutes, "figures": {}}
    for n, p in pooled.items():
        count = len(p["beats"])
        starts = np.array(p["starts"])
        out["figures"][n] = {
            "count": count, "per_minute": count / minutes if minutes else 0.0, "ways": p["ways"],
            "prepared": p["prepared"], "turns": p["turns"],
            "beats": {"median": float(np.median(p["beats"])) if count else None,
                      "p10": float(np.percentile(p["beats"], 10)) if count else None,
                      "p90": float(np.percentile(p["beats"], 90)) if count else None},
            # Starts in quarter beats of the two-beat group: 8 bins from 0 (an even beat).
            "starts_quarter_beats": np.histogram(starts, bins=8, range=(0, 2))[0].tolist(),
        }
    return out


def markdown(s: dict) -> str:
    L = ["| take | seconds | her turns to her left / right | his turns left / right |", "|---|---|---|---|"]
    for r in s["takes"]:
        L.append(f"| {r['take']} | {r['seconds']:.0f} | {r['her_turn']['+1']} / {r['her_turn']['-1']} | "
                 f"{r['his_turn']['+1']} / {r['his_turn']['-1']} |")
    L += ["", "| figure | in all (a minute) | turns of 300° in them | left / right | his hand up for it | length in beats: median (10-90 %) | "
              "starts in each quarter beat of the two-beat group, from an even beat |", "|---|---|---|---|---|---|---|"]
    for n, f in s["figures"].items():
        b = f["beats"]
        length = "–" if b["median"] is None else f"{b['median']:.1f} ({b['p10']:.1f}-{b['p90']:.1f})"
        prepared = f"{f['prepared']} ({100 * f['prepared'] / f['count']:.0f} %)" if n == "her_turn" and f["count"] else "–"
        L.append(f"| {n.replace('_', ' ')} | {f['count']} ({f['per_minute']:.1f}) | {f['turns']} | {f['ways']['+1']} / {f['ways']['-1']} | "
                 f"{prepared} | {length} | {' · '.join(str(v) for v in f['starts_quarter_beats'])} |")
    return "\n".join(L) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.data.led_figures", description=__doc__.splitlines()[0])
    ap.add_argument("--data", default=None, metavar="DIR", help="BVH couples (default: docs/data.md, Where the commands look)")
    ap.add_argument("--takes", default=None, help="comma-separated take names (default: every take)")
    ap.add_argument("--mirror", action="store_true", help="the mirrored couples (every way flipped)")
    ap.add_argument("--out", default="runs/figures", metavar="DIR", help="writes led_figures.json and led_figures.md there")
    args = ap.parse_args(argv)
    from .dataset import DataError
    try:
        takes = take_figures(args.data or default_data(), args.takes.split(",") if args.takes else None, args.mirror)
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    s = summary(takes)
    s["labels"] = {name: [asdict(f) for f in t["figures"]] for name, t in takes.items()}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "led_figures.json").write_text(json.dumps(s, indent=1))
    text = markdown(s)
    (out / "led_figures.md").write_text(text)
    print(text + f"\nwrote {out / 'led_figures.json'} and {out / 'led_figures.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
