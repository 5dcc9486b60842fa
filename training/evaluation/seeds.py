"""python -m training.evaluation.seeds: many steered duets, each judged on its own -> seeds.json + .md

    python -m training.evaluation.seeds --models public/models --seeds 100 --seconds 60 --out runs/seeds

Every seed is one steered duet (training.evaluation.soak's steering script and loop, our leader
model) with each follower method: every follower ONNX in --models and Motion Matching over the
training takes. Each duet is measured twice, the networks alone and with the contact layer, by
plausibility (per-frame flags against the recording's range, worst second, collapse) and by
metrics.interaction (torsos through each other, hands within 20 cm, foot skate). The recording of
the test takes (--takes) is measured the same way and every share is also given as a ratio to it.

Seeds run in --workers processes (one ONNX thread each); the table is the same for any count.
"""
from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..data.dataset import DataError, TEST_TAKES
from ..data.folders import add_folder
from ..mirror.skeleton import FPS
from . import figures as Fg
from . import options as O
from . import plausibility as P
from .evaluate_inputs import EvalError, find_models, load_eval_takes, load_onnx
from .interaction import contact_labels, measure, weighted as interaction_weighted
from .motion_matching import build, load_tracks, training_takes
from . import rhythm as R
from .duet import soak_one

INTERACTION = ["interpenetration", "hand_hold", "skate_leader_cm", "skate_follower_cm",
               "contact_skate_leader_cm", "contact_skate_follower_cm"]


def recording_row(data: str, names: list[str], r: dict) -> dict:
    takes = load_eval_takes(data, names, None, None)
    duets, inter, frames = [], [], []
    for t in takes:
        lead, follow = t.lead.positions, t.follow.positions
        duets.append(P.duet(lead, follow, r))
        inter.append(measure(lead, follow, contact_labels(lead), contact_labels(follow)))
        frames.append(len(lead))
    figs = {who: Fg.summarize([dancer_figures(getattr(t, part).positions) for t in takes])
            for who, part in (("leader", "lead"), ("follower", "follow"))}
    return {**P.summarize(duets, frames), **weighted(inter, frames), "figures": figs}


def dancer_figures(positions: np.ndarray) -> dict:
    """figures.dancer without its per-turn lists (the JSON keeps one number a measure)."""
    return {k: v for k, v in Fg.dancer(positions).items() if not isinstance(v, list)}


def figures_row(per_seed: list[dict]) -> dict:
    """Each dancer's figures pooled over the seeds, with the seed that turns least (a mean alone
    would hide a seed whose follower never turns)."""
    out = {}
    for who in ("leader", "follower"):
        items = [s["figures"][who] for s in per_seed]
        worst = min(range(len(items)), key=lambda i: items[i]["turns_per_min"])
        out[who] = {**Fg.summarize(items), "worst_seed": per_seed[worst]["seed"],
                    "worst_turns_per_min": items[worst]["turns_per_min"],
                    "seeds_without_turns": int(sum(i["turns"] == 0 for i in items))}
    return out


def weighted(rows: list[dict], frames: list[int]) -> dict:
    """The INTERACTION measures of many duets, weighted by their frames."""
    means = interaction_weighted([({k: r[k] for k in INTERACTION}, n) for r, n in zip(rows, frames)])
    return {k: means[k] for k in INTERACTION}


# ---------------------------------------------------------------- workers

_WORKER: dict = {}


def _init(models: str, method: str, data: str, test: list[str], r: dict, options: dict):
    manifest, onnx, leader = find_models(models)
    if options.get("leading_temperature") is not None:   # as resolve wrote it in the parent's manifest
        manifest["leadingTemperature"] = options["leading_temperature"]
    if method == "motion_matching":   # no sampling, nothing to guard
        follower = build(load_tracks(training_takes(data, exclude=test)), "follower")
    else:
        follower = O.follower_policy(load_onnx(onnx[method]), manifest, argparse.Namespace(**options),
                                     options["temperature"])
    leader = O.leader_policy(load_onnx(leader), manifest, argparse.Namespace(**options))
    _WORKER.update(manifest=manifest, leader=leader, follower=follower, ranges=r)


