"""A probe of the lead's way (docs/results.md, "Which way she turns"): does she turn the asked way
when his lead changes? Two leads, each run through `python -m training.evaluation.lead` with the
remaining arguments, then the asked way printed for each way:

- reflect WAY: his lead for one way is his lead for the other, reflected. Training reads every take
  also reflected (skeleton.mirror_motion), so the leader network's answer to a reflected input is as
  good as its answer to the input itself. While a request for WAY runs (+1: her left, -1: her
  right) the leader network reads the duet reflected (x -> -x, left and right swapped), asked for
  the other way, and its step is reflected back. The reflection is checked first against the
  features of a reflected take (take 10, as training builds its mirrored copies).
- plan DEG SIDE: while a request runs, his planned path (the control he reads, and the future path
  she reads) turns DEG degrees her way and moves SIDE metres to his other side, eased as her planned
  turn (rollout.lead_plan with LEAD_TURN = DEG, LEAD_SIDE = SIDE; 0 0: the plan left as it was).

The follower reads him as always.

    PYTHONPATH=. .venv/bin/python scripts/lead_way_probe.py reflect WAY [lead's arguments]
    PYTHONPATH=. .venv/bin/python scripts/lead_way_probe.py reflect 1 --seeds 20 --seconds 30 --no-legibility --out runs/lead_p1
    PYTHONPATH=. .venv/bin/python scripts/lead_way_probe.py plan 45 0 --seeds 20 --seconds 30 --no-legibility --out runs/lead_plan

Per block of the reflection (features.py, docs/features.md): every 3-vector (a position, velocity,
forward or up in root space, a hand's planned move) has its x negated and its joint swapped with
its twin (skeleton.MIRROR); a trajectory key (x, z, forward x, forward z) has both x negated; the
figure's planned turns change sign (the heading is atan2(x, z)); a root update (dx, dz, heading
change) has dx and the heading change negated; the contacts (left, right) swap; the music is what
it was.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from training.data.dataset import discover_takes, load_pair, pair_tracks, samples, select_takes
from training.evaluation import lead
from training.mirror import features as feat
from training.mirror import rollout
from training.mirror.skeleton import HANDS, KEY_JOINTS, MIRROR


def _twins(joints: list[int]) -> list[int]:
    """For a list of joints, where each one's twin sits in the same list."""
    return [joints.index(MIRROR[j]) for j in joints]


def _vectors(order: list[int], vectors_per_item: int) -> tuple[list[int], list[float]]:
    """Items of `vectors_per_item` 3-vectors each, taken in `order`, every x negated."""
    perm, sign = [], []
    for item in order:
        for v in range(vectors_per_item):
            base = (item * vectors_per_item + v) * 3
            perm += [base, base + 1, base + 2]
            sign += [-1.0, 1.0, 1.0]
    return perm, sign


def _block(name: str, size: int) -> tuple[list[int], list[float]]:
    """Where each number of a reflected block comes from in the block, and its sign."""
    if name in ("partner_trajectory_past", "partner_trajectory_future", "self_trajectory_past",
                "control", "trajectory_future"):
        return list(range(size)), [-1.0, 1.0, -1.0, 1.0] * feat.KEYS
    if name in ("partner_key_joints_past", "self_key_joints_past", "key_joints_future",
                "partner_key_joints_future"):
        twins = _twins(list(KEY_JOINTS))
        return _vectors([k * len(KEY_JOINTS) + twins[j] for k in range(feat.KEYS)
                         for j in range(len(KEY_JOINTS))], 1)
    if name in ("partner_pose", "self_pose", "pose"):
        return _vectors(MIRROR, 4)   # position, velocity, forward, up per joint
    if name == "figure":
        return list(range(size)), [1.0] + [-1.0] * feat.KEYS
    if name == "hands_plan":
        twins = _twins(list(HANDS))
        perm, sign = _vectors([k * len(HANDS) + twins[h] for k in range(feat.KEYS) for h in range(len(HANDS))], 1)
        return [0] + [p + 1 for p in perm], [1.0] + sign
    if name == "root_update":
        return [0, 1, 2], [-1.0, 1.0, -1.0]
    if name == "contacts":
        return [1, 0], [1.0, 1.0]
    if name == "music":
        return list(range(size)), [1.0] * size
    raise ValueError(f"no reflection known for the block {name!r}")


