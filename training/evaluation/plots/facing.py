"""facing_angle.png: the follower's facing angle over time beside the same played-back recorded
leader (evaluate's rollout): the recorded follower, ours, CCM and Motion Matching, each turn
marked where its 300 degrees are reached (figures.turns). What no other figure shows: whether the
follower turns when the recorded follower did."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...mirror import features as feat
from .. import figures as Fg
from .common import COLORS, LABELS, Skip, pyplot, save_figure


def figure_facing(args, out: Path) -> list[str]:
    from ...data.dataset import DataError
    from ..evaluate_inputs import EvalError, find_models, load_eval_takes, load_onnx
    from ..evaluate_rollouts import recorded, rollout
    from ..motion_matching import build, load_tracks, training_takes
    try:
        manifest, onnx, _ = find_models(args.models)
        take = load_eval_takes(args.data, [args.take], args.frames, None)[0]
    except (EvalError, DataError) as e:
        raise Skip(str(e)) from None
    methods = [(n, k) for n, k in (("ours", "follower"), ("ccm", "follower_ccm")) if n in onnx]
    if not methods:
        raise Skip(f"{args.models}: neither follower.onnx nor follower_ccm.onnx")
    runs = {k: rollout(take, load_onnx(onnx[n]), args.temperature, args.seed, manifest["startPose"])
            for n, k in methods}
    if args.motion_matching:
        mm = build(load_tracks(training_takes(args.data, exclude=[take.name])), "follower")
        runs["motion_matching"] = rollout(take, mm, args.temperature, args.seed, manifest["startPose"])
    ref = recorded(take)
    span = slice(feat.HISTORY + 1, feat.HISTORY + ref["steps"] + 1)
    seconds = np.arange(ref["steps"]) / feat.FPS
    rec = Fg.facing(ref["positions"][span])
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(11, 4.6))
    lines = [f"facing angle on take {take.name}, {ref['steps'] / feat.FPS:.1f} s, temperature {args.temperature:g}, "
             f"seed {args.seed}; turns = 300 degrees within 2.5 s"]
    rec_turns = Fg.turns(rec)

    def draw(angle, color, label, turns, lw):
        a = np.degrees(angle - angle[0])
        ax.plot(seconds, a, color=color, linewidth=lw, label=f"{label}: {len(turns)} turns")
        for f, _ in turns:
            ax.plot(seconds[f], a[f], "o", color=color, markersize=5)

    draw(rec, COLORS["recording"], "follower (recorded)", rec_turns, 2.2)
    lines.append(f"  recorded follower: {len(rec_turns)} turns at " + ", ".join(f"{f / feat.FPS:.1f}" for f, _ in rec_turns) + " s")
    for key, r in runs.items():
        angle = Fg.facing(r["positions"][span])
        t = Fg.turns(angle)
        draw(angle, COLORS[key], LABELS.get(key, key), t, 1.4)
        n = Fg.match(t, rec_turns)
        lines.append(f"  {LABELS.get(key, key)}: {len(t)} turns at " + ", ".join(f"{f / feat.FPS:.1f}" for f, _ in t) +
                     f" s; {n} match a recorded one (same direction, within {Fg.MATCH_SECONDS:g} s)")
    ax.set_xlabel("seconds")
    ax.set_ylabel("facing, degrees from the start (unwrapped)")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8, framealpha=0.85)
    ax.set_title(f"The follower's facing beside the recorded leader (take {take.name}, played back); "
                 f"dots: a turn's 300 degrees reached", fontsize=10)
    fig.tight_layout()
    save_figure(fig, out, "facing")
    plt.close(fig)
    return lines
