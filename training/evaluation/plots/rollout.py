"""rollout_topview.png: top view of free-running rollouts on a test take, leader played back from
the recording (evaluate's rollout), ours vs CCM vs the recording, and with the leader's plan bent."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...mirror import features as feat
from .common import COLORS, LABELS, Skip, pyplot, read_eval, save_figure


def figure_rollout(args, out: Path) -> list[str]:
    from ...data.dataset import DataError
    from ..evaluate_inputs import EvalError, find_models, load_eval_takes, load_onnx
    from ..evaluate_rollouts import parse_condition, rollout
    try:
        manifest, onnx, _ = find_models(args.models)
        take = load_eval_takes(args.data, [args.take], args.frames, None)[0]
    except (EvalError, DataError) as e:
        raise Skip(str(e)) from None
    methods = [(n, k) for n, k in (("ours", "follower"), ("ccm", "follower_ccm")) if n in onnx]
    if not methods:
        raise Skip(f"{args.models}: neither follower.onnx nor follower_ccm.onnx")
    t0, steps = int(take.frames[0]), len(take.frames)
    span = slice(t0, t0 + steps + 1)
    rec_follow, rec_lead = take.follow.root[span], take.lead.root[span]
    conditions = [("playback", None, "leader played back from the recording")]
    if args.rollout_bend:
        bend = parse_condition(f"playback:{args.rollout_bend}")[1]
        conditions.append(("bend", bend, f"leader's future keys turned {bend[1]:+g}° (what the follower sees)"))
    results = {}
    for cond, bend, _ in conditions:
        for name, key in methods:
            policy = load_onnx(onnx[name])
            r = rollout(take, policy, args.temperature, args.seed, manifest["startPose"], "playback", bend)
            results[cond, key] = r
    plt = pyplot()
    fig, axes = plt.subplots(1, len(conditions), figsize=(6.2 * len(conditions), 6.0), squeeze=False)
    every = feat.FPS
    lines = [f"rollout on take {take.name}: frames {t0}-{t0 + steps} ({steps} steps, {steps / feat.FPS:.1f} s), "
             f"temperature {args.temperature:g}, seed {args.seed}; root (x, z) in metres"]
    d_rec = np.linalg.norm(rec_follow - rec_lead, axis=1)
    lines.append(f"  recording: follower-leader distance mean {d_rec.mean():.2f} m; follower path length "
                 f"{np.linalg.norm(np.diff(rec_follow, axis=0), axis=1).sum():.1f} m")

    def path(ax, p, color, label, ls="-", lw=1.6):
        ax.plot(p[:, 0], p[:, 1], ls, color=color, linewidth=lw, label=label)
        ax.plot(p[::every, 0], p[::every, 1], "o", color=color, markersize=3.5)
        ax.plot(p[0, 0], p[0, 1], "s", color=color, markersize=8, markeredgecolor="white")
        ax.plot(p[-1, 0], p[-1, 1], "X", color=color, markersize=9, markeredgecolor="white")

    for ax, (cond, bend, title) in zip(axes[0], conditions):
        path(ax, rec_lead, COLORS["recorded_leader"], "leader (recorded, played back)", "--", 1.4)
        path(ax, rec_follow, COLORS["recording"], "follower (recorded)", "-", 1.4)
        for name, key in methods:
            r = results[cond, key]
            root = r["root"][feat.HISTORY:]            # from the start frame t0 on
            path(ax, root, COLORS[key], f"follower: {LABELS[key]}")
            err = np.linalg.norm(root - rec_follow[:len(root)], axis=1)
            dist = np.linalg.norm(root - r["leader_root"][feat.HISTORY:], axis=1)
            lines.append(f"  {cond:<8} {name:<4}: root distance to the recorded follower mean {err.mean():.2f} m, "
                         f"final {err[-1]:.2f} m; distance to leader mean {dist.mean():.2f} m (max {dist.max():.2f}); "
                         f"path length {np.linalg.norm(np.diff(root, axis=0), axis=1).sum():.1f} m; "
                         f"resets {r['resets']}")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)"); ax.set_ylabel("z (m)")
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8, framealpha=0.85)
    evaluated = read_eval(args)
    cond = f"playback:{args.rollout_bend}"
    if evaluated:
        ctl, roll = evaluated["protocols"].get("controlled", {}), evaluated["protocols"].get("rollout", {})
        t_key = f"{evaluated['config']['headline_temperature']:g}"
        for name, _ in methods + [("motion_matching", None)]:
            parts = []
            r = roll.get(name, {}).get("by_temperature", {})
            r = r.get(t_key) or r.get("any")
            if r:
                parts.append(f"playback MPJPE {r['mpjpe_cm']:.1f} cm, root error {r['root_error_m']:.2f} m")
            c = ctl.get(cond, {}).get(name)
            if c:
                parts.append(f"{cond}: distance to leader {c['distance_to_leader']:.2f} m, divergence "
                             f"{c['divergence']:.3f}, FID {c['fid']:.1f}")
            if parts:
                lines.append(f"  {args.eval} ({', '.join(evaluated['takes'])}, T {t_key}, mean over seeds) "
                             f"{name}: " + "; ".join(parts))
    # One seed is one sample of a stochastic policy: the spread over a few seeds, for the text only.
    seeds = [args.seed + k for k in range(max(1, args.summary_seeds))]
    if len(seeds) > 1:
        lines.append(f"  spread over seeds {seeds[0]}-{seeds[-1]} (playback; drawn: seed {args.seed}):")
        for name, key in methods:
            policy = load_onnx(onnx[name])
            stats = []
            for sd in seeds:
                r = (results["playback", key] if sd == args.seed else
                     rollout(take, policy, args.temperature, sd, manifest["startPose"]))
                root = r["root"][feat.HISTORY:]
                stats.append((np.linalg.norm(np.diff(root, axis=0), axis=1).sum(),
                              np.linalg.norm(root - rec_follow[:len(root)], axis=1).mean(),
                              np.linalg.norm(root - r["leader_root"][feat.HISTORY:], axis=1).mean()))
            st = np.array(stats)
            lines.append(f"    {name:<4}: path length " + ", ".join(f"{v:.1f}" for v in st[:, 0]) +
                         " m; root distance to the recorded follower " + ", ".join(f"{v:.2f}" for v in st[:, 1]) +
                         " m; distance to leader " + ", ".join(f"{v:.2f}" for v in st[:, 2]) + " m")
    fig.suptitle(f"Top view, test take {take.name}, {steps / feat.FPS:.0f} s free-running (dots every second, "
                 f"square = start, X = end; T = {args.temperature:g})")
    fig.tight_layout()
    save_figure(fig, out, "rollout")
    plt.close(fig)
    return lines
