"""Training samples from the network's own rollouts: from wherever its own motion took it, do
what the recorded dancer did next.

Teacher-forced, every input a network sees holds its dancer's recorded past. At run time that past
is its own earlier outputs, and a follower that did not start a turn when the recorded one did
reads a history the recording never shows: nothing in training told it what to do there, so it
goes on stepping (the follower that continues a recorded turn but hardly ever starts one:
docs/results.md, "Salsa turns"). So, from epoch `TrainConfig.own_rollouts_from` on, every few epochs the
network dances short stretches of the training takes beside the played-back recorded partner (a
follower beside the recorded leader; a leader beside the recorded follower, his plan the recorded
path laid down from where he stands, as evaluation steers him), and each frame it reaches becomes
a training sample whose target is still the recorded next frame, read in the dancer's own root
space. This is DAgger with the recording as the expert, as scheduled sampling does it for
sequence models.

The couples come from PREPARED/train_tracks.npz (training.data.prepare writes it).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from ..data.led_figures import figure_spans
from ..data.prepared import TrainError
from ..mirror import features as feat
from ..mirror.features import HISTORY, Track
from ..mirror.music import music_at
from ..evaluation.evaluate_inputs import window
from ..evaluation.evaluate_rollouts import steer_along_recording
from ..mirror.rollout import NOW, Dancer, apply_output, output_is_absurd

FIELDS = ("positions", "rotations", "root", "heading", "beat")


@dataclass
class Couple:
    leader: Track
    follower: Track
    mirror: bool
    figures: np.ndarray          # [M, 3] (way, start, end): the figures both read (led_figures.figure_spans)


def load_couples(prepared: str) -> list[Couple]:
    path = Path(prepared) / "train_tracks.npz"
    if not path.exists():
        raise TrainError(f"{path} not found (a recipe with own rollouts dances beside the training couples): "
                         f"re-run `python -m training.data.prepare --prepared {prepared}`")
    with np.load(path) as z:
        n = sum(1 for k in z.files if k.endswith("_mirror"))
        out = []
        for i in range(n):
            lead, follow = (Track(*(z[f"{i}_{role}_{k}"] for k in FIELDS)) for role in ("leader", "follower"))
            out.append(Couple(lead, follow, bool(z[f"{i}_mirror"]), figure_spans(lead.positions, follow.positions)))
    return out


@dataclass
class Run:
    couple: Couple
    me: Dancer
    t: int          # the recorded frame the rollout is at
    steps: int      # steps left


def recorded_hands(recorded: Track, t: int, me: Track) -> np.ndarray:
    """[1, KEYS, 2, 3] the recorded hands' places at the future keys of frame t (in the recorded
    root space), less where his own hands are now (in his): the moves that take his hands there."""
    f = np.array([t])
    future = feat.hands_moves(recorded, f) + feat.to_root_space_points(
        recorded.positions[t][feat.HANDS], recorded.root[t], recorded.heading[t])[None, None]
    now = feat.to_root_space_points(me.positions[NOW][feat.HANDS], me.root[NOW], me.heading[NOW])
    return future - now[None, None]


def inputs_at(run: Run, role: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(input, recorded output, intention target) of a rollout at its frame: the input from its own
    track beside the recorded partner; the figure and the targets the recording's."""
    c, t, now = run.couple, run.t, np.array([NOW])
    heard = music_at(c.leader.beat, np.array([t]))    # the recorded take's count, where the recording is
    figure = feat.figure_block(c.figures, np.array([t]))
    if role == "follower":
        partner, recorded = window(c.leader, t), c.follower
        x = feat.follower_input(partner, run.me.track, now, figure, heard)[0]
    else:
        partner, recorded = window(c.follower, t), c.leader
        steer_along_recording(run.me, recorded, t)   # his plan: the recorded path, laid from where he stands
        # His hands plan: where the recorded hands went over the next second, from where his are.
        plan = feat.hands_plan_block(recorded_hands(recorded, t, run.me.track), 1)
        x = feat.leader_input(partner, run.me.track, now, figure, plan, heard)[0]
    y = feat.output_features(recorded, np.array([t]))[0]
    j = feat.intention_target(partner, run.me.track, now)[0]
    return x, y, j


@torch.no_grad()
def own_rollout_samples(step, couples: list[Couple], offsets: np.ndarray, role: str, every: int,
                        horizon: int, temperatures: tuple[float, ...], gen: torch.Generator) -> dict[str, np.ndarray]:
    """Roll `step` (a StepModel on raw features) out for `horizon` frames from every `every`-th
    frame of each couple, all rollouts as one batch per step, at temperatures taken in turn. The
    first frame of each is the recording itself and is skipped; a rollout that produces absurd
    output ends there. Returns raw {"input", "output", "intention"} float32 and "mirror" bool."""
    runs: list[Run] = []
    for c in couples:
        side = c.follower if role == "follower" else c.leader
        last = side.frames - HISTORY - 2 - horizon
        for t0 in range(HISTORY + 1, last, every):
            runs.append(Run(c, Dancer(offsets[int(c.mirror)], window(side, t0)), t0, horizon))
    temps = torch.tensor([temperatures[i % len(temperatures)] for i in range(len(runs))], dtype=torch.float32)
    xs, ys, js, ms = [], [], [], []
    latent = step.cfg.channels * step.cfg.classes
    for k in range(horizon):
        live = [i for i, r in enumerate(runs) if r.steps > 0]
        if not live:
            break
        batch = [inputs_at(runs[i], role) for i in live]
        x = np.stack([b[0] for b in batch])
        if k > 0:
            xs.append(x); ys.append(np.stack([b[1] for b in batch])); js.append(np.stack([b[2] for b in batch]))
            ms.append(np.array([runs[i].couple.mirror for i in live]))
        noise = torch.rand(len(live), latent, generator=gen)
        out = np.empty((len(live), feat.OUTPUT_SIZE))
        for temp in temperatures:
            rows = (temps[live] == temp).nonzero()[:, 0]
            if len(rows):
                out[rows.numpy()] = step(torch.from_numpy(x[rows.numpy()]).float(),
                                         torch.tensor([temp]), noise[rows])[0].double().numpy()
        for o, i in zip(out, live):
            r = runs[i]
            if output_is_absurd(o):
                r.steps = 0
                continue
            apply_output(r.me, o)
            r.t += 1
            r.steps -= 1
    if not xs:
        size = feat.INPUT_SIZES[role]
        return {"input": np.zeros((0, size), np.float32), "output": np.zeros((0, feat.OUTPUT_SIZE), np.float32),
                "intention": np.zeros((0, feat.INTENTION_SIZE), np.float32), "mirror": np.zeros(0, bool)}
    return {"input": np.concatenate(xs).astype(np.float32), "output": np.concatenate(ys).astype(np.float32),
            "intention": np.concatenate(js).astype(np.float32), "mirror": np.concatenate(ms)}
