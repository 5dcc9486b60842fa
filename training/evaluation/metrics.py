"""Evaluation metrics, and the small motion autoencoder that FID and Diversity read.

Units and spaces are in each name or docstring: positions in metres in, centimetres out where the
name says `_cm`. Everything is numpy except the encoder (torch).

The paper takes FID and Diversity "from the encoder output": features of motion from a learned
encoder, as FID takes them from Inception. Ours is `EvalEncoder`, an autoencoder over 15-frame
windows of the follower (per frame: the 204 pose-block numbers in that frame's root space and the
root update from the frame before). It is trained once on the training takes, deterministically
(fixed seed, deterministic algorithms, one thread), and cached, so every evaluation embeds motion
with the very same weights; numbers are comparable across runs and methods, not to the paper's.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..mirror.features import CONTACT_HEIGHT, POSE_SIZE, ROOT_UPDATE_SIZE, Track, pose_block, root_update
from ..mirror.skeleton import FEET, FPS, HANDS, SPINE


# ---------------------------------------------------------------- pose and motion quality

def mpjpe_cm(pred: np.ndarray, target: np.ndarray) -> float:
    """Mean per-joint position error in cm between joint positions [..., J, 3] in metres. Both
    must be in the same space (evaluation uses each dancer's own root space)."""
    return float(np.linalg.norm(np.asarray(pred) - np.asarray(target), axis=-1).mean() * 100)


def jitter(positions: np.ndarray, fps: float = FPS) -> float:
    """Mean jerk magnitude (m/s^3) of joint positions [T, J, 3]: the third finite difference.
    Constant velocity and constant acceleration give 0."""
    positions = np.asarray(positions, float)
    if len(positions) < 4:
        return 0.0
    jerk = np.diff(positions, 3, axis=0) * fps ** 3
    return float(np.linalg.norm(jerk, axis=-1).mean())


def foot_skate_cm(positions: np.ndarray, contacts: np.ndarray | None = None,
                  height: float = CONTACT_HEIGHT) -> float:
    """Horizontal motion (cm per frame) of the ankles [T, J, 3] over the frame steps in which a
    foot is in contact: given as contacts [T-1, 2] (bool), or, by default, the ankle below
    `height` at both ends of the step (the features' contact height). A planted foot gives 0;
    no contact at all gives 0 too, so read it beside the ground truth's value."""
    feet = np.asarray(positions, float)[:, FEET]
    step = np.linalg.norm(feet[1:, :, [0, 2]] - feet[:-1, :, [0, 2]], axis=-1)     # [T-1, 2]
    if contacts is None:
        contacts = (feet[1:, :, 1] < height) & (feet[:-1, :, 1] < height)
    contacts = np.asarray(contacts, bool)
    return float(step[contacts].mean() * 100) if contacts.any() else 0.0


def hand_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Mean over frames of the smallest of the 4 hand-to-hand distances (m) between two dancers'
    world positions [T, J, 3]."""
    return float(closest_hand_distance(a, b).mean())


# ---------------------------------------------------------------- the two dancers together

# The torso as capsules around the SPINE chain. 14 cm is about half a torso's depth and width at
# the chest: two torsos whose spines come closer than twice that pass through each other.
TORSO_RADIUS = 0.14
HAND_HOLD_DISTANCE = 0.20   # m between a hand of each dancer: holding, or about to


def closest_on_segments(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray):
    """Parameters (s, t) in [0, 1] of the closest points p0 + s (p1 - p0) and q0 + t (q1 - q0) of
    two segments ([..., 3] each, broadcast) -> two arrays [...]. Exact, degenerate segments
    included (web/mirror/contact.ts closestOnSegments is the same for one pair)."""
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a, e = (d1 * d1).sum(-1), (d2 * d2).sum(-1)
    b, c, f = (d1 * d2).sum(-1), (d1 * r).sum(-1), (d2 * r).sum(-1)
    denom = a * e - b * b
    eps = 1e-12
    # Parallel (or degenerate) segments: any s works; take p0's end.
    s = np.where(denom > eps, np.clip((b * f - c * e) / np.maximum(denom, eps), 0, 1), 0.0)
    t = np.where(e > eps, (b * s + f) / np.maximum(e, eps), 0.0)
    # Where t leaves [0, 1] (or q is a point), fix t at that end of q and recompute s for it.
    t_clamped = np.clip(t, 0, 1)
    redo = (t != t_clamped) | (e <= eps)
    s = np.where(redo, np.where(a > eps, np.clip((b * t_clamped - c) / np.maximum(a, eps), 0, 1), 0.0), s)
    return s, t_clamped


def segment_distance(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """Closest distance between segments p0-p1 and q0-q1 ([..., 3] each, broadcast) -> [...]."""
    s, t = closest_on_segments(p0, p1, q0, q1)
    return np.linalg.norm((p0 + (p1 - p0) * s[..., None]) - (q0 + (q1 - q0) * t[..., None]), axis=-1)


def torso_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per frame, the closest distance (m) between the spine segments of two dancers' world
    positions [T, J, 3] -> [T]."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    pa0, pa1 = a[:, SPINE[:-1]][:, :, None], a[:, SPINE[1:]][:, :, None]        # [T, 3, 1, 3]
    pb0, pb1 = b[:, SPINE[:-1]][:, None], b[:, SPINE[1:]][:, None]              # [T, 1, 3, 3]
    return segment_distance(pa0, pa1, pb0, pb1).reshape(len(a), -1).min(1)


def closest_hand_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per frame, the smallest of the 4 hand-to-hand distances (m) [T]."""
    ha, hb = np.asarray(a)[:, HANDS], np.asarray(b)[:, HANDS]
    return np.linalg.norm(ha[:, :, None] - hb[:, None, :], axis=-1).reshape(len(ha), -1).min(1)


def interaction(leader: np.ndarray, follower: np.ndarray, leader_contacts: np.ndarray | None = None,
                follower_contacts: np.ndarray | None = None) -> dict:
    """How two dancers' world positions [T, J, 3] read as a couple.

    interpenetration: share of frames whose torsos pass through each other (spines closer than
    2 x TORSO_RADIUS); hand_hold: share of frames with some hand pair within HAND_HOLD_DISTANCE;
    closest_hand_m: the mean of that closest pair's distance; foot skate of each dancer while the
    ankle is low (`foot_skate_cm`'s default) and, where per-frame contact labels [T, 2] are
    given, while labelled in contact at both ends of the step."""
    leader, follower = np.asarray(leader, float), np.asarray(follower, float)
    hands = closest_hand_distance(leader, follower)
    out = {"interpenetration": float((torso_distance(leader, follower) < 2 * TORSO_RADIUS).mean()),
           "hand_hold": float((hands < HAND_HOLD_DISTANCE).mean()),
           "closest_hand_m": float(hands.mean()),
           "skate_leader_cm": foot_skate_cm(leader), "skate_follower_cm": foot_skate_cm(follower)}
    for name, pos, c in (("leader", leader, leader_contacts), ("follower", follower, follower_contacts)):
        if c is not None:
            c = np.asarray(c) > 0.5
            out[f"contact_skate_{name}_cm"] = foot_skate_cm(pos, c[1:] & c[:-1])
    return out


def ratio_to(reference: dict, values: dict) -> dict:
    """values / reference for every key both have (None where the reference is 0)."""
    return {k: (values[k] / reference[k] if reference[k] else None)
            for k in values if k in reference and isinstance(values[k], float)}


def steering_response(root: np.ndarray, turn_frame: int, direction: np.ndarray, fps: float = FPS,
                      within_degrees: float = 30.0, smooth_frames: int = 10) -> dict:
    """After the stick turns to `direction` (world x, z) at `turn_frame`: seconds until the
    dancer's root velocity, averaged over the last `smooth_frames` (a dancer sways within a
    step), is within `within_degrees` of it (None if never), and the mean speed (m/s) over the
    last second of the record."""
    root = np.asarray(root, float)
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    vel = (root[smooth_frames:] - root[:-smooth_frames]) * fps / smooth_frames      # ends at frame i+smooth
    cos = (vel @ d) / np.maximum(np.linalg.norm(vel, axis=-1), 1e-9)
    ok = np.nonzero(cos[max(turn_frame - smooth_frames, 0):] >= np.cos(np.radians(within_degrees)))[0]
    last = root[-int(fps):]
    speed = float(np.linalg.norm(last[-1] - last[0]) * fps / (len(last) - 1))
    return {"seconds": float(ok[0] / fps) if len(ok) else None, "speed": speed}


def codebook_error(target: np.ndarray, estimate: np.ndarray) -> float:
    """MSE between one-hot codes [B, C*D] (target from the output encoder, estimate from the
    input encoder), as train.validate measures it: 2k/(C*D) for k wrong channels of a row."""
    return float(np.mean((np.asarray(target, float) - np.asarray(estimate, float)) ** 2))


def one_hot(codes: np.ndarray, classes: int) -> np.ndarray:
    """Code indices [B, C] -> one-hot [B, C*classes]."""
    codes = np.asarray(codes)
    out = np.zeros(codes.shape + (classes,))
    np.put_along_axis(out, codes[..., None], 1.0, -1)
    return out.reshape(codes.shape[0], -1)


# ---------------------------------------------------------------- distribution metrics

def _psd_sqrt_trace(a: np.ndarray, b: np.ndarray) -> float:
    """Tr sqrt(A B) for covariances A, B, as Tr sqrt(A^1/2 B A^1/2): the same eigenvalues, but a
    symmetric matrix, so eigh is exact and stable where sqrtm of A B can turn complex."""
    w, v = np.linalg.eigh((a + a.T) / 2)
    half = (v * np.sqrt(np.clip(w, 0, None))) @ v.T
    m = half @ b @ half
    return float(np.sqrt(np.clip(np.linalg.eigvalsh((m + m.T) / 2), 0, None)).sum())


def fid(a: np.ndarray, b: np.ndarray) -> float:
    """Frechet distance between Gaussian fits of feature sets a [N, D] and b [M, D]:
    |mu_a - mu_b|^2 + Tr(S_a + S_b - 2 (S_a S_b)^1/2). A set against itself gives 0."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    if len(a) < 2 or len(b) < 2:
        raise ValueError("FID needs at least 2 samples per set")
    sa, sb = np.cov(a, rowvar=False), np.cov(b, rowvar=False)
    d = float(((a.mean(0) - b.mean(0)) ** 2).sum() + np.trace(sa) + np.trace(sb) - 2 * _psd_sqrt_trace(sa, sb))
    return max(d, 0.0)   # rounding can leave -1e-12 for identical sets


def diversity(x: np.ndarray, pairs: int = 300, seed: int = 0) -> float:
    """Mean distance between `pairs` random pairs of feature rows x [N, D] (fixed seed, so a set
    always gets the same number; the pairs are drawn with replacement, never a row with itself)."""
    x = np.asarray(x, np.float64)
    if len(x) < 2:
        return 0.0
    rng = np.random.default_rng(seed)
    i = rng.integers(0, len(x), pairs)
    j = (i + rng.integers(1, len(x), pairs)) % len(x)     # j != i
    return float(np.linalg.norm(x[i] - x[j], axis=-1).mean())


# ---------------------------------------------------------------- windows of motion

WINDOW = 15
FRAME_FEATURES = POSE_SIZE + ROOT_UPDATE_SIZE     # 207


def motion_features(track: Track, frames: np.ndarray) -> np.ndarray:
    """Per frame t [N, 207]: pose block at t in t's root space, root update from t-1 to t."""
    t = np.asarray(frames)
    return np.concatenate([
        pose_block(track.positions[t], track.positions[t - 1], track.rotations[t], track.root[t], track.heading[t]),
        root_update(track.root[t - 1], track.heading[t - 1], track.root[t], track.heading[t]),
    ], -1)


def windows(frame_features: np.ndarray, size: int = WINDOW, stride: int = 1) -> np.ndarray:
    """Consecutive frames [T, F] -> overlapping windows [M, size*F] (none if T < size)."""
    f = np.asarray(frame_features)
    starts = np.arange(0, len(f) - size + 1, stride)
    if len(starts) == 0:
        return np.zeros((0, size * f.shape[1]))
    return f[starts[:, None] + np.arange(size)].reshape(len(starts), -1)


# ---------------------------------------------------------------- the evaluation encoder

@dataclass
class EncoderConfig:
    window: int = WINDOW
    hidden: int = 256
    latent: int = 64
    epochs: int = 30
    batch_size: int = 256
    lr: float = 1e-3
    seed: int = 0


def _encoder_modules(cfg: EncoderConfig, inputs: int):
    import torch.nn as nn
    enc = nn.Sequential(nn.Linear(inputs, cfg.hidden), nn.ELU(), nn.Linear(cfg.hidden, cfg.latent))
    dec = nn.Sequential(nn.Linear(cfg.latent, cfg.hidden), nn.ELU(), nn.Linear(cfg.hidden, inputs))
    return enc, dec


def fingerprint(train_windows: np.ndarray, cfg: EncoderConfig) -> str:
    """What the weights depend on: the training windows (bytes) and the configuration."""
    h = hashlib.sha256(np.ascontiguousarray(train_windows, np.float32).tobytes())
    h.update(json.dumps(asdict(cfg), sort_keys=True).encode())
    return h.hexdigest()[:16]


def train_encoder(train_windows: np.ndarray, cfg: EncoderConfig = EncoderConfig(), quiet: bool = True) -> dict:
    """Train the autoencoder; returns a state dict of plain tensors (torch.save-able).

    Bit-for-bit repeatable on one machine: the RNG is forked and seeded, deterministic
    algorithms and a single thread are forced for the duration (and restored after), and the
    batch order comes from its own generator."""
    import torch
    import torch.nn.functional as F
    x = torch.from_numpy(np.ascontiguousarray(train_windows, np.float32))
    if len(x) < 2:
        raise ValueError("the evaluation encoder needs at least 2 training windows")
    mean = x.mean(0)
    std = x.std(0).clamp_min(1e-2)      # same floor as features.normalization
    xn = (x - mean) / std
    was_deterministic, threads = torch.are_deterministic_algorithms_enabled(), torch.get_num_threads()
    torch.use_deterministic_algorithms(True)
    torch.set_num_threads(1)
    try:
        with torch.random.fork_rng(devices=[]):
            torch.manual_seed(cfg.seed)
            enc, dec = _encoder_modules(cfg, x.shape[1])
            opt = torch.optim.Adam([*enc.parameters(), *dec.parameters()], lr=cfg.lr)
            gen = torch.Generator().manual_seed(cfg.seed)
            for epoch in range(cfg.epochs):
                perm = torch.randperm(len(xn), generator=gen)
                total = 0.0
                for s in range(0, len(xn), cfg.batch_size):
                    b = xn[perm[s:s + cfg.batch_size]]
                    loss = F.mse_loss(dec(enc(b)), b)
                    opt.zero_grad()
                    loss.backward()
                    opt.step()
                    total += loss.item() * len(b)
                if not quiet:
                    print(f"eval encoder epoch {epoch + 1}/{cfg.epochs}  reconstruction {total / len(xn):.4f}")
    finally:
        torch.use_deterministic_algorithms(was_deterministic)
        torch.set_num_threads(threads)
    return {"config": asdict(cfg), "inputs": x.shape[1], "mean": mean, "std": std,
            "encoder": enc.state_dict(), "decoder": dec.state_dict(), "reconstruction": total / len(xn)}


class EvalEncoder:
    """The trained encoder half: windows [M, window*207] -> latent features [M, latent]."""

    def __init__(self, state: dict):
        import torch
        self.state = state
        self.cfg = EncoderConfig(**state["config"])
        self.enc, _ = _encoder_modules(self.cfg, state["inputs"])
        self.enc.load_state_dict(state["encoder"])
        self.enc.eval()
        self.mean, self.std = state["mean"], state["std"]
        self._torch = torch

    def __call__(self, w: np.ndarray) -> np.ndarray:
        torch = self._torch
        if len(w) == 0:
            return np.zeros((0, self.cfg.latent))
        with torch.no_grad():
            x = (torch.from_numpy(np.ascontiguousarray(w, np.float32)) - self.mean) / self.std
            return self.enc(x).double().numpy()


def load_or_train_encoder(cache: str | Path, train_windows: np.ndarray,
                          cfg: EncoderConfig = EncoderConfig(), quiet: bool = True) -> tuple[EvalEncoder, bool]:
    """The cached encoder in cache/encoder.pt if it was trained on these windows with this
    configuration, else train it and write the cache. Returns (encoder, trained_now)."""
    import torch
    path = Path(cache) / "encoder.pt"
    key = fingerprint(train_windows, cfg)
    if path.exists():
        try:
            state = torch.load(path, map_location="cpu", weights_only=True)
            if state.get("fingerprint") == key:
                return EvalEncoder(state), False
        except Exception:   # a damaged cache is simply rebuilt
            pass
    state = train_encoder(train_windows, cfg, quiet)
    state["fingerprint"] = key
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    torch.save(state, tmp)
    tmp.replace(path)
    return EvalEncoder(state), True