def reflection(layout: list[tuple[str, int]]) -> tuple[np.ndarray, np.ndarray]:
    """(perm, sign) for a layout (features.py's): reflected = x[..., perm] * sign."""
    perm, sign, start = [], [], 0
    for name, size in layout:
        p, s = _block(name, size)
        if len(p) != size:
            raise ValueError(f"block {name!r}: {len(p)} numbers reflected, {size} in the layout")
        perm += [start + i for i in p]
        sign += s
        start += size
    return np.array(perm), np.array(sign)


REFLECTIONS = {
    "leader": reflection(feat.LEADER_INPUT_LAYOUT),
    "follower": reflection(feat.FOLLOWER_INPUT_LAYOUT),
    "output": reflection(feat.OUTPUT_LAYOUT),
    "intention": reflection(feat.INTENTION_LAYOUT),
}


def reflect(x: np.ndarray, kind: str) -> np.ndarray:
    """A feature vector [..., size] of `kind` (leader, follower, output, intention) reflected."""
    perm, sign = REFLECTIONS[kind]
    x = np.asarray(x)
    if x.shape[-1] != len(perm):
        raise ValueError(f"a {kind} vector has {len(perm)} numbers, got {x.shape[-1]}")
    return x[..., perm] * sign


def check(data: str = "../shared/data/cmu-salsa") -> None:
    """reflect(features of a take) against the features of the take reflected, every kind."""
    pair = load_pair(select_takes(discover_takes(data), ["10"])[0])
    plain, mirrored = samples(*pair_tracks(*pair)), samples(*pair_tracks(*pair, mirror=True))
    for role in ("leader", "follower"):
        for name, kind in ((f"{role}_input", role), (f"{role}_output", "output"), (f"{role}_intention", "intention")):
            err = np.abs(reflect(plain[name].astype(float), kind) - mirrored[name]).max()
            if err > 2e-4:
                raise SystemExit(f"the reflection of {name} is off by {err:.2g}")


def step(duet, leader_policy, follower_policy, stick, temperature, rng, way: int) -> None:
    """rollout.step, the leader reflected while a request for `way` runs."""
    rollout.steer_plan(duet.leader, duet.steering, np.asarray(stick, float))
    rollout.lead_plan(duet)
    xl, xf = rollout.step_inputs(duet)
    reflected = duet.request is not None and duet.request.direction == way
    ol = leader_policy(reflect(xl, "leader") if reflected else xl, temperature, rng)["output"][0]
    if reflected:
        ol = reflect(ol, "output")
    of = follower_policy(xf, temperature, rng)
    rollout.finish_step(duet, ol, of["output"][0], of["intention"][0] if "intention" in of else None)


def main(argv: list[str]) -> int:
    if len(argv) < 2 or argv[0] not in ("reflect", "plan") or argv[0] == "reflect" and argv[1] not in ("1", "-1"):
        print(__doc__.split("\n\n")[3], file=sys.stderr)
        return 2
    way = None
    if argv[0] == "reflect":
        way = int(argv[1])
        check()
        lead.step = lambda *a: step(*a, way=way)
        argv = argv[2:]
    else:
        rollout.LEAD_TURN, rollout.LEAD_SIDE = float(argv[1]), float(argv[2])
        argv = argv[3:]
    rc = lead.main(argv)
    out = Path(argv[argv.index("--out") + 1] if "--out" in argv else "runs/lead") / "lead.json"
    res = json.loads(out.read_text())
    for asked in (1, -1):
        rq = [r for s in res["per_seed"] for r in s["requests"] if r["direction"] == asked]
        turned, that_way = sum(r["turned"] for r in rq), sum(r["turned_that_way"] for r in rq)
        print(f"asked {'her left' if asked > 0 else 'her right'}{' (reflected)' if asked == way else ''}: "
              f"{len(rq)} requests, a turn after {turned}, the asked way after {that_way} "
              f"({100 * that_way / max(len(rq), 1):.0f} % of requests)")
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
