"""A probe of what tells her turn's way (docs/results.md, "Which way she turns"): at recorded
frames before each of her turns' completion, in every take as recorded and mirrored, her network's
next step (its heading change, the mean of 16 draws at variety 0.5) is read with her input as
recorded and with some of its blocks reflected (x -> -x, left and right swapped:
scripts/reflected_lead_probe.py's reflection). A block that carries the way turns her the other way
when reflected.

    PYTHONPATH=. .venv/bin/python scripts/her_reading_probe.py [FRAMES [FOLLOWER.onnx]]
    PYTHONPATH=. .venv/bin/python scripts/her_reading_probe.py -45,-20,-10
"""
import importlib.util
import sys
from pathlib import Path

import numpy as np

from training.data.dataset import discover_takes, load_pair, pair_tracks, samples
from training.evaluation import figures as F
from training.mirror import features as feat
from training.mirror.rollout import OnnxPolicy

_spec = importlib.util.spec_from_file_location("reflected_lead_probe", Path(__file__).with_name("reflected_lead_probe.py"))
_probe = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_probe)

HIS = ["partner_trajectory_past", "partner_trajectory_future", "partner_key_joints_past", "partner_pose"]
HERS = ["self_trajectory_past", "self_key_joints_past", "self_pose"]
VARIANTS = {"as recorded": [], "his blocks reflected": HIS, "his future path": ["partner_trajectory_future"],
            "his past path": ["partner_trajectory_past"], "his key joints": ["partner_key_joints_past"],
            "his pose": ["partner_pose"], "her own blocks reflected": HERS, "all reflected": HIS + HERS}
DRAWS, VARIETY = 16, 0.5


def main(argv: list[str]) -> int:
    offsets = [int(a) for a in argv[0].split(",")] if argv else [-20, -10, -6]
    policy = OnnxPolicy(argv[1] if len(argv) > 1 else "public/models/follower.onnx")
    rng = np.random.default_rng(0)
    sl = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)
    cols = {v: np.concatenate([np.arange(sl[n].start, sl[n].stop) for n in names]) if names else None
            for v, names in VARIANTS.items()}
    way = {o: {v: [] for v in VARIANTS} for o in offsets}
    for take in discover_takes("../shared/data/cmu-salsa"):
        lead, follow = load_pair(take)
        for mirror in (False, True):
            lt, ft = pair_tracks(lead, follow, mirror=mirror)
            s = samples(lt, ft)
            for f, d in F.turns(F.facing(ft.positions)):
                for o in offsets:
                    i = np.searchsorted(s["frame"], f + o)
                    if i >= len(s["frame"]) or s["frame"][i] != f + o:
                        continue
                    x = s["follower_input"][i].astype(np.float64)
                    xr = _probe.reflect(x, "follower")
                    for v, c in cols.items():
                        y = x.copy()
                        if c is not None:
                            y[c] = xr[c]
                        out = policy(np.repeat(y[None], DRAWS, 0), VARIETY, rng)["output"]
                        way[o][v].append(d * np.sign(out[:, 2].mean()) > 0)
    for o in offsets:
        print(f"{o} frames from the completion ({len(way[o]['as recorded'])} turns): her next step turns the recorded way")
        for v in VARIANTS:
            print(f"   {v:26s} {100 * np.mean(way[o][v]):3.0f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
