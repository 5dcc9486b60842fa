"""Protocols (b) and (c) of training.evaluation.evaluate: free-running rollouts of a follower
beside a leader played back from the recording, its plan bent away from the recording, or
generated (Motion Matching or our leader model) and steered along the recording's path; and the
motion metrics of a run against the recording."""
from __future__ import annotations

import math

import numpy as np

from ..mirror import features as feat
from ..mirror.features import FUTURE_OFFSETS, HISTORY, Track, follower_input, leader_input
from ..mirror.music import music_at
from ..mirror.rollout import NOW, Dancer, apply_output, output_is_absurd, reset_beside
from . import figures as Fg
from . import metrics as M
from . import plausibility as P
from . import rhythm as R
from .evaluate_inputs import EvalError, EvalTake, RecordingPolicy, window

DIVERGED = 3.0          # m between the partners' roots: the pair has come apart


def parse_condition(text: str) -> tuple[str, tuple[str, float] | None]:
    """'playback:rot+30' -> ('playback', ('rot', 30.0)); 'mm' -> ('mm', None)."""
    leader, _, bend = text.partition(":")
    if leader not in ("playback", "mm", "model"):
        raise EvalError(f"condition {text!r}: leader must be playback, mm or model")
    if not bend:
        return leader, None
    for kind in ("rot", "side"):
        if bend.startswith(kind):
            try:
                return leader, (kind, float(bend[len(kind):]))
            except ValueError:
                break
    raise EvalError(f"condition {text!r}: bend must be rot+DEG, rot-DEG, side+M or side-M")


def bend_plan(track: Track, bend: tuple[str, float] | None) -> None:
    """Bend the future keys of a track window in place: turned about the root at NOW by DEG, or
    pushed along the root's +x axis (root space) by up to M metres at +1 s (growing linearly)."""
    if bend is None:
        return
    keys = NOW + FUTURE_OFFSETS
    r0, h0 = track.root[NOW].copy(), track.heading[NOW]
    rel = track.root[keys] - r0
    kind, amount = bend
    if kind == "rot":
        a = math.radians(amount)
        c, s = math.cos(a), math.sin(a)
        # Heading h faces (sin h, cos h); turning by a maps (sin h, cos h) to (sin(h+a), cos(h+a)).
        rel = np.stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]], -1)
        track.heading[keys] = np.angle(np.exp(1j * (track.heading[keys] + a)))
    else:
        side = np.array([math.cos(h0), -math.sin(h0)])       # root-space +x in world (x, z)
        rel = rel + amount * (np.arange(1, len(keys) + 1) / len(keys))[:, None] * side
    track.root[keys] = r0 + rel


def steer_along_recording(leader: Dancer, lead: Track, t: int) -> None:
    """Set a generated leader's plan to the recording's future path at t, taken relative to the
    recorded root and laid down from where the generated leader stands now."""
    keys = t + FUTURE_OFFSETS
    local = feat.trajectory_block(lead.root[keys], lead.heading[keys], lead.root[t], lead.heading[t]).reshape(-1, 4)
    tr = leader.track
    pos = feat.from_root_space_points(np.stack([local[:, 0], np.zeros(len(local)), local[:, 1]], -1),
                                      tr.root[NOW], tr.heading[NOW])
    tr.root[NOW + FUTURE_OFFSETS] = pos[:, [0, 2]]
    tr.heading[NOW + FUTURE_OFFSETS] = tr.heading[NOW] + np.arctan2(local[:, 2], local[:, 3])


