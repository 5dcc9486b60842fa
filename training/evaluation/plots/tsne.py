"""tsne_latent.png: t-SNE of the output encoder's target logits S (blue) and the input encoder's
estimate Ŝ (red) on test frames, with (follower) and without (follower_no_gan) the adversarial
term (paper: DrawLatentSpace), and how well the two sets mix."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .common import Skip, codes_of, encode, load_model, load_test, per_frame_codebook_error, pyplot, save_figure

TARGET_COLOR, ESTIMATE_COLOR = "#1f77b4", "#d62728"     # the paper's blue target, red estimate


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

    plt = pyplot()
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
    save_figure(fig, out, "tsne")
    plt.close(fig)
    return lines

def _wrap(text: str, width: int) -> str:
    import textwrap
    return "\n".join(textwrap.wrap(text, width))
