"""python -m training.evaluation.interaction: do the two dancers read as a couple? -> interaction.json + .md

    python -m training.evaluation.interaction --data DIR --takes 02,13 --models public/models --out runs/interaction

Every number is read against the recording of the same takes (metrics.interaction: torsos
interpenetrating, a hand pair within 20 cm, the closest hand pair's distance, foot skate while
the ankle is low and while labelled in contact, and the share of frames with a foot in contact),
and given as a ratio to it. Follower methods: every follower ONNX in --models (ours, CCM, ...)
and Motion Matching over the training takes. Three protocols:

- teacher-forced: every input from the recording; the predicted next pose is placed from the
  recorded root and set against the recorded leader;
- free-running: the leader played back from the recording, the follower fed its own output
  (training.evaluation.evaluate's rollout), one seed;
- steered: our leader model and the follower, steered by training.evaluation.soak's script (--seeds of
  --seconds each), the loop of training/mirror/rollout.py.

Free-running and steered rows come twice: the networks alone (the Tracks, what the features
read) and with the run-time contact layer (training/mirror/contact.py, what the page shows), so the
layer never hides what the networks do. Steering response (training.evaluation.soak.steering_trials) is
measured for our leader with each follower.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..mirror import features as feat
from . import metrics as M
from . import options as O
from . import plausibility as P
from ..mirror.contact import ContactLayer
from ..data.dataset import DataError
from .evaluate_inputs import EvalError, EvalTake, find_models, load_eval_takes, load_onnx, window
from .evaluate_report import write_report
from .evaluate_rollouts import rollout
from ..mirror.features import HISTORY, follower_input, foot_contacts
from ..data.folders import add_folder
from .motion_matching import build, load_tracks, training_takes
from ..mirror.rollout import NOW, Dancer, OnnxPolicy, apply_output
from .duet import soak_one
from .soak import steering_trials

KEYS = ["interpenetration", "hand_hold", "closest_hand_m", "skate_leader_cm", "skate_follower_cm",
        "contact_skate_leader_cm", "contact_skate_follower_cm", "contact_share_leader", "contact_share_follower",
        "implausible_leader", "implausible_follower", "angles_out_leader", "angles_out_follower"]


def contact_labels(positions: np.ndarray) -> np.ndarray:
    """The recording's per-frame contact labels [T, 2] (features.foot_contacts; the first frame
    copies the second)."""
    c = foot_contacts(positions[1:], positions[:-1]).astype(float)
    return np.concatenate([c[:1], c])


def measure(leader, follower, leader_contacts, follower_contacts, ranges: dict | None = None) -> dict:
    """metrics.interaction, the share of frames with a foot in contact and, given the training
    takes' plausibility range, per dancer the share of frames with the body low, folded or split
    (`implausible`) or a joint angle outside that range (evaluation.plausibility)."""
    out = M.interaction(leader, follower, leader_contacts, follower_contacts)
    out["contact_share_leader"] = float((np.asarray(leader_contacts) > 0.5).any(-1).mean())
    out["contact_share_follower"] = float((np.asarray(follower_contacts) > 0.5).any(-1).mean())
    if ranges is None:
        return out
    for who, pos in (("leader", leader), ("follower", follower)):
        flags = P.frame_flags(pos, ranges)
        out[f"implausible_{who}"] = float(P.body_flagged(flags).mean())
        out[f"angles_out_{who}"] = float(flags["angles_out"].mean())
    return out


def with_layer(leader, follower, leader_contacts, follower_contacts, leader_heading, follower_heading):
    """The contact layer over a recorded sequence: shown positions of both (the layer never feeds
    back into the networks, so running it afterwards gives exactly what the loop would show)."""
    layer = ContactLayer()
    shown_l, shown_f = np.array(leader, float), np.array(follower, float)
    for t in range(len(shown_l)):
        layer.apply(shown_l[t], shown_f[t], leader_contacts[t], follower_contacts[t],
                    float(leader_heading[t]), float(follower_heading[t]))
    return shown_l, shown_f


def weighted(items: list[tuple[dict, int]]) -> dict:
    total = sum(n for _, n in items)
    return {k: float(sum(r[k] * n for r, n in items) / total) for k in items[0][0]}


def recording_row(takes: list[EvalTake], ranges: dict) -> dict:
    items = []
    for t in takes:
        sl = slice(int(t.frames[0]), int(t.frames[-1]) + 2)
        lp, fp = t.lead.positions[sl], t.follow.positions[sl]
        items.append((measure(lp, fp, contact_labels(t.lead.positions)[sl], contact_labels(t.follow.positions)[sl], ranges),
                      len(lp)))
    return weighted(items)


def teacher_forced_row(takes: list[EvalTake], policy, ranges: dict) -> dict:
    """One step from the recorded state at every frame: the follower's next pose (forward
    kinematics from its decoded rotations, as the loop places it) against the recorded leader."""
    items = []
    for t in takes:
        x = follower_input(t.lead, t.follow, t.frames, t.figure(t.frames))
        if hasattr(policy, "reset"):
            policy.reset()
            out = np.asarray(policy(x)["output"], np.float64)
        else:
            out = np.concatenate([policy(x[s:s + 512], 0.0, np.random.default_rng(0))["output"]
                                  for s in range(0, len(x), 512)]).astype(np.float64)
        fol = np.empty((len(t.frames), feat.N_JOINTS, 3))
        for i, f in enumerate(t.frames):
            d = Dancer(np.asarray(t.follow_offsets, float), window(t.follow, int(f)))
            apply_output(d, out[i])
            fol[i] = d.positions
        contacts = np.clip(out[:, -2:], 0, 1)
        lead = t.lead.positions[t.frames + 1]
        items.append((measure(lead, fol, contact_labels(t.lead.positions)[t.frames + 1], contacts, ranges), len(fol)))
    return weighted(items)


def free_running_rows(takes: list[EvalTake], policy, start_pose: dict, temperature: float,
                      ranges: dict) -> tuple[dict, dict]:
    alone, layered = [], []
    for t in takes:
        r = rollout(t, policy, temperature, 0, start_pose)
        idx = np.arange(HISTORY + 1, HISTORY + r["steps"] + 1)
        sl = slice(r["t0"] - HISTORY, r["t0"] + r["steps"] + 1)
        lc = contact_labels(t.lead.positions)[sl][idx]
        fc = r["contacts"][idx]
        lp, fp = r["leader_positions"][idx], r["positions"][idx]
        alone.append((measure(lp, fp, lc, fc, ranges), len(idx)))
        sl_, sf_ = with_layer(lp, fp, lc, fc, t.lead.heading[sl][idx], r["heading"][idx])
        layered.append((measure(sl_, sf_, lc, fc, ranges), len(idx)))
    return weighted(alone), weighted(layered)


def steered_rows(manifest, leader, follower, seeds: int, frames: int, temperature: float, bar,
                 ranges: dict) -> tuple[dict, dict]:
    alone, layered = [], []
    for seed in range(seeds):
        rec = {}
        soak_one(manifest, leader, follower, seed, frames, temperature, rec)
        alone.append((measure(rec["leader"], rec["follower"], rec["leader_contacts"], rec["follower_contacts"], ranges),
                      frames))
        layered.append((measure(rec["leader_shown"], rec["follower_shown"], rec["leader_contacts"],
                                rec["follower_contacts"], ranges), frames))
        bar.update(1)
    return weighted(alone), weighted(layered)


def run(args) -> dict:
    t_start = time.time()
    manifest, onnx, leader_onnx = find_models(args.models)
    if leader_onnx is None:
        raise EvalError(f"{args.models}: no leader.onnx (the steered duet needs it)")
    takes = load_eval_takes(args.data, [t for t in args.takes.split(",") if t], None, None)
    names = [t.name for t in takes]
    methods = {m: load_onnx(p) for m, p in onnx.items() if not args.methods or m in args.methods.split(",")}
    if not args.methods or "motion_matching" in args.methods.split(","):
        train = training_takes(args.data, exclude=names)
        methods["motion_matching"] = build(load_tracks(train), "follower")
    if "plausibility" not in manifest:
        raise EvalError(f"{args.models}/manifest.json has no plausibility range: re-export it "
                        f"(python -m training.learning.export, after training.data.prepare)")
    ranges = manifest["plausibility"]
    error = O.resolve(args, manifest)
    if error:
        raise EvalError(f"{args.models}/manifest.json: {error}")
    leader = O.leader_policy(load_onnx(leader_onnx), manifest, args)
    temperature = args.temperature   # the leader's; each follower runs at its own (options.py)
    frames = int(args.seconds * feat.FPS)
    res = {"takes": names, "recording": recording_row(takes, ranges), "methods": {}}
    bar = tqdm(total=len(methods) * args.seeds, desc="steered duets", unit="duet", file=sys.stderr,
               disable=args.quiet)
    for m, policy in methods.items():
        row = {"teacher_forced": teacher_forced_row(takes, policy, ranges)}
        if m != "motion_matching":   # no sampling, nothing to guard
            policy = O.follower_policy(policy, manifest, args, temperature)
        row["free_running"], row["free_running_layer"] = free_running_rows(takes, policy, manifest["startPose"], temperature, ranges)
        row["steered"], row["steered_layer"] = steered_rows(manifest, leader, policy, args.seeds, frames, temperature, bar, ranges)
        row["steering"] = steering_trials(manifest, leader, policy, temperature)
        res["methods"][m] = row
    bar.close()
    res["config"] = {"models": str(args.models), "data": str(args.data), "seeds": args.seeds,
                     "seconds": args.seconds, "temperature": temperature,
                     "follower_temperature": args.follower_temperature, "guard": args.guard,
                     "wall_seconds": time.time() - t_start}
    return res


def write_markdown(path: Path, res: dict) -> None:
    ref = res["recording"]
    heads = ["interpenetration", "hand hold", "closest hand m", "skate L cm", "skate F cm",
             "contact skate L cm", "contact skate F cm", "contact share L", "contact share F",
             "implausible L", "implausible F", "angles out L", "angles out F"]
    L = [f"# Interaction: takes {', '.join(res['takes'])}", "",
         f"Steered: {res['config']['seeds']} x {res['config']['seconds']:g} s of training.evaluation.soak steering; "
         f"temperature {res['config']['temperature']}; models `{res['config']['models']}`. "
         "Each cell: value (ratio to the recording).", "",
         "| method | protocol | " + " | ".join(heads) + " |", "|---|---|" + "---|" * len(heads),
         "| recording | | " + " | ".join(f"{ref[k]:.3f}" for k in KEYS) + " |"]
    for m, row in res["methods"].items():
        for proto in ("teacher_forced", "free_running", "free_running_layer", "steered", "steered_layer"):
            r = row[proto]
            ratio = M.ratio_to(ref, r)
            cells = [f"{r[k]:.3f}" + (f" ({ratio[k]:.2f}×)" if ratio.get(k) is not None else "") for k in KEYS]
            L.append(f"| {m} | {proto.replace('_', ' ')} | " + " | ".join(cells) + " |")
    L += ["", "Steering response of our leader (90-degree stick turns):", "",
          "| follower | seconds to within 30° | missed | speed m/s |", "|---|---|---|---|"]
    for m, row in res["methods"].items():
        s = row["steering"]
        seconds = "n/a" if s["turn_seconds"] is None else f"{s['turn_seconds']:.2f}"
        L.append(f"| {m} | {seconds} | {s['turn_missed']} of {s['trials']} | {s['speed']:.2f} |")
    path.write_text("\n".join(L) + "\n")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.interaction", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "the takes whose recording is the reference (and Motion Matching's database)")
    ap.add_argument("--takes", default="02,13", help="comma-separated takes (the recording's reference)")
    add_folder(ap, "models", "the follower and leader models measured")
    ap.add_argument("--methods", default=None, help="comma-separated subset (ours, ccm, motion_matching, ...)")
    ap.add_argument("--seeds", type=int, default=4, help="steered duets per method")
    ap.add_argument("--seconds", type=float, default=60.0, help="length of each steered duet")
    O.add_options(ap)
    ap.add_argument("--out", default="runs/interaction", help="where interaction.json and .md go")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    try:
        res = run(args)
    except (EvalError, DataError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    write_report(Path(args.out), "interaction", res, write_markdown)
    return 0


if __name__ == "__main__":
    sys.exit(main())