def rollout(take: EvalTake, follower_policy, temperature: float, seed: int, start_pose: dict,
            leader_mode: str = "playback", bend=None, leader_policy=None, bar=None) -> dict:
    """One free run over the take's frames. Returns world arrays over frames t0-HISTORY ...
    t0+steps (the first HISTORY+1 are the recording's starting state) and reset counts."""
    rng = np.random.default_rng(seed)
    t0, steps = int(take.frames[0]), len(take.frames)
    follower = Dancer(np.asarray(take.follow_offsets, float), window(take.follow, t0))
    leader = Dancer(np.asarray(take.lead_offsets, float), window(take.lead, t0))
    for p in (follower_policy, leader_policy):
        if hasattr(p, "reset"):
            p.reset()
    n = HISTORY + steps + 1
    rec = {"positions": np.empty((n, feat.N_JOINTS, 3)), "rotations": np.empty((n, feat.N_JOINTS, 3, 3)),
           "root": np.empty((n, 2)), "heading": np.empty(n), "leader_positions": np.empty((n, feat.N_JOINTS, 3)),
           "leader_root": np.empty((n, 2)), "contacts": np.zeros((n, 2))}

    def record(i0, i1, src_lo):
        ft, lt = follower.track, leader.track
        for k in ("positions", "rotations", "root", "heading"):
            rec[k][i0:i1] = getattr(ft, k)[src_lo:NOW + 1]
        rec["leader_positions"][i0:i1] = lt.positions[src_lo:NOW + 1]
        rec["leader_root"][i0:i1] = lt.root[src_lo:NOW + 1]
        rec["contacts"][i1 - 1] = follower.contacts     # the follower's foot contacts, as it says

    record(0, HISTORY + 1, 0)
    for i in range(steps):
        t = t0 + i
        if leader_mode == "playback":
            leader.track = window(take.lead, t)
            bend_plan(leader.track, bend)
        else:
            steer_along_recording(leader, take.lead, t)
            bend_plan(leader.track, bend)
        now = np.array([NOW])
        heard = music_at(take.lead.beat, np.array([t]))   # the take's count, found in its footwork
        figure = take.figure(np.array([t]))              # the figure the recorded leader led
        xf = follower_input(leader.track, follower.track, now, figure, heard)[0]
        if isinstance(follower_policy, RecordingPolicy):
            follower_policy.seek(take.follow, t)
        of = np.asarray(follower_policy(xf, temperature, rng)["output"][0], np.float64)
        if leader_mode != "playback":
            xl = leader_input(follower.track, leader.track, now, figure, music=heard)[0]
            ol = np.asarray(leader_policy(xl, temperature, rng)["output"][0], np.float64)
            # Leader first, as rollout.finish_step does.
            if output_is_absurd(ol):
                reset_beside(leader, follower, start_pose["leader"])
            else:
                apply_output(leader, ol)
        if output_is_absurd(of):
            reset_beside(follower, leader, start_pose["follower"])
        else:
            apply_output(follower, of)
        if leader_mode == "playback":
            leader.track = window(take.lead, t + 1)
        record(HISTORY + 1 + i, HISTORY + 2 + i, NOW)
        if bar is not None:
            bar.update(1)
    rec.update(t0=t0, steps=steps, resets=follower.resets, leader_resets=leader.resets,
               beat=take.lead.beat[t0 - HISTORY:t0 + steps + 1])
    return rec


def recorded(take: EvalTake) -> dict:
    """The recording in the layout rollout() returns (the ground-truth reference)."""
    t0, steps = int(take.frames[0]), len(take.frames)
    sl = slice(t0 - HISTORY, t0 + steps + 1)
    return {"positions": take.follow.positions[sl], "rotations": take.follow.rotations[sl],
            "root": take.follow.root[sl], "heading": take.follow.heading[sl],
            "leader_positions": take.lead.positions[sl], "leader_root": take.lead.root[sl],
            "beat": take.lead.beat[sl], "t0": t0, "steps": steps, "resets": 0, "leader_resets": 0}


def as_track(r: dict) -> Track:
    return Track(r["positions"], r["rotations"], r["root"], r["heading"])


def latents(encoder, r: dict) -> np.ndarray:
    frames = np.arange(HISTORY + 1, HISTORY + r["steps"] + 1)   # the generated frames
    return encoder(M.windows(M.motion_features(as_track(r), frames)))


