"""python -m training.learning.train: intention predictor, then adversarial codebook matching.

    python -m training.learning.train --all              # every shipped model (follower, follower_ccm, leader)
    python -m training.learning.train --model follower   # one model (names in MODELS below)
    python -m training.learning.train --all --smoke      # tiny run for CI (< 2 min)
    torchrun --nproc_per_node 2 -m training.learning.train --model follower   # data parallel (DDP)

Reads the prepared arrays (--prepared, default runs/data); each model lives in --runs (default
runs/models) as NAME/: checkpoint.pt (resume with --resume), losses.png, history.json. Bad input
(no prepared data, feature sizes that do not match, a corrupt checkpoint) stops with a one-line
error instead of quietly starting over.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from tqdm import tqdm

from ..mirror import features as feat
from .distributed import (average_gradients, broadcast_parameters, pick_device, setup_distributed, stop_distributed,
                          wait_for_all)
from ..data.folders import add_folder
from ..evaluation.figures import HAND_RAISED
from ..evaluation.loss_plot import plot_history
from .models import CodebookMatching, Discriminator, IntentionPredictor, ModelConfig, StepModel, code_logits, sample_codes
from .distill import teacher_from_onnx
from .own_rollouts import load_couples, own_rollout_samples
from ..mirror.on_count import planned_turn
from ..data.prepared import (TrainError, load_mirror_flags, load_offsets, load_split, load_stats, normalize,
                             pose_error_cm)
from .runs import load_checkpoint, save_checkpoint
from .partner_losses import (INTERACTION_JOINTS, block_positions, decoded_positions, input_slices,
                             partner_terms, penetration_loss)
from ..mirror.skeleton import FPS


@dataclass
class TrainConfig:
    model: ModelConfig = field(default_factory=ModelConfig)
    intention_epochs: int = 20
    epochs: int = 40
    batch_size: int = 256
    lr: float = 1e-3
    weight_decay: float = 1e-4
    lambda_reconstruction: float = 1.0
    lambda_codebook: float = 10.0         # 12-epoch trials, val MSE (normalized): λC 1 -> 1.15 (codes unmatched), 10 -> 0.40, 100 -> 0.71 (decoder starved)
    lambda_generator: float = 0.01        # 0 switches the adversarial term off ("w/o GAN")
    intention_noise: float = 0.0          # std of noise on the frozen predictor's output (normalized)
    end_to_end: bool = False              # train the intention predictor jointly ...
    scheduled_sampling: bool = True       # ... feeding its prediction with probability epoch/E
    control_noise: float = 0.05           # leader: metres of noise on the 1 s control key
    control_rotation: float = 15.0        # leader: degrees of random turn of the control path
    # Terms on the decoded body (training/learning/partner_losses.py), in m^2 against normalized MSE.
    # Sizes: a 5 cm slide of a planted foot costs 30 * 0.0025 = 0.075, about half the final
    # reconstruction loss; penetration is rare in the recording, so its weight is larger.
    lambda_penetration: float = 0.0
    lambda_foot_contact: float = 0.0
    lambda_interaction: float = 0.0
    recorded_contacts: bool = False       # weight the foot-contact term by the recorded contacts
    # The foot-contact term skips samples whose recorded heading turns faster than this (degrees a
    # second; 0: none): in a pivot the planted foot turns under the dancer, and a decoder that
    # cannot yet place it exactly learns that not turning is the cheapest way to keep it still.
    contact_spare_turning: float = 0.0
    # Follower: this share of samples has the partner's whole window moved closer (a leader
    # steered into the follower, which the recording never shows), penalized by penetration
    # with its own weight; the interaction term skips them (their recorded distances are moot).
    proximity_share: float = 0.0
    lambda_proximity: float = 0.0
    # Std of Gaussian noise (in normalized units) on the dancer's own past and pose in the input,
    # the target staying the recorded next frame: at run time those blocks are the model's own
    # earlier outputs, and a model that only ever saw recorded ones has never learnt to come back
    # from its own drift (a follower sinking to the floor and staying there).
    state_noise: float = 0.0
    # Share of samples whose decoder does not see the own state (decoder_state recipes only). A
    # decoder that always sees the current pose can predict the next one from it and leave the
    # code nearly unused, so the sampled code no longer varies the motion (the follower swayed on
    # the spot: Diversity 13 against the recording's 24). Hidden now and then, the pose has to be
    # carried by the code, which the decoder then keeps reading.
    state_dropout: float = 0.0
    # Train on the tempo copies too (prepare's train_tempo.npz): more varied samples, same steps.
    tempo_copies: bool = False
    # Weight of the samples where the follower's turn starts (turn_onsets) in the reconstruction
    # and codebook losses; 1 weighs every sample alike. The recorded follower turns 20-27 times a
    # minute, but a turn's first frames are few beside the frames that continue one, and a model
    # that reads its own history learns to continue turns far better than to start them.
    turn_weight: float = 1.0
    # Follower: weight of the turn onsets he does not lead with a raised hand (his higher hand stays
    # under figures.HAND_RAISED over the next second, read from her intention target); None weighs them as
    # turn_weight. The recorded follower completes a turn in 81 % of the 2.5 s windows in which his
    # hand goes up and in 24 % of the others (recorded_leads): weighing only the led starts asks her
    # to read his hand.
    unled_turn_weight: float | None = None
    # Leader: weight of the samples where his own turn starts (own_turn_onsets). The recorded leader turns 6-7 times a minute, in 10 of 12 takes; turn_weight only weighs
    # the moments he leads hers, and a leader who turns only beside a spinning partner turns in few seeds.
    own_turn_weight: float = 1.0
    # Leader: share of samples whose hands plan (features.hands_plan_block: where his recorded
    # hands went over the next second) is hidden, as when nobody asks. Shown, he learns to take his
    # hands where the plan says, which is how a request raises his lead hand; 1: never shown.
    hands_plan_dropout: float = 1.0
    # Samples from the network's own rollouts beside the recorded partner, the target still the
    # recorded next frame (own_rollouts.py): from matching epoch `own_rollouts_from` on (None:
    # never), made anew every `own_rollouts_every` epochs with the network as it is then, each
    # rollout `own_rollouts_horizon` frames long, one starting every `own_rollouts_stride` frames
    # of the training couples (as recorded and mirrored), at the temperatures taken in turn.
    own_rollouts_from: int | None = None
    own_rollouts_every: int = 2
    own_rollouts_horizon: int = 8
    own_rollouts_stride: int = 4
    own_rollouts_temperatures: tuple[float, ...] = (0.5, 1.0)
    # Distillation (distill.py): an ONNX step model of this role and code size, a wider network
    # as export wrote it. Each batch then also asks the student's predictor for the teacher's
    # intention, its input encoder for the teacher's code distribution (KL per channel) and its
    # decoder for what the teacher's decoder makes of a code drawn from it, at the weight of the
    # reconstruction, beside the recipe's own terms (at 3 the leader danced no nearer his
    # teacher: docs/measurements.md, the tried table).
    teacher: str | None = None
    seed: int = 1


# The follower's network. 24 code channels: at 8 the decoder's reconstruction from even the
# target code is the bulk of the error (5.7 of 5.8 cm validation MPJPE for ours and CCM alike),
# so better matching has nothing to win; at 24 the reconstruction drops to 4.6 cm and the wrong
# channels cost 0.3-0.5 cm, the part the intention can reduce (it does on the validation take
# for three seeds; on the test takes ours and CCM tie: docs/results.md, "Latent size").
FOLLOWER = ModelConfig(channels=24)
# Weights of the terms on the decoded body (partner_losses.py; docs/results.md, "Partner terms",
# measured on steered duets):
# - penetration 3000: at 100 the follower came closer than without the terms (the interaction term
#   draws it in) and its torso passed through the leader's in 10.5 % of steered frames;
# - foot contact 100, weighted by the recorded contacts: weighted by the decoded contacts, 30 made
#   the feet stick and the motion stiff (free-running FID 193 against 97 without the terms), 10
#   kept FID (111) but hardly reduced foot skate; the recorded contacts are what the decoded ones
#   learn anyway, and at 100 they cut the follower's steered slide by a third (skate in contact
#   3.45 against 4.94 cm without the term) while FID stays 101.
PARTNER = dict(lambda_penetration=3000.0, lambda_foot_contact=100.0, lambda_interaction=10.0,
               recorded_contacts=True)
# Proximity augmentation (TrainConfig.proximity_share): the recording never shows a leader
# walking into the follower, so the penetration term alone never taught the follower to make
# room for a steered leader (its torso passed through the leader's in 10.3 % of steered frames,
# 5.3 % with a quarter of the samples moved closer at weight 100; docs/results.md).
PROXIMITY = dict(proximity_share=0.25, lambda_proximity=100.0)

# Ours and its baseline, CCM (the same network without the intention step, all else alike), from
# which the shipped pair is made (steady, then the settings in MODELS).
OURS = TrainConfig(model=FOLLOWER, intention_noise=0.3, **PARTNER, **PROXIMITY)
CCM = TrainConfig(model=replace(FOLLOWER, intention=False), **PARTNER, **PROXIMITY)
# The leader's network reads his control, the figure and the hands plan beside her (features.py).
# His penetration term at 100: at 3000 the steered duet's numbers did not change.
LEADER = TrainConfig(model=ModelConfig(role="leader", input_size=feat.LEADER_INPUT_SIZE),
                     lambda_penetration=100.0, lambda_interaction=10.0)

STATE_NOISE = 0.2   # normalized units: about 1 cm on the hip height, 3-4 cm on a hand, 0.1 m/s on a velocity
# With the pose beside the code the validation MPJPE is 2.4 cm (follower) and 1.9 cm (leader) after
# 20 matching epochs, against 5.2 cm after 40 decoded from the code alone (docs/plausibility.md).
STEADY_EPOCHS = 20


def steady(cfg: TrainConfig) -> TrainConfig:
    """A recipe whose decoder reads the current pose beside the code, trained with noise on the
    dancer's own state (docs/plausibility.md). Decoded from its code alone, the leader held one
    body shape in 52.7 % of steered frames and the follower lay on the floor for a second or more
    in 14 of 100 steered minutes; with it, no frozen body and no fall in 100."""
    return replace(cfg, model=replace(cfg.model, decoder_state=True), state_noise=STATE_NOISE,
                   epochs=STEADY_EPOCHS)


# The shipped models (`--all`), then the paper's ablations that docs/results.md ("The paper's
# tables on this data") compares them with: bash scripts/evaluate_all.sh trains those and measures
# all. What was tried and not shipped is a row of docs/results.md's tried table, whose commit
# holds its recipe.
WIDE = {
    # Her intention predictor fits training frames better than new ones (MSE 0.14 vs 0.23): noise
    # of the size of that gap keeps the encoders from trusting its training-set accuracy, which
    # buys FID and Diversity on the test takes (docs/results.md, w/o intention noise).
    # Her decoder keeps reading its code with the state hidden from it in half the samples
    # (TrainConfig.state_dropout): as varied as the recording against the recorded leader, and the
    # page's upright guard (training/mirror/guard.py) catches her rare falls (docs/plausibility.md).
    # Her own rollouts (own_rollouts.py: 8 frames from every 4th frame, made anew every 2 epochs
    # from epoch 10) and her turn starts weighed 4x: beside the played-back recorded leader she
    # turns 25.9 times a minute (the recording: 25.9; 11.5 without) with FID 82 (118), and beside our
    # steered leader none of 20 seeds sinks at variety 0.35-0.5 (5 of 20 at 0.5 without), so the
    # page runs her at 0.5 (docs/results.md, "Salsa turns").
    # The tempo copies: she hears the music (features' "music" block) and dances on the count from
    # 150 to 200 beats a minute (docs/music.md).
    "follower": replace(steady(OURS), state_dropout=0.5, turn_weight=4.0, own_rollouts_from=10, tempo_copies=True),
    # The baseline by the same recipe, so that the comparison stays fair.
    "follower_ccm": replace(steady(CCM), state_dropout=0.5, turn_weight=4.0, own_rollouts_from=10, tempo_copies=True),
    # Both dancers read the figure being led (features.figure_block: her turns as the recording
    # labels them, training/data/led_figures.py; at run time the visitor's and his own,
    # rollout.Figures), always shown. The leader also reads the hands plan
    # (features.hands_plan_block: where his hands go over the next second), hidden in half the
    # samples as when nobody plans: a figure raises his lead hand through it (rollout.hands_input).
    # His decoder sees its own state in half the samples and he trains on his own rollouts (his plan
    # the recorded path laid from where he stands), as the followers: he dances (steered, body
    # motion 0.54 m/s against 0.33 without, the recording 0.83), and the page's upright guard keeps
    # him up. Training seed 2: how steadily a leader dances beside the followers depends on it (100
    # steered seeds with a dancer's hips or head low, or feet wide: seed 1, 3 seconds with the
    # contact layer; seed 2 none but 1 of the CCM follower; seed 3, 8 and 7).
    # His foot-contact term is the followers' (100 on the recorded contacts), sparing the samples
    # where his recorded heading turns faster than 120 degrees a second (contact_spare_turning): his
    # steered skate in contact is 1.28x the recording's (2.01x at 30 on his decoded contacts), and
    # nobody steering he turns 9.5 times a minute (0.82x) within 1.47 m of his spot. Without the
    # sparing he stopped turning (0.7 a minute nobody steering; at 300, none); at 30 on the recorded
    # contacts he had a bad second in 15 of 100 steered seeds (docs/results.md, "His feet").
    "leader": replace(steady(LEADER), hands_plan_dropout=0.5, state_dropout=0.5,
                      own_rollouts_from=10, lambda_foot_contact=100.0, recorded_contacts=True,
                      contact_spare_turning=120.0, tempo_copies=True, seed=2),
}
# The teachers: the wide networks above as trained by their recipe (runs "follower_wide" and so on)
# and exported, kept beside the code because distilling needs them and a retrain of a wide one
# is not the same network twice (docs/training.md).
TEACHERS = "models/teacher"


def distilled(name: str) -> TrainConfig:
    """The recipe WIDE[name] at width 256 (its intention predictor 128), distilled from the wide
    network's shipped file. Trained from the recording alone at that width the leader stopped
    turning and a request stopped making her turn; distilled they dance as the wide pair at about
    half its step (docs/measurements.md, "The step")."""
    cfg = WIDE[name]
    return replace(cfg, model=replace(cfg.model, hidden=256, intention_hidden=128),
                   teacher=f"{TEACHERS}/{name}.onnx")


MODELS = {
    # The shipped three, distilled.
    **{name: distilled(name) for name in WIDE},
    # Their teachers' recipes: what crossval trains in each fold (a fold's teacher would have to
    # be trained first), and how a teacher is remade (export --runs R --models DIR, then copy
    # DIR/NAME_wide.onnx to models/teacher/NAME.onnx).
    **{f"{name}_wide": cfg for name, cfg in WIDE.items()},
    # The paper's ablations, on the recipe without the partner terms (docs/results.md, "The paper's
    # tables on this data"): a smaller follower (hidden 256), CCM with three times the code channels
    # (CCM (L)), no adversarial term (w/o GAN), no noise on the intention, and the intention
    # predictor trained jointly with (and without) scheduled sampling.
    "follower_small": TrainConfig(model=replace(FOLLOWER, hidden=256, intention_hidden=128), intention_noise=0.3),
    "follower_ccm_large": TrainConfig(model=replace(FOLLOWER, intention=False, channels=3 * FOLLOWER.channels)),
    "follower_no_gan": TrainConfig(model=FOLLOWER, lambda_generator=0.0, intention_noise=0.3),
    "follower_no_intention_noise": TrainConfig(model=FOLLOWER),
    "follower_end_to_end": TrainConfig(model=FOLLOWER, end_to_end=True),
    "follower_end_to_end_no_ss": TrainConfig(model=FOLLOWER, end_to_end=True, scheduled_sampling=False),
}
SHIPPED = ["follower", "follower_ccm", "leader"]


# ---------------------------------------------------------------- data

def augment_control(x: torch.Tensor, cfg: TrainConfig, gen: torch.Generator) -> torch.Tensor:
    """Leader only: turn and jitter the control path (raw features) so that a steered path that
    the recording never took still reads as a plausible intention."""
    sl = feat.block_slices(feat.LEADER_INPUT_LAYOUT)["control"]
    keys = x[:, sl].reshape(-1, feat.KEYS, 4).clone()
    b = keys.shape[0]
    a = (torch.rand(b, 1, generator=gen) * 2 - 1) * math.radians(cfg.control_rotation)
    c, s = torch.cos(a), torch.sin(a)
    for i in (0, 2):   # (x, z) position and (x, z) forward both turn about the root
        px, pz = keys[..., i].clone(), keys[..., i + 1].clone()
        keys[..., i], keys[..., i + 1] = c * px + s * pz, -s * px + c * pz
    ramp = torch.arange(1, feat.KEYS + 1) / feat.KEYS
    keys[..., :2] += torch.randn(b, feat.KEYS, 2, generator=gen) * cfg.control_noise * ramp[None, :, None]
    x = x.clone()
    x[:, sl] = keys.reshape(b, -1)
    return x


def hide_block(x: torch.Tensor, block: str, share: float, gen: torch.Generator) -> torch.Tensor:
    """Leader inputs (raw) -> a copy with one block zeroed in `share` of the samples: the hands
    plan (no plan)."""
    sl = feat.block_slices(feat.LEADER_INPUT_LAYOUT)[block]
    hidden = torch.rand(len(x), generator=gen) < share
    x = x.clone()
    x[hidden, sl] = 0.0
    return x


PROXIMITY_HIP_DISTANCE = (0.15, 0.45)   # m: where a moved partner's hip ends up from the own hip


def move_partner_closer(x: torch.Tensor, share: float, gen: torch.Generator) -> tuple[torch.Tensor, torch.Tensor]:
    """Follower inputs (raw) -> a copy where `share` of the samples have every partner position
    (trajectory keys, key joints, pose) shifted horizontally toward the own hip, so the hips end
    up PROXIMITY_HIP_DISTANCE apart; directions and velocities stay. Returns (x, moved mask)."""
    sl = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)
    b = len(x)
    partner_hip = x[:, sl["partner_pose"]].reshape(b, feat.N_JOINTS, 12)[:, 0, [0, 2]]
    own_hip = x[:, sl["self_pose"]].reshape(b, feat.N_JOINTS, 12)[:, 0, [0, 2]]
    v = own_hip - partner_hip
    dist = v.norm(dim=-1).clamp_min(1e-6)
    lo, hi = PROXIMITY_HIP_DISTANCE
    target = lo + (hi - lo) * torch.rand(b, generator=gen)
    moved = (torch.rand(b, generator=gen) < share) & (dist > target)
    shift = torch.where(moved[:, None], v / dist[:, None] * (dist - target)[:, None], torch.zeros_like(v))
    x = x.clone()
    for block, width, xz in (("partner_trajectory_past", 4, (0, 1)), ("partner_trajectory_future", 4, (0, 1)),
                             ("partner_key_joints_past", 3, (0, 2)), ("partner_pose", 12, (0, 2))):
        part = x[:, sl[block]].reshape(b, -1, width)
        part[..., xz[0]] += shift[:, None, 0]
        part[..., xz[1]] += shift[:, None, 1]
        x[:, sl[block]] = part.reshape(b, -1)
    return x, moved


ONSET_FUTURE_DEGREES = 180.0   # the dancer's own heading turns this much over the next second ...
ONSET_PAST_DEGREES = 90.0      # ... after turning less than this over the last one


def key_heading_change(keys: np.ndarray, now_last: bool) -> np.ndarray:
    """Trajectory keys [N, K, 4] in root space -> degrees turned from the first key to the last,
    the root frame itself (heading 0) added at the end (past keys) or the start (future keys).
    Summed key to key, so a spin of more than 180 degrees is counted whole."""
    h = np.arctan2(keys[..., 2], keys[..., 3])
    zero = np.zeros_like(h[:, :1])
    h = np.concatenate([h, zero] if now_last else [zero, h], 1)
    return np.degrees(np.angle(np.exp(1j * np.diff(h, axis=1))).sum(1))


def turn_onsets(x_raw: np.ndarray, y_raw: np.ndarray, role: str = "follower") -> np.ndarray:
    """Samples (raw input and output) -> bool [N]: the dancer's turn starts here. It turns at
    least ONSET_FUTURE_DEGREES over the next second and turned less than ONSET_PAST_DEGREES over
    the last, read from its own path (12 % of the follower's samples)."""
    return own_turn_onsets(x_raw, y_raw, role)


def own_turn_onsets(x_raw: np.ndarray, y_raw: np.ndarray, role: str) -> np.ndarray:
    """Samples (raw input and output) -> bool [N]: the dancer's own turn starts here, read from
    the dancer's own path (the same thresholds as turn_onsets)."""
    layout = feat.LEADER_INPUT_LAYOUT if role == "leader" else feat.FOLLOWER_INPUT_LAYOUT
    si = feat.block_slices(layout)
    past = key_heading_change(x_raw[:, si["self_trajectory_past"]].reshape(len(x_raw), feat.KEYS, 4), True)
    future = planned_turn(y_raw)
    return (np.abs(future) >= ONSET_FUTURE_DEGREES) & (np.abs(past) < ONSET_PAST_DEGREES)


def own_onset_weights(cfg: "TrainConfig", x_raw: np.ndarray, y_raw: np.ndarray, role: str) -> torch.Tensor:
    """Per-sample weights [N]: own_turn_weight where the leader's own turn starts, else 1."""
    w = torch.ones(len(x_raw))
    if role == "leader" and cfg.own_turn_weight != 1.0:
        w[torch.from_numpy(own_turn_onsets(x_raw, y_raw, role))] = cfg.own_turn_weight
    return w


def led_onsets(intention_raw: np.ndarray) -> np.ndarray:
    """A follower's raw intention targets [N, 90] -> bool [N]: the leader's higher hand goes above
    HAND_RAISED (m over the floor, figures.py: the recorded lead) at some key of the next second."""
    keys = intention_raw[:, :feat.INTENTION_SIZE].reshape(len(intention_raw), feat.KEYS, feat.N_KEY_JOINTS, 3)
    return keys[:, :, 1:3, 1].max((1, 2)) > HAND_RAISED


def onset_weights(cfg: "TrainConfig", x_raw: np.ndarray, y_raw: np.ndarray, j_raw: np.ndarray,
                  role: str) -> torch.Tensor:
    """Per-sample weights [N]: 1, turn_weight where a turn starts (turn_onsets), and for a follower
    with unled_turn_weight that weight where a turn starts that his hand does not lead (led_onsets)."""
    w = torch.ones(len(x_raw))
    onsets = turn_onsets(x_raw, y_raw, role)
    w[torch.from_numpy(onsets)] = cfg.turn_weight
    if cfg.unled_turn_weight is not None and role != "leader":
        w[torch.from_numpy(onsets & ~led_onsets(j_raw))] = cfg.unled_turn_weight
    return w


# ---------------------------------------------------------------- training

def cosine(step: int, total: int, lr: float) -> float:
    return lr * 0.5 * (1 + math.cos(math.pi * min(step, total) / max(total, 1)))


def saved_config(config: dict | None) -> dict | None:
    """A checkpoint's recipe as asdict(TrainConfig) gives it: model fields the checkpoint lacks
    (ModelConfig.decoder_music) take their defaults, which are what it was trained with."""
    if not config or "model" not in config:
        return config
    return {**config, "model": asdict(ModelConfig(**config["model"]))}


def train_model(name: str, cfg: TrainConfig, data: str, out: str, device: str = "cpu",
                resume: bool = False, quiet: bool = False, rank: int = 0, world: int = 1,
                init_from: str | None = None) -> dict:
    torch.manual_seed(cfg.seed)
    np.random.seed(cfg.seed)
    role = cfg.model.role
    train = load_split(data, "train", role, cfg.tempo_copies)
    val = load_split(data, "validation", role)
    stats = load_stats(data, role)
    run = Path(out) / name
    run.mkdir(parents=True, exist_ok=True)
    ckpt_path = run / "checkpoint.pt"

    xr = torch.from_numpy(train["input"]).float()          # raw, for leader augmentation
    partner_weights = {"penetration": cfg.lambda_penetration, "foot_contact": cfg.lambda_foot_contact,
                       "interaction": cfg.lambda_interaction}
    if any(partner_weights.values()) or cfg.own_rollouts_from is not None:
        offsets = load_offsets(data, role, device)
    mirrored = torch.from_numpy(load_mirror_flags(data, cfg.tempo_copies)).long()
    couples = load_couples(data) if cfg.own_rollouts_from is not None else []
    y, j = normalize(train["output"], stats, "output"), normalize(train["intention"], stats, "intention")
    sample_weight = (onset_weights(cfg, train["input"], train["output"], train["intention"], role)
                     if cfg.turn_weight != 1.0 else torch.ones(len(xr)))
    own_weight = own_onset_weights(cfg, train["input"], train["output"], role)
    weighted = cfg.turn_weight != 1.0 or cfg.own_turn_weight != 1.0
    xv, yv, jv = (normalize(val[k], stats, k) for k in ("input", "output", "intention"))
    mcfg = cfg.model
    predictor = IntentionPredictor(mcfg).to(device)
    matching = CodebookMatching(mcfg).to(device)
    disc = Discriminator(mcfg).to(device)
    opt_p = torch.optim.AdamW(predictor.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    gen_params = list(matching.parameters()) + (list(predictor.parameters()) if cfg.end_to_end else [])
    opt_g = torch.optim.AdamW(gen_params, lr=cfg.lr, weight_decay=cfg.weight_decay)
    opt_d = torch.optim.AdamW(disc.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    history = {"intention_train": [], "intention_val": [], "reconstruction": [], "codebook": [], "own_rollout_samples": [],
               "generator": [], "discriminator": [], "val_mse": [], "val_codebook": [],
               "val_mpjpe_cm": [], **{k: [] for k, w in partner_weights.items() if w},
               **({"proximity": []} if cfg.lambda_proximity else {}),
               **({"distill_codes": [], "distill_decoder": []} if cfg.teacher else {})}
    stage, epoch, seconds = "intention", 0, 0.0
    if resume and ckpt_path.exists():
        ck = load_checkpoint(ckpt_path)
        if saved_config(ck.get("config")) != asdict(cfg):
            raise TrainError(f"{ckpt_path}: saved with another configuration; use a new --out or delete it")
        predictor.load_state_dict(ck["predictor"]); matching.load_state_dict(ck["matching"])
        disc.load_state_dict(ck["disc"]); opt_p.load_state_dict(ck["opt_p"])
        opt_g.load_state_dict(ck["opt_g"]); opt_d.load_state_dict(ck["opt_d"])
        history, stage, epoch, seconds = ck["history"], ck["stage"], ck["epoch"], ck["seconds"]
        if rank == 0 and not quiet:
            print(f"{name}: resumed at {stage} epoch {epoch}")
    elif init_from is not None:
        # A fine-tune: the weights of another run (same sizes), its intention predictor kept as
        # it is; this recipe's matching epochs train on with fresh optimizers.
        ck = load_checkpoint(Path(init_from) / "checkpoint.pt")
        if ck.get("stage") not in ("matching", "done") or saved_config(ck["config"])["model"] != asdict(cfg.model):
            raise TrainError(f"{init_from}: not a finished run of the same model sizes; cannot fine-tune from it")
        predictor.load_state_dict(ck["predictor"]); matching.load_state_dict(ck["matching"])
        disc.load_state_dict(ck["disc"])
        stage = "matching"
        if rank == 0 and not quiet:
            print(f"{name}: fine-tuning {init_from} ({ck['history']['val_mse'][-1]:.4f} val mse there)")
    elif ckpt_path.exists() and not resume and rank == 0 and not quiet:
        print(f"{name}: {ckpt_path} exists; training from scratch over it (use --resume to continue)")
    broadcast_parameters([predictor, matching, disc], world)
    teacher = None
    if cfg.teacher is not None:
        teacher = teacher_from_onnx(cfg.teacher, mcfg).to(device)
        for p in teacher.parameters():
            p.requires_grad_(False)
        if (teacher.input_mean.to(device) != stats["input_mean"].to(device)).any():
            raise TrainError(f"{cfg.teacher}: normalized with other prepared data than {data}")
        if rank == 0 and not quiet:
            print(f"{name}: distilled from {cfg.teacher} (width {teacher.cfg.hidden})")

    gen = torch.Generator().manual_seed(cfg.seed + 1000 * rank)
    n = len(xr)
    # An epoch is as many steps as one pass over the samples at the recorded tempo: with tempo
    # copies each epoch draws that many from the larger pool, so a recipe with them costs the
    # same time and is compared at the same number of steps.
    recorded = len(load_mirror_flags(data))
    steps_per_epoch = max(1, recorded // (cfg.batch_size * world))

    def batches(epoch_seed):
        perm = torch.randperm(n, generator=torch.Generator().manual_seed(cfg.seed * 7919 + epoch_seed))
        perm = perm[rank::world]   # each process its own shard of one shared shuffle
        for s in range(steps_per_epoch):
            idx = perm[s * cfg.batch_size:(s + 1) * cfg.batch_size]
            if len(idx):
                yield idx

    slices = feat.block_slices(feat.LEADER_INPUT_LAYOUT if role == "leader" else feat.FOLLOWER_INPUT_LAYOUT)
    own = torch.cat([torch.arange(slices[k].start, slices[k].stop)
                     for k in ("self_trajectory_past", "self_key_joints_past", "self_pose")])

    def inputs(idx, proximity: bool = False):
        """Normalized inputs of a batch as the networks read them (with state noise), which samples
        had their partner moved closer, and the inputs without noise (what the body terms compare
        the decoded pose with: the pose the dancer really was in)."""
        x, moved = xr[idx], None
        if role == "leader" and cfg.control_noise + cfg.control_rotation > 0:
            x = augment_control(x, cfg, gen)
        if role == "leader" and cfg.hands_plan_dropout > 0:
            x = hide_block(x, "hands_plan", cfg.hands_plan_dropout, gen)
        if proximity and role == "follower" and cfg.proximity_share > 0:
            x, moved = move_partner_closer(x, cfg.proximity_share, gen)
        clean = ((x - stats["input_mean"]) / stats["input_std"]).to(device)
        if cfg.state_noise == 0:
            return clean, moved, clean
        noisy = clean.clone()
        noisy[:, own] += cfg.state_noise * torch.randn(len(noisy), len(own), generator=gen).to(device)
        return noisy, moved, clean

    def save(stage_, epoch_):
        if rank == 0:
            save_checkpoint(ckpt_path, {
                "config": asdict(cfg), "name": name, "stage": stage_, "epoch": epoch_,
                "seconds": seconds, "history": history, "predictor": predictor.state_dict(),
                "matching": matching.state_dict(), "disc": disc.state_dict(),
                "opt_p": opt_p.state_dict(), "opt_g": opt_g.state_dict(), "opt_d": opt_d.state_dict()})

    # Stage 1: the intention predictor alone (MSE), then frozen. End-to-end variants skip it.
    if mcfg.intention and not cfg.end_to_end and stage == "intention":
        total = cfg.intention_epochs * steps_per_epoch
        while epoch < cfg.intention_epochs:
            t0 = time.time()
            predictor.train()
            bar = tqdm(batches(epoch), total=steps_per_epoch, disable=quiet or rank > 0,
                       desc=f"{name} intention {epoch + 1}/{cfg.intention_epochs}", leave=False)
            losses = []
            for i, idx in enumerate(bar):
                for g in opt_p.param_groups:
                    g["lr"] = cosine(epoch * steps_per_epoch + i, total, cfg.lr)
                x = inputs(idx)[0]
                if teacher is None:
                    target = j[idx].to(device)
                else:
                    with torch.no_grad():
                        target = teacher.predictor(x)
                loss = F.mse_loss(predictor(x), target)
                opt_p.zero_grad(); loss.backward(); average_gradients([predictor], world); opt_p.step()
                losses.append(loss.item())
                bar.set_postfix(mse=f"{np.mean(losses[-50:]):.4f}")
            predictor.eval()
            with torch.no_grad():
                v = F.mse_loss(predictor(xv.to(device)), jv.to(device)).item()
            history["intention_train"].append(float(np.mean(losses)))
            history["intention_val"].append(v)
            epoch += 1
            seconds += time.time() - t0
            if rank == 0 and not quiet:
                print(f"{name} intention {epoch}/{cfg.intention_epochs}  train {np.mean(losses):.4f}  val {v:.4f}")
            save("intention", epoch)
        stage, epoch = "matching", 0
        save(stage, epoch)
    elif stage == "intention":
        stage, epoch = "matching", 0

    # Stage 2: codebook matching (+ adversarial term), intention predictor frozen.
    if mcfg.intention and not cfg.end_to_end:
        predictor.eval()
        for p in predictor.parameters():
            p.requires_grad_(False)
    total = cfg.epochs * steps_per_epoch
    bce = F.binary_cross_entropy_with_logits
    # Raw features back from normalized ones, for the terms on the decoded body (set up once).
    scale = {k: (stats[f"{k}_std"].to(device).float(), stats[f"{k}_mean"].to(device).float()) for k in ("input", "output")}
    raw = lambda t, k: t * scale[k][0] + scale[k][1]
    recorded_n = n                 # the prepared samples; own rollouts' samples follow them
    made_at = None                 # the epoch whose network danced the rollouts held now
    while epoch < cfg.epochs:
        t0 = time.time()
        start = cfg.own_rollouts_from
        if start is not None and epoch >= start and (made_at is None or epoch - made_at >= cfg.own_rollouts_every):
            step_model = StepModel(mcfg, predictor if mcfg.intention else None, matching, stats).eval()
            rolled = own_rollout_samples(step_model, couples, offsets.cpu().double().numpy(), role,
                                      cfg.own_rollouts_stride, cfg.own_rollouts_horizon,
                                      cfg.own_rollouts_temperatures, gen)
            xr = torch.cat([xr[:recorded_n], torch.from_numpy(rolled["input"])])
            y = torch.cat([y[:recorded_n], normalize(rolled["output"], stats, "output")])
            j = torch.cat([j[:recorded_n], normalize(rolled["intention"], stats, "intention")])
            w_own = (onset_weights(cfg, rolled["input"], rolled["output"], rolled["intention"], role)
                     if cfg.turn_weight != 1.0 else torch.ones(len(rolled["input"])))
            sample_weight = torch.cat([sample_weight[:recorded_n], w_own])
            own_weight = torch.cat([own_weight[:recorded_n],
                                    own_onset_weights(cfg, rolled["input"], rolled["output"], role)])
            mirrored = torch.cat([mirrored[:recorded_n], torch.from_numpy(rolled["mirror"]).long()])
            n, made_at = len(xr), epoch
            history["own_rollout_samples"].append(len(w_own))
            if rank == 0 and not quiet:
                print(f"{name} own rollouts at epoch {epoch}: {len(w_own)} samples beside {recorded_n} recorded")
        matching.train(); disc.train()
        if cfg.end_to_end:
            predictor.train()
        bar = tqdm(batches(10_000 + epoch), total=steps_per_epoch, disable=quiet or rank > 0,
                   desc=f"{name} matching {epoch + 1}/{cfg.epochs}", leave=False)
        sums = {"reconstruction": [], "codebook": [], "generator": [], "discriminator": [],
                **({"distill_codes": [], "distill_decoder": []} if teacher is not None else {}),
                **{k: [] for k, w in partner_weights.items() if w}, **({"proximity": []} if cfg.lambda_proximity else {})}
        p_pred = epoch / cfg.epochs   # scheduled sampling: share of predicted intentions
        for i, idx in enumerate(bar):
            lr = cosine(epoch * steps_per_epoch + i, total, cfg.lr)
            for o in (opt_g, opt_d):
                for g in o.param_groups:
                    g["lr"] = lr
            (x, moved, x_clean), yb = inputs(idx, proximity=True), y[idx].to(device)
            intention, extra = None, 0.0
            if mcfg.intention:
                if cfg.end_to_end:
                    pred = predictor(x)
                    extra = F.mse_loss(pred, j[idx].to(device))
                    if cfg.scheduled_sampling:
                        use = (torch.rand(len(idx), 1, generator=gen) < p_pred).to(device)
                        intention = torch.where(use, pred, j[idx].to(device))
                    else:
                        intention = pred
                else:
                    with torch.no_grad():
                        intention = predictor(x)
                        if cfg.intention_noise > 0:
                            intention = intention + cfg.intention_noise * torch.randn(
                                intention.shape, generator=gen).to(device)
            state_keep = None
            if mcfg.decoder_state and cfg.state_dropout > 0:
                state_keep = (torch.rand(len(idx), 1, generator=gen) >= cfg.state_dropout).float().to(device)
            recon, s, s_hat, code, code_hat = matching(x, yb, intention, state_keep=state_keep)
            if not weighted:   # the recipes before turn_weight, bit for bit
                l_r, l_c = F.mse_loss(recon, yb), F.mse_loss(code, code_hat)
            else:
                w = sample_weight[idx].clone()
                w = torch.maximum(w, own_weight[idx])   # his own weigh more always
                w = w.to(device)[:, None]
                w = w / w.mean()
                l_r, l_c = (w * (recon - yb) ** 2).mean(), (w * (code - code_hat) ** 2).mean()
            loss = cfg.lambda_reconstruction * l_r + cfg.lambda_codebook * l_c + extra
            if teacher is not None:
                l_kl, l_dec = distill_terms(teacher, matching, x, intention)
                loss = loss + l_kl + l_dec
                sums["distill_codes"].append(l_kl.item()); sums["distill_decoder"].append(l_dec.item())
            if any(partner_weights.values()):
                keep = slice(None) if moved is None else ~moved.to(device)   # recorded relations only
                off = offsets[mirrored[idx]]
                terms = partner_terms(raw(recon[keep], "output"), raw(yb[keep], "output"), raw(x_clean[keep], "input"),
                                      off[keep], role, cfg.recorded_contacts,
                                      INTERACTION_JOINTS,
                                      math.radians(cfg.contact_spare_turning) / FPS)
                for k, w in partner_weights.items():
                    if w:
                        loss = loss + w * terms[k]
                        sums[k].append(terms[k].item())
                if moved is not None and cfg.lambda_proximity > 0 and moved.any():
                    m = moved.to(device)
                    me = decoded_positions(raw(recon[m], "output"), off[m])
                    l_p = penetration_loss(me, block_positions(raw(x_clean[m], "input"), input_slices(role)["partner_pose"]))
                    loss = loss + cfg.lambda_proximity * l_p
                    sums["proximity"].append(l_p.item())
            l_g = torch.zeros(())
            if cfg.lambda_generator > 0:
                # Discriminator step on detached logits, then the generator term for the encoders.
                d_real, d_fake = disc(s.detach()), disc(s_hat.detach())
                l_d = bce(d_real, torch.ones_like(d_real)) + bce(d_fake, torch.zeros_like(d_fake))
                opt_d.zero_grad(); l_d.backward(); average_gradients([disc], world); opt_d.step()
                d_gen = disc(s_hat)
                l_g = bce(d_gen, torch.ones_like(d_gen))
                loss = loss + cfg.lambda_generator * l_g
                sums["discriminator"].append(l_d.item())
            opt_g.zero_grad(); loss.backward()
            average_gradients([matching, predictor] if cfg.end_to_end else [matching], world)
            opt_g.step()
            sums["reconstruction"].append(l_r.item()); sums["codebook"].append(l_c.item())
            sums["generator"].append(l_g.item())
            bar.set_postfix(rec=f"{np.mean(sums['reconstruction'][-50:]):.4f}",
                            cb=f"{np.mean(sums['codebook'][-50:]):.4f}")
        val_mse, val_cb, val_mpjpe = validate(predictor, matching, mcfg, xv, yv, device, stats)
        for k, v in sums.items():
            history[k].append(float(np.mean(v)) if v else 0.0)
        history["val_mse"].append(val_mse)
        history["val_codebook"].append(val_cb)
        history.setdefault("val_mpjpe_cm", []).append(val_mpjpe)
        epoch += 1
        seconds += time.time() - t0
        if rank == 0 and not quiet:
            print(f"{name} matching {epoch}/{cfg.epochs}  rec {history['reconstruction'][-1]:.4f}  "
                  f"cb {history['codebook'][-1]:.4f}  G {history['generator'][-1]:.3f}  "
                  f"val mse {val_mse:.4f}  val cb {val_cb:.4f}  val mpjpe {val_mpjpe:.2f} cm  "
                  + "".join(f"{k} {history[k][-1]:.2e}  " for k, w in partner_weights.items() if w)
                  + "".join(f"{k} {history[k][-1]:.3f}  " for k in ("distill_codes", "distill_decoder") if k in sums) +
                  f"({time.time() - t0:.1f} s)")
        save("matching", epoch)
    stage = "done"
    save(stage, epoch)
    if rank == 0:
        plot_history(history, run / "losses.png", name)
        (run / "history.json").write_text(json.dumps({"seconds": seconds, **history}, indent=1))
    return {"name": name, "seconds": seconds, "val_mse": history["val_mse"][-1] if history["val_mse"] else None}


def distill_terms(teacher: StepModel, matching: CodebookMatching, x: torch.Tensor,
                  intention: torch.Tensor | None) -> tuple[torch.Tensor, torch.Tensor]:
    """The student's distance from the teacher on a batch of normalized inputs: the KL divergence
    of its input encoder's code distribution from the teacher's (per channel, nats), and the MSE
    between its decoder's and the teacher's on one code drawn from the teacher's distribution
    (Gumbel-max at temperature 1: every code the page's varieties draw, in proportion). Every
    sample weighs alike: weighted by the turn weights, the leader turned less (the tried table)."""
    c = teacher.cfg.channels
    with torch.no_grad():
        t_logits, _, _ = code_logits(teacher.predictor, teacher.matching, x)
        t_code = sample_codes(t_logits, c, 1.0)
        t_out = teacher.matching.decode(t_code, x)
    s_logits = matching.estimate_logits(x, intention)
    t_log = F.log_softmax(t_logits.reshape(len(x), c, -1), -1)
    s_log = F.log_softmax(s_logits.reshape(len(x), c, -1), -1)
    kl = (t_log.exp() * (t_log - s_log)).sum(-1).mean()
    return kl, F.mse_loss(matching.decode(t_code, x), t_out)


@torch.no_grad()
def validate(predictor, matching, mcfg, xv, yv, device, stats, batch=4096):
    """Teacher-forced validation: argmax code from the input encoder. Returns the MSE on
    normalized output, the codebook matching error (MSE between target and estimated one-hot
    codes) and the pose MPJPE in cm (joint positions in the dancer's root space, the number
    evaluation reports on the test takes)."""
    predictor.eval(); matching.eval()
    se, cb, pe, n = 0.0, 0.0, 0.0, 0
    for s in range(0, len(xv), batch):
        x, yb = xv[s:s + batch].to(device), yv[s:s + batch].to(device)
        s_hat, s_target, _ = code_logits(predictor, matching, x, yb)
        code_hat, code = (sample_codes(l, mcfg.channels, 0.0) for l in (s_hat, s_target))
        y_hat = matching.decode(code_hat, x)
        se += F.mse_loss(y_hat, yb, reduction="sum").item() / yb.shape[1]
        cb += F.mse_loss(code, code_hat, reduction="sum").item() / code.shape[1]
        pe += pose_error_cm(y_hat, yb, stats).sum().item()
        n += len(x)
    return se / n, cb / n, pe / n


def smoke(cfg: TrainConfig) -> TrainConfig:
    """A configuration that exercises every code path in seconds (CI)."""
    return replace(cfg, intention_epochs=1, epochs=2, teacher=None,
                   model=replace(cfg.model, hidden=32, intention_hidden=32, channels=2, classes=4))


# Flags that change a recipe: argparse name -> how its value changes the TrainConfig.
OVERRIDES = {
    "epochs": lambda c, v: replace(c, epochs=v),
    "intention_epochs": lambda c, v: replace(c, intention_epochs=v),
    "seed": lambda c, v: replace(c, seed=v),
    "channels": lambda c, v: replace(c, model=replace(c.model, channels=v)),
    "lambda_generator": lambda c, v: replace(c, lambda_generator=v),
    "hidden": lambda c, v: replace(c, model=replace(c.model, hidden=v)),
    "intention_hidden": lambda c, v: replace(c, model=replace(c.model, intention_hidden=v)),
    "teacher": lambda c, v: replace(c, teacher=v),
}


def apply_overrides(cfg: TrainConfig, args) -> TrainConfig:
    """The recipe with every flag given on the command line applied (unset flags change nothing)."""
    for key, change in OVERRIDES.items():
        value = getattr(args, key)
        if value is not None and value is not False:
            cfg = change(cfg, value)
    return cfg


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.learning.train", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--model", action="append", choices=sorted(MODELS), help="model(s) to train")
    ap.add_argument("--all", action="store_true", help=f"train the shipped models: {', '.join(SHIPPED)}")
    ap.add_argument("--ablations", action="store_true", help="train the evaluation-only models too")
    add_folder(ap, "prepared", "read", old=("--data",))
    add_folder(ap, "runs", "written, one folder per model", old=("--out",))
    ap.add_argument("--epochs", type=int, help="override matching epochs")
    ap.add_argument("--intention-epochs", type=int)
    ap.add_argument("--lambda-generator", type=float, help="override λG (λC stays as configured)")
    ap.add_argument("--seed", type=int, help="override the seed (seed-to-seed spread)")
    ap.add_argument("--channels", type=int, help="override the number of code channels C")
    ap.add_argument("--hidden", type=int, help="override the codebook-matching width (encoders and decoder)")
    ap.add_argument("--intention-hidden", type=int, help="override the predictor's width")
    ap.add_argument("--teacher", metavar="FILE", help="distill from FILE, a wider network's step model as "
                    "export wrote it (training/learning/distill.py)")
    ap.add_argument("--smoke", action="store_true", help="tiny sizes and 2 epochs (CI)")
    ap.add_argument("--resume", action="store_true", help="continue from RUNS/NAME/checkpoint.pt")
    ap.add_argument("--init-from", metavar="DIR", help="fine-tune: start from the weights of the run in DIR "
                    "(its intention predictor kept), then this recipe's matching epochs")
    ap.add_argument("--device", default="cpu", help="cpu, cuda, cuda:N or auto")
    ap.add_argument("--threads", type=int, default=0, help="torch CPU threads (0 = torch default)")
    args = ap.parse_args(argv)
    names = list(args.model or [])
    if args.all:
        names += [n for n in SHIPPED if n not in names]
    if args.ablations:
        names += [n for n in MODELS if n not in names]
    if not names:
        ap.error("name a --model, or use --all")
    if args.threads:
        torch.set_num_threads(args.threads)
    device = pick_device(args.device)
    rank, world = setup_distributed(device)
    t0 = time.time()
    try:
        for name in names:
            cfg = MODELS[name]
            if args.smoke:
                cfg = smoke(cfg)
            cfg = apply_overrides(cfg, args)
            r = train_model(name, cfg, args.prepared, args.runs, device, args.resume, rank=rank, world=world,
                            init_from=args.init_from)
            if rank == 0:
                mse = "" if r["val_mse"] is None else f", val mse {r['val_mse']:.4f}"
                print(f"{name}: done in {r['seconds']:.0f} s{mse}")
        wait_for_all(world)   # not on an error: the other process may never arrive
    except TrainError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    finally:
        stop_distributed(world)
    if rank == 0:
        print(f"total wall time {time.time() - t0:.0f} s on {device} x{world}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
