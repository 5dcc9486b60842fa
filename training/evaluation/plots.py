"""python -m training.evaluation.plots: the paper's analysis figures from the trained models -> PNGs.

    python -m training.evaluation.plots --out docs                 # every figure
    python -m training.evaluation.plots --out docs --only tsne,sweep

Figures (each prints the numbers it shows; one whose inputs are missing is skipped with a note):

tsne_latent.png             t-SNE of the output encoder's target logits S (blue) and the input
                            encoder's estimate Ŝ (red) on test frames, with (follower) and without
                            (follower_no_gan) the adversarial term (paper: DrawLatentSpace).
codebook_error_density.png  per-frame codebook matching error on the test frames (paper:
                            CodebookErrorDensity), as recorded and with the leader's future path
                            in the follower input turned by ±30° / ±60° about the follower's root.
lambda_sweep.png            last-epoch validation codebook error and MSE against λG/λC (paper:
                            MatchingError).
rollout_topview.png         top view of free-running rollouts on a test take, leader played back
                            from the recording (evaluate.rollout), ours vs CCM vs the recording.
training_curves.png         validation MSE and codebook error per epoch of every model.

Codebook error of one frame: the MSE between the one-hot target code (argmax of S per channel)
and the one-hot estimate (argmax of Ŝ, temperature 0), i.e. 2k/(C*D) for k channels that differ,
as train.validate and evaluate measure it. Under control both encoders read the turned input (the
target still encodes the recorded output, the only one there is); Motion Matching has no encoder
of its own, so its code is our output encoder's code of the frame it picked (as in evaluate).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

import numpy as np

from ..mirror import features as feat

FIGURES = ["tsne", "codebook", "sweep", "rollout", "curves"]
FILES = {"tsne": "tsne_latent.png", "codebook": "codebook_error_density.png", "sweep": "lambda_sweep.png",
         "rollout": "rollout_topview.png", "curves": "training_curves.png"}
DPI = 110

# One colour per method across every figure: ours red, CCM blue/grey, Motion Matching green.
COLORS = {
    "follower": "#d62728", "follower_no_gan": "#ff7f0e", "follower_small": "#e377c2",
    "follower_end_to_end": "#8c564b", "follower_end_to_end_no_ss": "#bcbd22",
    "follower_ccm": "#4a7bb7", "follower_ccm_large": "#1f3f7a", "motion_matching": "#2ca02c",
    "leader": "#9467bd", "recording": "#111111", "recorded_leader": "#9467bd",
}
LABELS = {
    "follower": "ours", "follower_no_gan": "ours w/o GAN (λG=0)", "follower_small": "ours, small (256)",
    "follower_end_to_end": "ours, end-to-end", "follower_end_to_end_no_ss": "ours, end-to-end w/o SS",
    "follower_ccm": "CCM", "follower_ccm_large": "CCM large (24 ch)", "motion_matching": "Motion Matching",
    "leader": "leader model (leader data)",
}
TARGET_COLOR, ESTIMATE_COLOR = "#1f77b4", "#d62728"     # the paper's blue target, red estimate
CURVE_MODELS = ["follower", "follower_ccm", "follower_ccm_large", "follower_small", "leader"]
ABLATIONS = ["follower_no_gan", "follower_end_to_end", "follower_end_to_end_no_ss"]
CONTROL_ANGLES = [30.0, -30.0, 60.0, -60.0]
FOLLOWER_IN = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)


class Skip(RuntimeError):
    """A figure's inputs are missing or unfinished; the message is one line for a user."""


# ---------------------------------------------------------------- pure helpers