def _one(job: tuple[int, int, float, float]) -> dict:
    seed, frames, temperature, tempo = job
    w = _WORKER
    rec: dict = {}
    O.restart_count(w["follower"], w["leader"])
    soak = soak_one(w["manifest"], w["leader"], w["follower"], seed, frames, temperature, rec, tempo=tempo)
    out = {"seed": seed, "resets": soak["resets"], "guarded": getattr(w["follower"], "guarded", 0),
           "leader_guarded": getattr(w["leader"], "guarded", 0),
           "figures": {"leader": dancer_figures(rec["leader"]), "follower": dancer_figures(rec["follower"])},
           # on the count, as drawn and the networks' own (evaluation.rhythm)
           "rhythm": R.bodies_rhythm(rec, tempo, seed)}
    for kind, suffix in (("alone", ""), ("layer", "_shown")):
        lead, follow = rec["leader" + suffix], rec["follower" + suffix]
        out[kind] = {**P.duet(lead, follow, w["ranges"]),
                     **measure(lead, follow, rec["leader_contacts"], rec["follower_contacts"])}
    return out


def run_method(args, method: str, r: dict, test: list[str], bar, r_rhythm: dict) -> dict:
    frames = int(args.seconds * FPS)
    jobs = [(seed, frames, args.temperature, args.tempo) for seed in range(args.first_seed, args.first_seed + args.seeds)]
    options = {k: getattr(args, k) for k in O.option_names()}   # every option, as resolved here
    init = (args.models, method, args.data, test, r, options)

    def counted(results):
        for res in results:
            bar.update(1)
            yield res

    if args.workers > 1:
        with multiprocessing.get_context("spawn").Pool(args.workers, _init, init) as pool:
            per_seed = list(counted(pool.imap(_one, jobs)))
    else:
        _init(*init)
        per_seed = list(counted(map(_one, jobs)))
    row = {"per_seed": per_seed, "resets": int(sum(s["resets"] for s in per_seed)),
           "guarded": int(sum(s["guarded"] for s in per_seed)),
           "seeds_guarded": int(sum(s["guarded"] > 0 for s in per_seed)), "figures": figures_row(per_seed),
           "rhythm": {body: R.summarize([s["rhythm"][body] for s in per_seed], r_rhythm) for body in R.BODIES}}
    for kind in ("alone", "layer"):
        duets = [s[kind] for s in per_seed]
        row[kind] = {**P.summarize(duets, [frames] * len(duets)), **weighted(duets, [frames] * len(duets))}
    return row


def ratios(row: dict, ref: dict) -> dict:
    """Every share and speed of `row` divided by the recording's (None where the recording's is 0)."""
    out = {}
    for who in ("leader", "follower"):
        out[who] = {k: (row[who][k] / ref[who][k] if ref[who][k] else None)
                    for k in P.FLAGS + ["root_speed_p99"]}
    out["path_ratio"] = row["path_ratio"] / ref["path_ratio"]
    out.update({k: (row[k] / ref[k] if ref[k] else None) for k in INTERACTION})
    return out


