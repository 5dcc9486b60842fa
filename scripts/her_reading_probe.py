"""A probe of what tells her turn's way (docs/results.md, "Which way she turns"): her network reads
the recorded couple with some blocks of her input reflected (x -> -x, left and right swapped:
scripts/lead_way_probe.py's reflection). A block that carries the way turns her the other way
when reflected. Two readings:

- one step: at recorded frames FRAMES before each of her turns' completion, in every take as
  recorded and mirrored, her next step's heading change (the mean of 16 draws at variety 0.5);
- free runs (--free): beside the played-back recorded leader, every take, SEEDS seeds at variety
  0.5 with no guard (as evaluate's free runs), her turns that meet a recorded one within 0.75 s and
  how many of them go its way (figures.against).

    PYTHONPATH=. .venv/bin/python scripts/her_reading_probe.py [FRAMES [FOLLOWER.onnx]]
    PYTHONPATH=. .venv/bin/python scripts/her_reading_probe.py -45,-20,-10
    PYTHONPATH=. .venv/bin/python scripts/her_reading_probe.py --free [SEEDS [FOLLOWER.onnx]]
"""
import importlib.util
import json
import sys
from pathlib import Path

import numpy as np

from training.data.dataset import discover_takes, load_pair, pair_tracks, samples
from training.evaluation import figures as F
from training.evaluation.evaluate_inputs import load_eval_takes
from training.evaluation.evaluate_rollouts import rollout
from training.mirror import features as feat
from training.mirror.features import HISTORY
from training.mirror.rollout import OnnxPolicy

_spec = importlib.util.spec_from_file_location("lead_way_probe", Path(__file__).with_name("lead_way_probe.py"))
_probe = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_probe)

DATA, MODEL = "../shared/data/cmu-salsa", "public/models/follower.onnx"
HIS = ["partner_trajectory_past", "partner_trajectory_future", "partner_key_joints_past", "partner_pose"]
HERS = ["self_trajectory_past", "self_key_joints_past", "self_pose"]
ONE_STEP = {"as recorded": [], "his blocks reflected": HIS, "his future path": ["partner_trajectory_future"],
            "his past path": ["partner_trajectory_past"], "his key joints": ["partner_key_joints_past"],
            "his pose": ["partner_pose"], "her own blocks reflected": HERS, "all reflected": HIS + HERS}
FREE = {"as recorded": [], "his body reflected (key joints, pose)": ["partner_key_joints_past", "partner_pose"],
        "his path reflected (past, future)": ["partner_trajectory_past", "partner_trajectory_future"]}
DRAWS, VARIETY = 16, 0.5


def columns(names: list[str]) -> np.ndarray | None:
    sl = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)
    return np.concatenate([np.arange(sl[n].start, sl[n].stop) for n in names]) if names else None


def partly_reflected(x: np.ndarray, cols: np.ndarray | None) -> np.ndarray:
    if cols is None:
        return x
    y = np.array(x, np.float64, copy=True)
    y[..., cols] = _probe.reflect(x, "follower")[..., cols]
    return y


def one_step(offsets: list[int], model: str) -> None:
    policy, rng = OnnxPolicy(model), np.random.default_rng(0)
    cols = {v: columns(names) for v, names in ONE_STEP.items()}
    way = {o: {v: [] for v in ONE_STEP} for o in offsets}
    for take in discover_takes(DATA):
        lead, follow = load_pair(take)
        for mirror in (False, True):
            tracks = pair_tracks(lead, follow, mirror=mirror)
            s = samples(*tracks)
            for f, d in F.turns(F.facing(tracks[1].positions)):
                for o in offsets:
                    i = np.searchsorted(s["frame"], f + o)
                    if i >= len(s["frame"]) or s["frame"][i] != f + o:
                        continue
                    x = s["follower_input"][i].astype(np.float64)
                    for v, c in cols.items():
                        out = policy(np.repeat(partly_reflected(x, c)[None], DRAWS, 0), VARIETY, rng)["output"]
                        way[o][v].append(d * np.sign(out[:, 2].mean()) > 0)
    for o in offsets:
        print(f"{o} frames from the completion ({len(way[o]['as recorded'])} turns): her next step turns the recorded way")
        for v in ONE_STEP:
            print(f"   {v:26s} {100 * np.mean(way[o][v]):3.0f} %")


def free_runs(seeds: int, model: str) -> None:
    base = OnnxPolicy(model)
    takes = load_eval_takes(DATA, [t.name for t in discover_takes(DATA)], None, None)
    start_pose = json.loads(Path("public/models/manifest.json").read_text())["startPose"]
    for v, names in FREE.items():
        c = columns(names)
        same = met = found = 0
        for take in takes:
            t0 = int(take.frames[0])
            recorded = take.follow.positions[t0 - HISTORY:t0 + len(take.frames) + 1]
            for seed in range(seeds):
                rec = rollout(take, lambda x, t, rng: base(partly_reflected(x, c), t, rng), VARIETY, seed, start_pose)
                a = F.against(rec["positions"], recorded)
                same, met, found = same + a["matched"], met + a["matched_any_direction"], found + a["found"]
        print(f"{v:38s} her turns {found}, meeting a recorded one {met}, its way {same} ({100 * same / max(met, 1):.0f} %)")


def main(argv: list[str]) -> int:
    if argv and argv[0] == "--free":
        free_runs(int(argv[1]) if len(argv) > 1 else 5, argv[2] if len(argv) > 2 else MODEL)
    else:
        one_step([int(a) for a in argv[0].split(",")] if argv else [-20, -10, -6], argv[1] if len(argv) > 1 else MODEL)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