def rotate_partner_future(x: np.ndarray, degrees: float) -> np.ndarray:
    """Follower inputs [N, 660] (raw) with the leader's future trajectory keys turned by `degrees`
    about the follower's root: key positions (x, z) and forward directions (x, z) alike.

    The block is in the follower's root space, so the root is the origin. The sense matches
    evaluate.bend_plan and train.augment_control: a heading h (facing (sin h, cos h)) becomes h + a.
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


def per_frame_codebook_error(target: np.ndarray, estimate: np.ndarray, classes: int) -> np.ndarray:
    """Code indices [N, C] -> per-frame MSE between the one-hot codes [N]: 2k/(C*D) for k
    channels that differ (the mean of this is metrics.codebook_error)."""
    target, estimate = np.asarray(target), np.asarray(estimate)
    return 2.0 * (target != estimate).sum(1) / (target.shape[1] * classes)


def knn_mixing(a: np.ndarray, b: np.ndarray, k: int = 10) -> float:
    """How well two point sets overlap: the mean share of each point's k nearest neighbours
    (Euclidean, in the given space) that belong to the other set, divided by the share a perfect
    mix would give. 1 = indistinguishable, 0 = fully separated."""
    pts = np.concatenate([a, b]).astype(np.float64)
    lab = np.r_[np.zeros(len(a)), np.ones(len(b))]
    sq = (pts ** 2).sum(1)
    d = sq[:, None] + sq[None] - 2 * pts @ pts.T
    np.fill_diagonal(d, np.inf)
    nn = np.argpartition(d, k, axis=1)[:, :k]
    other = (lab[nn] != lab[:, None]).mean(1)
    expected = np.where(lab == 0, len(b), len(a)) / (len(pts) - 1)
    return float(np.mean(other / expected))


def log_positions(ratios, zero_at: float | None = None) -> tuple[np.ndarray, float]:
    """x positions on a log axis for values >= 0: a 0 goes to `zero_at` (default one decade
    below the smallest positive value). Returns (positions, zero position)."""
    r = np.asarray(ratios, dtype=float)
    pos = r[r > 0]
    if zero_at is None:
        zero_at = (pos.min() / 10) if len(pos) else 1e-4
    return np.where(r > 0, r, zero_at), zero_at


def log_softmax_channels(logits: np.ndarray, channels: int) -> np.ndarray:
    """Per-channel log-softmax [N, C*D]: the logits without their arbitrary per-channel offset
    (what the discriminator sees)."""
    z = logits.reshape(len(logits), channels, -1).astype(np.float64)
    z = z - z.max(-1, keepdims=True)
    z = z - np.log(np.exp(z).sum(-1, keepdims=True))
    return z.reshape(len(logits), -1)


def evenly(n: int, k: int) -> np.ndarray:
    """k indices spread evenly over range(n) (all of them when k >= n)."""
    if k >= n:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, k).round().astype(int))


# ---------------------------------------------------------------- inputs

def run_state(run: Path) -> dict | None:
    """{'stage', 'epoch', 'history', 'config'} of a training folder, or None when there is no
    readable checkpoint. history.json is preferred for a finished run (it is written last)."""
    from ..data.prepared import TrainError
    from ..learning.runs import load_checkpoint
    ckpt = run / "checkpoint.pt"
    hist = run / "history.json"
    if not ckpt.exists():
        return None
    try:
        ck = load_checkpoint(ckpt)
    except TrainError:   # being written right now, or damaged
        return None
    history = ck.get("history", {})
    if ck.get("stage") == "done" and hist.exists():
        try:
            history = json.loads(hist.read_text())
        except ValueError:
            pass
    return {"stage": ck.get("stage"), "epoch": ck.get("epoch"), "history": history, "config": ck.get("config", {})}


def load_model(runs: Path, name: str, prepared: str):
    """The step model of a finished run, or Skip with the reason."""
    from ..data.prepared import TrainError
    from ..learning.runs import load_run
    try:
        return load_run(runs / name, prepared).model
    except TrainError as e:
        raise Skip(str(e)) from None


def load_test(prepared: str) -> dict[str, np.ndarray]:
    from ..data.prepared import TrainError, load_split
    try:
        return load_split(prepared, "test", "follower")
    except TrainError as e:
        raise Skip(str(e)) from None


def encode(model, x_raw: np.ndarray, y_raw: np.ndarray | None = None):
    """(estimate logits Ŝ, target logits S or None) [N, C*D] from raw inputs/outputs; the
    intention comes from the model's own predictor."""
    import torch
    with torch.no_grad():
        x = torch.from_numpy(np.asarray(x_raw, np.float32))
        y = None if y_raw is None else torch.from_numpy(np.asarray(y_raw, np.float32))
        est, tgt, _ = model.logits(x, y)
    return est.numpy(), None if tgt is None else tgt.numpy()