def run(args) -> dict:
    t0 = time.time()
    manifest, onnx, leader = find_models(args.models)
    if leader is None:
        raise EvalError(f"{args.models}: no leader.onnx (the steered duet needs it)")
    test = [t for t in args.takes.split(",") if t]
    if "plausibility" not in manifest:
        raise EvalError(f"{args.models}/manifest.json has no plausibility range: re-export it "
                        f"(python -m training.learning.export, after training.data.prepare)")
    r = manifest["plausibility"]   # the training dancers' range, as prepare measured it
    error = O.resolve(args, manifest)
    if error:
        raise EvalError(f"{args.models}/manifest.json: {error}")
    known = [*onnx, "motion_matching"]
    wanted = [m for m in (args.methods or "").split(",") if m]
    unknown = [m for m in wanted if m not in known]
    if unknown:
        raise EvalError(f"--methods {','.join(unknown)}: not in {args.models} (known: {', '.join(known)})")
    methods = [m for m in known if not wanted or m in wanted]
    ref = recording_row(args.data, test, r)
    r_rhythm = R.recorded(args.data)   # every take at its found count: the rhythm's reference
    res = {"takes": test, "ranges": r, "recording": ref, "methods": {}, "rhythm_recording": r_rhythm,
           "tempo": args.tempo}
    bar = tqdm(total=len(methods) * args.seeds, desc="steered duets", unit="duet", file=sys.stderr,
               disable=args.quiet)
    for m in methods:
        row = run_method(args, m, r, test, bar, r_rhythm)
        row["ratio"] = {k: ratios(row[k], ref) for k in ("alone", "layer")}
        res["methods"][m] = row
    bar.close()
    res["config"] = {"models": str(args.models), "seeds": args.seeds, "first_seed": args.first_seed,
                     "seconds": args.seconds, "temperature": args.temperature,
                     "follower_temperature": args.follower_temperature, "guard": args.guard,
                     "guard_margin": args.guard_margin, "guard_hip_margin": args.guard_hip_margin,
                     "on_count": args.on_count, "on_count_strength": args.on_count_strength,
                     "on_count_hips": args.on_count_hips,
                     "wall_seconds": time.time() - t0}
    return res


def fmt(v, digits=2, pct=False) -> str:
    if v is None:
        return "–"
    return f"{100 * v:.{digits - 1}f} %" if pct else f"{v:.{digits}f}"


