"""The page's own duets against the recording: the figures of what scripts/figures_probe.mjs saw.

    node scripts/figures_probe.mjs 1,2,...,20          # the page dances each seed 30 s, nobody steering
    python -m training.evaluation.page_figures runs/figures_probe.json

The probe records both dancers' joints at every step as the page draws them (after the contact
layer) and as the networks left them, and the count each step danced on, nobody steering and
nobody asking for a turn. This measures them with figures.py as training.evaluation.lead measures
its "Dancing unasked" duets in Python: turns a minute, spin frames, body motion and travel of each
dancer against the recorded couple of the test takes, the least-turning seed of each, and the
leader's largest distance from his spot (where the page started him; lead measures it from where
its duets start him); and with rhythm.py as training.evaluation.rhythm measures its duets nobody
steering: each dancer's footwork pulse, steps on the beat and the partners together, as drawn and
on the networks' bodies.
Issue 30 asks these in the page as well as in Python (items 1 and 4).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ..data.dataset import DataError, TEST_TAKES
from ..data.folders import add_folder
from ..mirror.skeleton import FPS
from .evaluate_inputs import EvalError
from .lead import dancing, dancing_summary, dancing_table, recording
from .rhythm import BODIES, bodies_rhythm, format_summary, recorded, summarize

ROLES = ("leader", "follower")


def load(path: Path) -> dict:
    """The probe's file, checked: one entry per seed, each dancer [steps, 17 * 3] at the model's rate."""
    try:
        dump = json.loads(Path(path).read_text())
    except FileNotFoundError:
        raise EvalError(f"{path}: no such file (write it with node scripts/figures_probe.mjs)") from None
    except json.JSONDecodeError as e:
        raise EvalError(f"{path}: not JSON ({e})") from None
    if dump.get("fps") != FPS:
        raise EvalError(f"{path}: recorded at {dump.get('fps')} steps a second, the models step at {FPS}")
    if not dump.get("seeds"):
        raise EvalError(f"{path}: no seeds")
    for s in dump["seeds"]:
        for who in ROLES:
            p = np.asarray(s[who], float)
            if p.ndim != 2 or p.shape[1] != 51 or len(p) < 5 * FPS or not np.isfinite(p).all():
                raise EvalError(f"{path}: seed {s['seed']}'s {who} is not at least 5 s of 17 finite joints "
                                f"(shape {p.shape})")
        if "beat" in s:    # the count: one per step, beside both bodies of both dancers
            steps = {len(s.get(k, [])) for k in ("beat", "leader", "follower", "leaderOwn", "followerOwn")}
            if len(steps) != 1 or not np.isfinite(np.asarray(s["beat"], float)).all() or not s.get("tempo", 0) > 0:
                raise EvalError(f"{path}: seed {s['seed']}: the count, its tempo and both bodies of both dancers "
                                f"need one entry a step each (steps of the count and the bodies: {sorted(steps)})")
    return dump


def one_seed(s: dict) -> dict:
    """lead.dancing of one seed: the leader's distance from the seed's `start` (x, z) when the dump
    has it (the probe: where the page put him), else from where the recording began."""
    lead, follow = (np.asarray(s[who], float).reshape(-1, 17, 3) for who in ROLES)
    return {"seed": s["seed"], **dancing(lead, follow, s.get("start"))}


def seed_rhythm(s: dict) -> dict[str, dict]:
    """One seed's rhythm as drawn and on the networks' bodies (the probe's `leaderOwn` /
    `followerOwn`) over the count each step danced on: rhythm.bodies_rhythm of the seed as
    duet.soak_one's record holds a duet. {} when the dump holds no count (a probe before it recorded one)."""
    if "beat" not in s:
        return {}
    record = {"beat": np.asarray(s["beat"], float)}
    for who in ROLES:
        record[f"{who}_shown"] = np.asarray(s[who], float).reshape(-1, 17, 3)
        record[who] = np.asarray(s[who + "Own"], float).reshape(-1, 17, 3)
    return bodies_rhythm(record, float(s["tempo"]), s["seed"])


def markdown(res: dict) -> str:
    lines = [f"# The page's duets, nobody steering: {len(res['per_seed'])} seeds × {res['seconds']:g} s "
             f"(scripts/figures_probe.mjs, as drawn after the contact layer), against the recording "
             f"of takes {', '.join(res['takes'])}", "", *dancing_table(res["summary"], res["recording"])]
    if res.get("rhythm"):
        ref = res["rhythm_reference"]
        lines += ["", f"## Their rhythm at {res['tempo']:g} beats a minute (the page's silent count; Python's own: "
                      f"`rhythm --steer nobody --tempos {res['tempo']:g} --seconds {res['seconds']:g} --seeds N`)", "",
                  f"the recorded couples: pulse leader {ref['leader_pulse']:.2f} follower {ref['follower_pulse']:.2f}, "
                  f"together {ref['together']:.2f}, on the beat leader {ref['leader_on_beat']:+.2f} "
                  f"follower {ref['follower_on_beat']:+.2f}", ""]
        for body, what in BODIES.items():
            lines += [format_summary(f"the page, {what}", res["rhythm"][body], ref), ""]
    return "\n".join(lines) + "\n"


def run(args) -> dict:
    dump = load(args.dump)
    takes = [t for t in args.takes.split(",") if t]
    per_seed = [one_seed(s) for s in dump["seeds"]]
    ref = recording(args.data, takes)
    res = {"takes": takes, "recording": ref, "seconds": dump.get("seconds", 0), "per_seed": per_seed,
           "summary": dancing_summary(per_seed, ref)}
    rhythms = [seed_rhythm(s) for s in dump["seeds"]]
    if all(rhythms):
        tempos = {float(s["tempo"]) for s in dump["seeds"]}
        if len(tempos) != 1:
            raise EvalError(f"{args.dump}: the seeds danced at {sorted(tempos)} beats a minute, not one tempo")
        reference = recorded(args.data)
        res.update(tempo=tempos.pop(), rhythm_reference=reference,
                   rhythm={body: summarize([r[body] for r in rhythms], reference) for body in BODIES},
                   rhythm_per_seed=rhythms)
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.page_figures", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dump", type=Path, help="the JSON file scripts/figures_probe.mjs wrote")
    add_folder(ap, "data", "read: the recorded dancers to compare with")
    ap.add_argument("--takes", default=",".join(TEST_TAKES))
    ap.add_argument("--out", default=None, help="also write the table and the numbers here (a folder)")
    args = ap.parse_args(argv)
    try:
        res = run(args)
    except (EvalError, DataError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    text = markdown(res)
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "page_figures.json").write_text(json.dumps(res, indent=1))
        (out / "page_figures.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