def codes_of(logits: np.ndarray, channels: int) -> np.ndarray:
    return logits.reshape(len(logits), channels, -1).argmax(-1)


def read_eval(args) -> dict | None:
    """runs/eval/metrics.json (training.evaluation.evaluate) when it is there and readable."""
    try:
        return json.loads(Path(args.eval).read_text())
    except (OSError, ValueError):
        return None


def _save(fig, out: Path, key: str) -> None:
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / FILES[key], dpi=DPI)


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"font.size": 10, "axes.titlesize": 11, "legend.fontsize": 9})
    return plt


# ---------------------------------------------------------------- 1. t-SNE

def figure_tsne(args, out: Path) -> list[str]:
    from sklearn.manifold import TSNE
    test = load_test(args.prepared)
    idx = evenly(len(test["input"]), args.tsne_frames)
    x, y = test["input"][idx], test["output"][idx]
    panels = []
    for name, title in (("follower", "with adversarial training (ours)"),
                        ("follower_no_gan", "without adversarial training (λG = 0)")):
        try:
            m = load_model(Path(args.runs), name, args.prepared)
        except Skip as e:
            if name == "follower":
                raise
            panels.append((name, title, None, str(e)))
            continue
        est, tgt = encode(m, x, y)
        c = m.cfg.channels
        emb = TSNE(n_components=2, perplexity=30, init="pca", random_state=0,
                   max_iter=args.tsne_iter).fit_transform(np.concatenate([tgt, est]))
        n = len(tgt)
        mix_latent = knn_mixing(tgt, est)
        mix_2d = knn_mixing(emb[:n], emb[n:])
        # The same overlap measure on the logits without their per-channel offset (what the
        # discriminator sees) and on the per-channel probabilities.
        ls_t, ls_e = log_softmax_channels(tgt, c), log_softmax_channels(est, c)
        mix_other = {"log-softmax": knn_mixing(ls_t, ls_e), "softmax": knn_mixing(np.exp(ls_t), np.exp(ls_e))}
        cb = per_frame_codebook_error(codes_of(tgt, c), codes_of(est, c), m.cfg.classes).mean()
        panels.append((name, title, (emb, n, mix_latent, mix_2d, cb, mix_other), None))

    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.4))
    lines = [f"t-SNE of the logits (C*D = {tgt.shape[1]}), {len(idx)} test frames -> {2 * len(idx)} points, "
             f"random_state 0; mixing = k-NN (k=10) share of the other set / chance (1 = overlap, 0 = apart)"]
    for ax, (name, title, res, note) in zip(axes, panels):
        ax.set_title(title)
        ax.set_xticks([]); ax.set_yticks([])
        if res is None:
            ax.text(0.5, 0.5, f"{name} not available:\n" + _wrap(note, 45), ha="center", va="center",
                    transform=ax.transAxes, fontsize=9, color="#555555")
            lines.append(f"  {name}: not available ({note})")
            continue
        emb, n, mix_latent, mix_2d, cb, mix_other = res
        ax.scatter(emb[:n, 0], emb[:n, 1], s=7, c=TARGET_COLOR, alpha=0.6, linewidths=0, label="target S (output encoder)")
        ax.scatter(emb[n:, 0], emb[n:, 1], s=7, c=ESTIMATE_COLOR, alpha=0.6, linewidths=0,
                   label="estimate Ŝ (input encoder)")
        ax.legend(loc="upper right", markerscale=2.5, framealpha=0.9)
        ax.text(0.02, 0.02, f"S/Ŝ k-NN mixing (1 = overlap): logits {mix_latent:.2f}, t-SNE {mix_2d:.2f}\n"
                f"codebook error {cb:.4f}", transform=ax.transAxes, fontsize=9, va="bottom",
                bbox=dict(facecolor="white", alpha=0.8, edgecolor="none"))
        ax.set_xlabel("t-SNE 1"); ax.set_ylabel("t-SNE 2")
        lines.append(f"  {name}: mixing of the logits {mix_latent:.3f} (t-SNE 2-d {mix_2d:.3f}); of per-channel "
                     f"log-softmax {mix_other['log-softmax']:.3f}, of softmax probabilities "
                     f"{mix_other['softmax']:.3f}; codebook error on these frames {cb:.4f}")
    fig.suptitle("Target vs estimated latent (test frames): blue S from the output encoder, red Ŝ from the input encoder")
    fig.tight_layout()
    _save(fig, out, "tsne")
    plt.close(fig)
    return lines