# The figure measures (figures.py) every run reports: pooled over the takes, then means over seeds
# with the worst seed beside them (mean_metrics).
FIGURE_KEYS = ["turns_per_min", "spin_frames", "body_motion", "travel", "recall", "precision", "direction"]
# The follower's rhythm (rhythm.py) beside the played-back leader, at the take's count found in its
# footwork (the count she hears): her footwork's pulse, her steps on the beat, and her motion beats
# within 0.1 s of the recorded leader's (together). Frame-weighted means over the takes.
RHYTHM_KEYS = ["pulse", "on_beat", "together"]


def run_metrics(runs: list[dict], refs: list[dict], encoder, ref_latents: np.ndarray,
                ranges: dict | None = None) -> dict:
    """Metrics of one run over all takes (frame-weighted means; FID and Diversity pooled). With
    the training takes' plausibility range (the manifest's), also the follower's plausibility:
    `implausible`, the share of frames with its body low, folded or split (plausibility.BODY_FLAGS),
    `angles_out`, and the worst second over the takes, since a mean pose error never shows a fall."""
    per, weights, lat, figs = [], [], [], []
    for r, g in zip(runs, refs):
        idx = np.arange(HISTORY + 1, HISTORY + r["steps"] + 1)
        local = feat.to_root_space_points(r["positions"][idx], r["root"][idx][:, None], r["heading"][idx][:, None])
        local_ref = feat.to_root_space_points(g["positions"][idx], g["root"][idx][:, None], g["heading"][idx][:, None])
        apart = np.linalg.norm(r["root"][idx] - r["leader_root"][idx], axis=-1)
        per.append({
            "mpjpe_cm": M.mpjpe_cm(local, local_ref),
            "root_error_m": float(np.linalg.norm(r["root"][idx] - g["root"][idx], axis=-1).mean()),
            "foot_skate_cm": M.foot_skate_cm(r["positions"][idx]),
            "jitter": M.jitter(r["positions"][idx]),
            "hand_distance": M.hand_distance(r["positions"][idx], r["leader_positions"][idx]),
            "distance_to_leader": float(apart.mean()),
            "divergence": float((apart > DIVERGED).mean()),
        })
        if ranges is not None:
            flags = P.frame_flags(r["positions"][idx], ranges)
            per[-1].update(implausible=float(P.body_flagged(flags).mean()),
                           angles_out=float(flags["angles_out"].mean()), worst_second=P.worst_second(flags))
        weights.append(len(idx))
        lat.append(latents(encoder, r))
        figs.append({**Fg.dancer(r["positions"][idx]), **Fg.against(r["positions"][idx], g["positions"][idx])})
        beat = r["beat"][idx]
        rh = R.rhythm(r["leader_positions"][idx], r["positions"][idx], beat, R.bpm_of(beat))
        per[-1].update(pulse=rh["follower_pulse"], on_beat=rh["follower_on_beat"], together=rh["together"])
    w = np.asarray(weights, float) / sum(weights)
    out = {k: float(sum(wi * p[k] for wi, p in zip(w, per))) for k in per[0]}
    if ranges is not None:
        out["worst_second"] = float(max(p["worst_second"] for p in per))   # worst over takes, not a mean
    lat = np.concatenate(lat)
    out["fid"] = M.fid(lat, ref_latents)
    out["diversity"] = M.diversity(lat)
    fig = Fg.summarize(figs)
    out.update({k: fig[k] for k in FIGURE_KEYS})
    out["resets"] = int(sum(r["resets"] for r in runs))
    out["leader_resets"] = int(sum(r["leader_resets"] for r in runs))
    return out


def mean_metrics(items: list[dict]) -> dict:
    """Means over seeds; the worst second stays the worst of them, and each figure measure also
    gets its lowest and highest seed (KEY_min, KEY_max): a mean alone hides a seed that never turns."""
    out = {k: float((np.max if k == "worst_second" else np.nanmean)([i[k] for i in items]))
           for k in items[0] if k not in ("seed", "temperature")}
    for k in FIGURE_KEYS + RHYTHM_KEYS:
        if k in items[0]:
            v = [i[k] for i in items]
            out[f"{k}_min"], out[f"{k}_max"] = float(np.nanmin(v)), float(np.nanmax(v))
    return out
