"""codebook_error_density.png: per-frame codebook matching error on the test frames (paper:
CodebookErrorDensity), as recorded and with the leader's future path in the follower input turned
by ±30° / ±60° about the follower's root."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...mirror import features as feat
from .common import (COLORS, LABELS, Skip, codes_of, encode, load_model, load_test, per_frame_codebook_error,
                     pyplot, read_eval, save_figure)

CONTROL_ANGLES = [30.0, -30.0, 60.0, -60.0]
FOLLOWER_IN = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)


def rotate_partner_future(x: np.ndarray, degrees: float) -> np.ndarray:
    """Follower inputs [N, 660] (raw) with the leader's future trajectory keys turned by `degrees`
    about the follower's root: key positions (x, z) and forward directions (x, z) alike.

    The block is in the follower's root space, so the root is the origin. The sense matches
    evaluate_rollouts.bend_plan and train.augment_control: a heading h (facing (sin h, cos h)) becomes h + a.
    """
    x = np.array(x, dtype=np.float64, copy=True)
    if degrees == 0:
        return x
    sl = FOLLOWER_IN["partner_trajectory_future"]
    keys = x[:, sl].reshape(len(x), feat.KEYS, 4)
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    for i in (0, 2):
        px, pz = keys[..., i].copy(), keys[..., i + 1].copy()
        keys[..., i], keys[..., i + 1] = c * px + s * pz, -s * px + c * pz
    x[:, sl] = keys.reshape(len(x), -1)
    return x

def motion_matching_policy(args):
    from ...data.dataset import DataError
    from ..motion_matching import build, load_tracks, training_takes
    try:
        return build(load_tracks(training_takes(args.data)), "follower")
    except DataError as e:
        raise Skip(f"Motion Matching: {e}") from None

def codebook_errors_under_control(args) -> tuple[dict, dict, list[str]]:
    """{method: {angle: per-frame errors}}, {method: classes*channels}, notes."""
    test = load_test(args.prepared)
    x, y = test["input"].astype(np.float64), test["output"]
    angles = [0.0] + CONTROL_ANGLES
    inputs = {a: rotate_partner_future(x, a) for a in angles}
    errors, latent, notes = {}, {}, []
    names = ["follower", "follower_no_gan", "follower_ccm", "follower_ccm_large"]
    models = {}
    for name in names:
        try:
            models[name] = load_model(Path(args.runs), name, args.prepared)
        except Skip as e:
            if name == "follower":
                raise
            notes.append(f"{name} left out: {e}")
    targets = {}
    for name, m in models.items():
        c, d = m.cfg.channels, m.cfg.classes
        errors[name], latent[name] = {}, c * d
        for a in angles:
            est, tgt = encode(m, inputs[a], y)
            t = codes_of(tgt, c)
            if name == "follower":
                targets[a] = t
            errors[name][a] = per_frame_codebook_error(t, codes_of(est, c), d)
    if args.motion_matching:
        try:
            mm = motion_matching_policy(args)
        except Skip as e:
            notes.append(str(e))
        else:
            ours = models["follower"]
            errors["motion_matching"], latent["motion_matching"] = {}, latent["follower"]
            for a in angles:
                mm.reset()      # batched query: own future extrapolated, as evaluate's teacher-forced run
                picked = np.asarray(mm(inputs[a])["output"], np.float32)
                _, code_mm = encode(ours, inputs[a], picked)
                errors["motion_matching"][a] = per_frame_codebook_error(
                    targets[a], codes_of(code_mm, ours.cfg.channels), ours.cfg.classes)
    else:
        notes.append("Motion Matching left out (--no-motion-matching)")
    return errors, latent, notes

def figure_codebook(args, out: Path) -> list[str]:
    errors, latent, notes = codebook_errors_under_control(args)
    n_frames = len(next(iter(errors.values()))[0.0])
    plt = pyplot()
    methods = list(errors)
    cols = 3
    rows = (len(methods) + 1 + cols - 1) // cols
    fig, grid = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.9 * rows), squeeze=False)
    axes = list(grid.flat)
    for ax in axes[len(methods) + 1:]:
        ax.axis("off")
    quantum = 2.0 / min(latent.values())                       # one wrong channel of the smallest code
    top = max(max(np.max(v) for v in e.values()) for e in errors.values())
    edges = (np.arange(-0.5, top / quantum + 1.5)) * quantum
    styles = {"recorded": ("-", 1.0, 2.0), "±30°": ("--", 0.9, 1.6), "±60°": (":", 0.9, 2.0)}
    lines = [f"per-frame codebook error on {n_frames} test frames (temperature 0); control turns the leader's "
             f"future keys in the follower input about the follower's root"]
    for ax, m in zip(axes, methods):
        e = errors[m]
        groups = {"recorded": e[0.0], "±30°": np.r_[e[30.0], e[-30.0]], "±60°": np.r_[e[60.0], e[-60.0]]}
        for g, v in groups.items():
            ls, alpha, lw = styles[g]
            ax.hist(v, bins=edges, density=True, histtype="step", color=COLORS[m], linestyle=ls,
                    linewidth=lw, alpha=alpha, label=f"{g}: mean {v.mean():.3f}")
        ax.set_title(LABELS[m], color=COLORS[m])
        ax.set_xlabel("codebook matching error (per frame)")
        ax.set_xlim(edges[0], edges[-1])
        ax.set_ylim(0, ax.get_ylim()[1] * 1.45)      # room for the legend above the bars
        ax.set_ylabel("density")
        ax.legend(loc="upper right")
        lines.append(f"  {m:<20} mean  recorded {e[0.0].mean():.4f}  +30 {e[30.0].mean():.4f}  -30 "
                     f"{e[-30.0].mean():.4f}  +60 {e[60.0].mean():.4f}  -60 {e[-60.0].mean():.4f}   "
                     f"share of frames exact (0 error): {np.mean(e[0.0] == 0):.2f} -> ±60° "
                     f"{np.mean(groups['±60°'] == 0):.2f}")
    ax = axes[len(methods)]
    angles = sorted(errors[methods[0]])
    for m in methods:
        ax.plot(angles, [errors[m][a].mean() for a in angles], "o-", color=COLORS[m], label=LABELS[m])
    ax.set_xticks(angles)
    ax.set_xlabel("turn of the leader's future path (°)")
    ax.set_ylabel("mean codebook error")
    ax.set_title("mean vs turn")
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle("Codebook matching error on test frames: as recorded (solid) and with the leader's future path\n"
                 "in the follower input turned ±30° (dashed) / ±60° (dotted) about the follower's root")
    fig.tight_layout()
    save_figure(fig, out, "codebook")
    plt.close(fig)
    if "motion_matching" in errors:
        lines.append("  motion_matching: our output encoder's code of the frame MM picked vs of the recorded frame "
                     "(own future path extrapolated, as in evaluate's teacher-forced run)")
    evaluated = read_eval(args)
    if evaluated:
        tf = evaluated["protocols"]["teacher_forced"]
        pairs = [(m, k) for m, k in (("follower", "ours"), ("follower_ccm", "ccm"), ("motion_matching", "motion_matching"))
                 if m in errors and tf.get(k, {}).get("codebook_error") is not None]
        lines.append(f"  cross-check with {args.eval} (teacher-forced codebook error): " + ", ".join(
            f"{k} {tf[k]['codebook_error']:.4f} (here {errors[m][0.0].mean():.4f})" for m, k in pairs))
    lines += [f"  note: {n}" for n in notes]
    lines.append("  note: CCM large has 3x the channels, so one wrong channel costs 1/3 of what it does for "
                 "the others")
    return lines