def _wrap(text: str, width: int) -> str:
    import textwrap
    return "\n".join(textwrap.wrap(text, width))


# ---------------------------------------------------------------- 2. codebook error density

def motion_matching_policy(args):
    from ..data.dataset import DataError
    from .motion_matching import build, load_tracks, training_takes
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
    plt = _plt()
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
    _save(fig, out, "codebook")
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


# ---------------------------------------------------------------- 3. λG/λC sweep

def sweep_runs(args) -> tuple[list[dict], list[str]]:
    """Finished runs with their λG/λC and last-epoch validation metrics, plus notes."""
    runs = Path(args.runs)
    candidates = [runs / "follower_no_gan", runs / "follower"]
    sweep = Path(args.sweep)
    if sweep.is_dir():
        candidates += sorted(p / "follower" for p in sweep.iterdir() if p.is_dir())
    points, notes = [], []
    for run in candidates:
        st = run_state(run)
        if st is None:
            notes.append(f"{run}: no checkpoint yet")
            continue
        if st["stage"] != "done":
            notes.append(f"{run}: still training ({st['stage']} epoch {st['epoch']})")
            continue
        h, cfg = st["history"], st["config"]
        if not h.get("val_codebook"):
            notes.append(f"{run}: no validation history")
            continue
        lg, lc = cfg.get("lambda_generator"), cfg.get("lambda_codebook")
        points.append({"run": str(run), "lambda_generator": lg, "lambda_codebook": lc, "ratio": lg / lc,
                       "val_codebook": h["val_codebook"][-1], "val_mse": h["val_mse"][-1],
                       "best_val_codebook": min(h["val_codebook"]), "epochs": len(h["val_codebook"])})
    points.sort(key=lambda p: p["ratio"])
    return points, notes


def figure_sweep(args, out: Path) -> list[str]:
    points, notes = sweep_runs(args)
    if not points:
        raise Skip("no finished run of the λG sweep: " + "; ".join(notes))
    lcs = {p["lambda_codebook"] for p in points}
    ratios = np.array([p["ratio"] for p in points])
    pos, zero_at = log_positions(ratios)
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2))
    for ax, key, label in ((axes[0], "val_codebook", "validation codebook matching error"),
                           (axes[1], "val_mse", "validation MSE (normalized output)")):
        v = np.array([p[key] for p in points])
        positive = ratios > 0
        ax.plot(pos[positive], v[positive], "-", color=COLORS["follower"], alpha=0.5)
        if (~positive).any() and positive.any():   # 0 is not on a log scale: a dotted link
            first = np.argmax(positive)
            ax.plot([zero_at, pos[first]], [v[~positive][-1], v[first]], ":", color=COLORS["follower"], alpha=0.5)
        ax.plot(pos, v, "o", color=COLORS["follower"], markersize=7)
        for x_, y_, p in zip(pos, v, points):
            ax.annotate(f"{y_:.4f}", (x_, y_), textcoords="offset points", xytext=(0, 8), ha="center", fontsize=8)
        ax.set_xscale("log")
        ticks = sorted(set(pos.tolist()))
        lg_of = {float(x_): p["lambda_generator"] for x_, p in zip(pos, points)}
        ax.set_xticks(ticks)
        ax.set_xticklabels([("0" if t == zero_at and 0 in ratios else f"{t:g}") + f"\nλG={lg_of[t]:g}" for t in ticks])
        ax.minorticks_off()
        if 0 in ratios and positive.any():
            brk = math.sqrt(zero_at * pos[positive].min())
            ax.text(brk, 0, "//", transform=ax.get_xaxis_transform(), ha="center", va="center",
                    fontsize=12, color="#555555", backgroundcolor="white")
        ax.set_xlim(min(ticks) / 2.5, max(ticks) * 2.5)
        ax.set_xlabel(f"λG / λC   (λC = {', '.join(f'{c:g}' for c in sorted(lcs))}; log axis, broken before 0)")
        ax.set_ylabel(label)
        ax.margins(y=0.2)
        ax.grid(alpha=0.3)
    fig.suptitle("GAN weight vs matching weight: last-epoch validation metrics (follower)")
    fig.tight_layout()
    _save(fig, out, "sweep")
    plt.close(fig)
    lines = ["λG/λC sweep, last epoch (best epoch in brackets):"]
    for p in points:
        lines.append(f"  λG {p['lambda_generator']:g} / λC {p['lambda_codebook']:g} = {p['ratio']:g}: val codebook "
                     f"{p['val_codebook']:.4f} ({p['best_val_codebook']:.4f}), val MSE {p['val_mse']:.4f}, "
                     f"{p['epochs']} epochs  [{p['run']}]")
    lines += [f"  note: {n}" for n in notes]
    return lines


