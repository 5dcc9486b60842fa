"""python -m training.evaluation.recorded_leads: what the recorded leader's hands do around her turns.

The numbers behind the page's lead (training/mirror/rollout.py: LEAD_HAND_RAISED, RAISE, and the
hand that leads each direction). For every recorded follower turn (figures.turns: 300 degrees
within 2.5 s, timed where the 300 are reached), in every take as recorded and mirrored, it reads
the leader's hands in his own root space (x to his left, y up, z ahead) from WINDOW[0] to
WINDOW[1] seconds around the turn's completion, and reports:
- how high his higher hand peaks in the PEAK seconds before completion, how often above RAISED
  metres, and how often his hands are that high in any frame;
- when the peak comes, which hand it is for each direction, and where it is;
- which way the higher hand winds over the floor plan in the last second (its signed area,
  lead.winding's sign: negative for her turn to the left);
- how far his own facing goes her way over a request's span around her turn (FACING_SPAN seconds
  from her turn's completion: a request's 2.5 s, her turn completing where the page's requests
  complete it), and how far his root moves: rollout.LEAD_TURN and LEAD_SIDE are read against it;
- in windows of REQUEST_SECONDS from every EVERY-th frame (what `lead` reads after a request and at
  the same moments unasked): how often his hand goes above RAISED metres, and how often she, and
  he, complete a turn in the windows with it and without it; and the ratio `lead` reports (asked /
  unasked) as the recorded couple scores it (request_contrast): beside a leader who raises his hand
  as often as this one, the unasked moments already hold her turns in most windows.

    python -m training.evaluation.recorded_leads
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

from ..data.dataset import DataError, discover_takes, load_pair, pair_tracks
from ..data.folders import add_folder
from ..mirror import features as feat
from ..mirror.skeleton import FPS, HANDS
from . import figures as F
from .figures import HAND_RAISED
from .lead import winding

WINDOW = (-2.0, 0.5)   # s around the turn's completion
PEAK = 1.5             # s before completion where the lead's peak is looked for
WIND = 1.0             # s before completion over which the winding is read
EVERY = 6              # frames between the windows' starts
FACING_SPAN = (-1.7, 0.8)   # s around the turn's completion
REQUEST_SECONDS = 2.5       # s: the windows her turns and his raised hand are read in (`lead` reads 4 s after a request)


def couples(data: str):
    """Every recorded couple of `data` as recorded and mirrored: (leader, follower) tracks."""
    for take in discover_takes(data):
        lead_m, follow_m = load_pair(take)
        for mirror in (False, True):
            yield pair_tracks(lead_m, follow_m, 0, mirror)


def hands_around_turns(data: str) -> tuple[dict[int, list[np.ndarray]], np.ndarray]:
    """({direction: [hands [frames, 2, 3] around each turn]}, all his hands [N, 2, 3]), root space."""
    offsets = np.arange(int(WINDOW[0] * FPS), int(WINDOW[1] * FPS) + 1)
    around, every = {1: [], -1: []}, []
    for lead, follow in couples(data):
        hands = feat.to_root_space_points(lead.positions[:, HANDS], lead.root[:, None], lead.heading[:, None])
        every.append(hands)
        for t, direction in F.turns(F.facing(follow.positions)):
            idx = t + offsets
            if idx[0] >= 0 and idx[-1] < lead.frames:
                around[direction].append(hands[idx])
    return around, np.concatenate(every)


def facing_around_turns(data: str) -> tuple[np.ndarray, np.ndarray]:
    """[turns] degrees his facing goes her way over FACING_SPAN around each of her turns (signed:
    positive the way she turns), and [turns] metres his root moves over it."""
    a, b = int(round(FACING_SPAN[0] * FPS)), int(round(FACING_SPAN[1] * FPS))
    turned, moved = [], []
    for lead, follow in couples(data):
        his = F.facing(lead.positions)   # unwrapped
        for t, direction in F.turns(F.facing(follow.positions)):
            if t + a >= 0 and t + b < lead.frames:
                turned.append(direction * np.degrees(his[t + b] - his[t + a]))
                moved.append(float(np.linalg.norm(lead.root[t + b] - lead.root[t + a])))
    return np.array(turned), np.array(moved)


def facing_report(turned: np.ndarray, moved: np.ndarray) -> str:
    q = np.percentile(turned, [25, 50, 75])
    return (f"His facing over the {FACING_SPAN[1] - FACING_SPAN[0]:g} s from {-FACING_SPAN[0]:g} s before her turn "
            f"completes: her way by a median {q[1]:+.0f} degrees (quartiles {q[0]:+.0f} and {q[2]:+.0f}, {len(turned)} turns); "
            f"his root moves a median {np.median(moved):.2f} m.")


def windows(data: str) -> np.ndarray:
    """[N, 3] bool, a row per REQUEST_SECONDS window from every EVERY-th frame of every take (as
    recorded and mirrored): his higher hand goes above HAND_RAISED, she completes a turn, he does."""
    w, rows = int(REQUEST_SECONDS * FPS), []
    for lead, follow in couples(data):
        hand = lead.positions[:, HANDS, 1].max(-1)
        hers, his = F.facing(follow.positions), F.facing(lead.positions)   # unwrapped: a window is a slice
        for s in range(0, lead.frames - w, EVERY):
            sl = slice(s, s + w + 1)
            rows.append((hand[sl].max() > HAND_RAISED, bool(F.turns(hers[sl])), bool(F.turns(his[sl]))))
    return np.array(rows, bool).reshape(-1, 3)


def request_contrast(r: np.ndarray) -> tuple[float, float]:
    """lead's asked / unasked ratio read on the recording (rows of windows()): how much more often
    she turns in the windows his hand goes up than in all windows (a raise is what a request asks of
    him, and all windows are the unasked moments of a leader who leads as he does), and the same for
    a follower who turned after every raise (1 / her share of all windows). (nan, nan): no turn."""
    up, she = r[:, 0], r[:, 1]
    if not she.any() or not up.any():
        return float("nan"), float("nan")
    return float(she[up].mean() / she.mean()), float(1.0 / she.mean())


def windows_report(r: np.ndarray) -> str:
    up, she, he = r[:, 0], r[:, 1], r[:, 2]
    pct = lambda x: f"{100 * x.mean():.1f} %" if len(x) else "–"
    recorded, every = request_contrast(r)
    return (f"In {len(r)} windows of {REQUEST_SECONDS:g} s (from every {EVERY}th frame): his hand goes above "
            f"{HAND_RAISED:g} m in {pct(up)}; she completes a turn in {pct(she)} of them, {pct(she[up])} with his "
            f"hand up and {pct(she[~up])} without; he completes one in {pct(he)}, {pct(he[up])} and {pct(he[~up])}. "
            f"Read as lead's requests against the same moments unasked: she turns {recorded:.2f}x as often "
            f"with his hand up as in all windows; a follower who turned after every raise, {every:.2f}x.")


def report(around: dict[int, list[np.ndarray]], every: np.ndarray) -> list[str]:
    start = int(WINDOW[0] * FPS)
    peak = slice(int(-PEAK * FPS) - start, -start + 1)
    wind = slice(int(-WIND * FPS) - start, -start + 1)
    n = sum(len(v) for v in around.values())
    highest = np.concatenate([np.stack(v)[:, peak, :, 1].max(axis=(1, 2)) for v in around.values()])
    lines = [f"{n} recorded follower turns (as recorded and mirrored); his hands in his root space.",
             f"His higher hand's peak in the {PEAK:g} s before her turn completes: median {np.median(highest):.2f} m "
             f"(10-90 %: {np.percentile(highest, 10):.2f}-{np.percentile(highest, 90):.2f}); above {HAND_RAISED:g} m "
             f"in {100 * (highest > HAND_RAISED).mean():.0f} % of her turns, against {100 * (every[..., 1].max(-1) > HAND_RAISED).mean():.0f} % "
             f"of all his frames."]
    for direction, name in ((1, "to her left (+1)"), (-1, "to her right (-1)")):
        h = np.stack(around[direction])[:, peak]                       # [turns, frames, 2, 3]
        flat = h[..., 1].reshape(len(h), -1).argmax(1)
        frame, hand = np.unravel_index(flat, h.shape[1:3])
        at = h[np.arange(len(h)), frame, hand]                           # [turns, 3]
        left = hand == 0
        seconds = (frame + peak.start + start) / FPS
        signs = np.array([np.sign(winding(x)) for x in np.stack(around[direction])[:, wind]])
        lines.append(f"Her turns {name}: {len(h)}; the peak {-np.median(seconds):.2f} s before completion (median); "
                     f"the left hand's in {100 * left.mean():.0f} %, at ({', '.join(f'{v:.2f}' for v in at[left].mean(0))}) m, "
                     f"the right hand's at ({', '.join(f'{v:.2f}' for v in at[~left].mean(0))}) m; the hand winds "
                     f"negative in {100 * (signs < 0).mean():.0f} % over the last {WIND:g} s.")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.recorded_leads", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "BVH couples")
    args = ap.parse_args(argv)
    try:
        around, every = hands_around_turns(args.data)
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if not around[1] or not around[-1]:
        print(f"error: {args.data}: no recorded turn of both directions to read a lead from", file=sys.stderr)
        return 2
    print("\n".join(report(around, every) + [facing_report(*facing_around_turns(args.data)),
                                              windows_report(windows(args.data))]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