def write_markdown(path: Path, res: dict) -> None:
    ref, cfg = res["recording"], res["config"]
    lines = [f"# Plausibility over {cfg['seeds']} steered seeds × {cfg['seconds']:g} s "
             f"(variety: leader {cfg['temperature']:g}, network followers {cfg.get('follower_temperature') or cfg['temperature']:g}), against the recording of takes {', '.join(res['takes'])}", "",
             "Share of frames flagged (ratio to the recording in brackets); worst = the worst seed's share.", ""]
    for who in ("leader", "follower"):
        lines += [f"## {who}", "",
                  "| method | " + " | ".join(P.FLAGS) + " | root speed p99 (m/s) | worst second | seeds with a bad second | collapses |",
                  "|---" * (len(P.FLAGS) + 5) + "|"]
        r0 = ref[who]
        lines.append("| recording | " + " | ".join(fmt(r0[k], pct=True) for k in P.FLAGS) +
                     f" | {r0['root_speed_p99']:.2f} | {fmt(r0['worst_second'], pct=True)} | {r0['bad_seconds']} | {r0['collapses']} |")
        for m, row in res["methods"].items():
            for kind in ("alone", "layer"):
                s, q = row[kind][who], row["ratio"][kind][who]
                cells = [f"{fmt(s[k], pct=True)} ({fmt(q[k], 1)}×) worst {fmt(s[k + '_worst_seed'], pct=True)}"
                         for k in P.FLAGS]
                lines.append(f"| {m} {kind} | " + " | ".join(cells) +
                             f" | {s['root_speed_p99']:.2f} ({fmt(q['root_speed_p99'])}×) | {fmt(s['worst_second'], pct=True)}"
                             f" | {s['bad_seconds']} / {row[kind]['seeds']} | {s['collapses']} |")
        lines.append("")
    lines += ["## The couple", "",
              "| method | path ratio follower/leader | " + " | ".join(INTERACTION) + " | guard resets |",
              "|---" * (len(INTERACTION) + 3) + "|",
              f"| recording | {ref['path_ratio']:.2f} | " + " | ".join(fmt(ref[k], 3) for k in INTERACTION) + " | – |"]
    for m, row in res["methods"].items():
        for kind in ("alone", "layer"):
            s, q = row[kind], row["ratio"][kind]
            lines.append(f"| {m} {kind} | {s['path_ratio']:.2f} ({fmt(q['path_ratio'])}×) | " +
                         " | ".join(f"{fmt(s[k], 3)} ({fmt(q[k])}×)" for k in INTERACTION) + f" | {row['resets']} |")
    lines += ["", "## Salsa figures (training.evaluation.figures)", "",
              "Turns per minute (300 degrees within 2.5 s), spin frames, body motion (joint speed relative "
              "to the hips) and travel of each dancer, pooled over the seeds, as a ratio to the recorded "
              "dancer's; the seed that turns least, and how many seeds have no turn at all.", "",
              "| method | dancer | turns/min | spin frames | body motion m/s | travel m/s | least-turning seed | seeds without a turn |",
              "|---|---|---|---|---|---|---|---|"]
    for who in ("leader", "follower"):
        f0 = ref["figures"][who]
        lines.append(f"| recording | {who} | {f0['turns_per_min']:.1f} | {fmt(f0['spin_frames'], pct=True)} | "
                     f"{f0['body_motion']:.2f} | {f0['travel']:.2f} | – | – |")
        for m, row in res["methods"].items():
            f = row["figures"][who]
            q = Fg.ratios(f, f0)
            lines.append(f"| {m} | {who} | {f['turns_per_min']:.1f} ({q['turns_per_min']:.2f}×) | "
                         f"{fmt(f['spin_frames'], pct=True)} ({q['spin_frames']:.2f}×) | {f['body_motion']:.2f} "
                         f"({q['body_motion']:.2f}×) | {f['travel']:.2f} ({q['travel']:.2f}×) | "
                         f"seed {f['worst_seed']}: {f['worst_turns_per_min']:.1f}/min | {f['seeds_without_turns']} |")
    if cfg.get("guard"):
        lines += ["", f"The network followers' upright guard (training/mirror/guard.py): "
                      f"{cfg.get('guard')} samples" +
                      (f", acting {cfg['guard_margin']:g} m before the range's edge." if cfg.get("guard_margin") else ".")]
        for m, row in res["methods"].items():
            if m != "motion_matching":
                lines.append(f"- {m}: the guard chose another sample in {row['guarded']} steps "
                             f"({100 * row['guarded'] / (cfg['seeds'] * cfg['seconds'] * FPS):.2f} % of frames), "
                             f"in {row['seeds_guarded']} of {cfg['seeds']} seeds.")
    lines += ["", f"Wall time {cfg['wall_seconds'] / 60:.1f} min."]
    path.write_text("\n".join(lines) + "\n")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.seeds", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "read")
    add_folder(ap, "models", "read: the leader and every follower dance")
    ap.add_argument("--takes", default=",".join(TEST_TAKES), help="recorded takes to compare with")
    ap.add_argument("--seeds", type=int, default=100)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--methods", default=None, help="comma-separated subset (ours, ccm, motion_matching; default all)")
    ap.add_argument("--workers", type=int, default=2)
    O.add_options(ap)   # the network followers only; Motion Matching dances as it is
    ap.add_argument("--out", default="runs/seeds")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    if args.seeds < 1 or args.seconds < 2:
        ap.error("--seeds must be at least 1 and --seconds at least 2")
    try:
        res = run(args)
    except (EvalError, DataError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "seeds.json").write_text(json.dumps(res, indent=1))
    write_markdown(out / "seeds.md", res)
    for m, row in res["methods"].items():
        for body, what in R.BODIES.items():
            print(R.format_summary(f"rhythm of {m}, steered, at {res['tempo']:g} beats a minute, {what}",
                                   row["rhythm"][body], res["rhythm_recording"]))
    print(f"wrote {out}/seeds.json and seeds.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