# ---------------------------------------------------------------- 4. rollout top view

def figure_rollout(args, out: Path) -> list[str]:
    from . import evaluate as E
    from ..data.dataset import DataError
    try:
        manifest, onnx, _ = E.find_models(args.models)
        take = E.load_eval_takes(args.data, [args.take], args.frames, None)[0]
    except (E.EvalError, DataError) as e:
        raise Skip(str(e)) from None
    methods = [(n, k) for n, k in (("ours", "follower"), ("ccm", "follower_ccm")) if n in onnx]
    if not methods:
        raise Skip(f"{args.models}: neither follower.onnx nor follower_ccm.onnx")
    t0, steps = int(take.frames[0]), len(take.frames)
    span = slice(t0, t0 + steps + 1)
    rec_follow, rec_lead = take.follow.root[span], take.lead.root[span]
    conditions = [("playback", None, "leader played back from the recording")]
    if args.rollout_bend:
        bend = E.parse_condition(f"playback:{args.rollout_bend}")[1]
        conditions.append(("bend", bend, f"leader's future keys turned {bend[1]:+g}° (what the follower sees)"))
    results = {}
    for cond, bend, _ in conditions:
        for name, key in methods:
            policy = E.load_onnx(onnx[name])
            r = E.rollout(take, policy, args.temperature, args.seed, manifest["startPose"], "playback", bend)
            results[cond, key] = r
    plt = _plt()
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
            policy = E.load_onnx(onnx[name])
            stats = []
            for sd in seeds:
                r = (results["playback", key] if sd == args.seed else
                     E.rollout(take, policy, args.temperature, sd, manifest["startPose"]))
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
    _save(fig, out, "rollout")
    plt.close(fig)
    return lines


# ---------------------------------------------------------------- 5. training curves

def figure_curves(args, out: Path) -> list[str]:
    runs = Path(args.runs)
    found, missing = [], []
    lines = ["validation per epoch (teacher-forced, temperature 0); last epoch [best]:"]
    extra = sorted(p.name for p in runs.iterdir() if (p / "checkpoint.pt").exists()
                   and p.name not in CURVE_MODELS + ABLATIONS) if runs.is_dir() else []
    for name in CURVE_MODELS + ABLATIONS + extra:
        st = run_state(runs / name)
        if st is None or not st["history"].get("val_mse"):
            missing.append(name)
            continue
        found.append((name, st))
    if not found:
        raise Skip(f"{runs}: no training history of {', '.join(CURVE_MODELS)}")
    plt = _plt()
    from matplotlib.ticker import ScalarFormatter
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    spare = iter(["#17becf", "#7f7f7f", "#aec7e8", "#98df8a", "#c5b0d5", "#c49c94", "#f7b6d2", "#dbdb8d"] * 3)
    for name, st in found:
        h = st["history"]
        color = COLORS.get(name) or next(spare)
        done = st["stage"] == "done"
        label = LABELS.get(name, name) + ("" if done else f" (training, epoch {st['epoch']})")
        ls = "--" if name == "leader" else "-"
        for ax, key in zip(axes, ("val_mse", "val_codebook")):
            v = h[key]
            ax.plot(np.arange(1, len(v) + 1), v, ls, color=color, label=label, linewidth=1.6)
        lines.append(f"  {name:<26} MSE {h['val_mse'][-1]:.4f} [{min(h['val_mse']):.4f}]  codebook "
                     f"{h['val_codebook'][-1]:.4f} [{min(h['val_codebook']):.4f}]  "
                     f"{len(h['val_mse'])} epochs{'' if done else ' (still training)'}")
    axes[0].set_ylabel("validation MSE (normalized output)")
    axes[1].set_ylabel("validation codebook matching error")
    for ax, title in zip(axes, ("reconstruction", "codebook matching")):
        ax.set_xlabel("matching epoch")
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(ScalarFormatter())
        ax.yaxis.set_minor_formatter(ScalarFormatter())
        ax.set_title(title)
        ax.grid(alpha=0.3, which="both")
    axes[1].legend(fontsize=8, loc="upper right")
    fig.suptitle("Validation curves (take 12; the leader model on the leader's data)")
    fig.tight_layout()
    _save(fig, out, "curves")
    plt.close(fig)
    if missing:
        lines.append(f"  not available yet: {', '.join(missing)}")
    lines.append("  note: CCM large has 3x the channels: its codebook error per wrong channel is 1/3 of the others'")
    return lines


# ---------------------------------------------------------------- main

def main(argv=None) -> int:
    from ..data.folders import add_folder
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.plots", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="docs", help="folder for the PNGs")
    ap.add_argument("--only", default=",".join(FIGURES), help=f"comma-separated subset of {','.join(FIGURES)}")
    add_folder(ap, "prepared", "test split for t-SNE and codebook error")
    add_folder(ap, "runs", "checkpoints and training history")
    ap.add_argument("--sweep", default="runs/sweep", help="λG sweep: one folder per value, each with follower/")
    add_folder(ap, "models", "rollout top view")
    add_folder(ap, "data", "rollout take, Motion Matching database", old=("--bvh",))
    ap.add_argument("--eval", default="runs/eval/metrics.json", help="training.evaluation.evaluate output (cross-checks)")
    ap.add_argument("--take", default="13", help="test take of the rollout")
    ap.add_argument("--frames", type=int, default=600, help="rollout steps at most")
    ap.add_argument("--temperature", type=float, default=0.5, help="rollout sampling temperature")
    ap.add_argument("--seed", type=int, default=0, help="rollout seed (drawn)")
    ap.add_argument("--summary-seeds", type=int, default=3, help="seeds seed.. seed+N-1 in the rollout's printed spread")
    ap.add_argument("--rollout-bend", default="rot+60", help="second rollout panel: rot±DEG or side±M ('' for none)")
    ap.add_argument("--tsne-frames", type=int, default=500, help="test frames in the t-SNE (2 points each)")
    ap.add_argument("--tsne-iter", type=int, default=1000)
    ap.add_argument("--no-motion-matching", dest="motion_matching", action="store_false",
                    help="leave Motion Matching out of the codebook figure")
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args(argv)
    wanted = [f for f in args.only.split(",") if f]
    unknown = [f for f in wanted if f not in FIGURES]
    if unknown:
        ap.error(f"unknown figure(s) {', '.join(unknown)}; choose from {', '.join(FIGURES)}")
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, str(args.threads))
    import torch
    torch.set_num_threads(args.threads)
    out = Path(args.out)
    makers = {"tsne": figure_tsne, "codebook": figure_codebook, "sweep": figure_sweep,
              "rollout": figure_rollout, "curves": figure_curves}
    written, skipped = [], []
    for f in wanted:
        try:
            lines = makers[f](args, out)
        except Skip as e:
            skipped.append(f"{FILES[f]}: {e}")
            print(f"skipped {FILES[f]}: {e}", file=sys.stderr)
            continue
        written.append(out / FILES[f])
        print(f"== {out / FILES[f]}")
        print("\n".join(lines), flush=True)
    if not written:
        print("error: no figure could be made (" + "; ".join(skipped) + ")", file=sys.stderr)
        return 2
    print(f"wrote {len(written)} figure(s) to {out}" + (f"; skipped {len(skipped)}" if skipped else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
