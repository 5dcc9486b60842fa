"""Networks: intention predictor, (adversarial) categorical codebook matching, discriminator.

Shapes follow docs/features.md. All modules work on normalized features; `StepModel` wraps the
trained pieces with normalization so one call is one animation step (what export.py writes).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import NamedTuple

import torch
import torch.nn as nn
import torch.nn.functional as F

from ..mirror.features import (FOLLOWER_INPUT_LAYOUT, INPUT_SIZE, INTENTION_SIZE, LEADER_INPUT_LAYOUT,
                               N_JOINTS, OUTPUT_SIZE, POSE_SIZE, block_slices)


@dataclass
class ModelConfig:
    role: str = "follower"            # "follower" or "leader" (the leader's input ends with control)
    intention: bool = True            # False: plain codebook matching (the CCM baseline)
    hidden: int = 512                 # codebook-matching MLP width
    intention_hidden: int = 256
    channels: int = 8                 # C categorical channels ...
    classes: int = 32                 # ... of D classes each
    dropout: float = 0.2
    # The decoder also reads the dancer's own current joint positions and velocities. Decoded from
    # the code alone, a pose is the same for as long as the sampled code is: the body holds one
    # shape between code switches (stop-motion; docs/plausibility.md). With the current motion
    # beside the code, the same code carries the body on from where it is.
    decoder_state: bool = False
    # The decoder also reads the music block (the count over the past and next second, the tempo)
    # beside the code and the pose, never hidden. Read only by the encoders, the count reaches the
    # pose through the code, and a half-beat shift of it moves a step by a tenth of the ankles'
    # speed (docs/music.md): the code may not carry when the feet land.
    decoder_music: bool = False
    input_size: int = INPUT_SIZE
    output_size: int = OUTPUT_SIZE
    intention_size: int = INTENTION_SIZE

    @property
    def latent(self) -> int:
        return self.channels * self.classes

    @property
    def state_columns(self) -> list[int]:
        """Columns of the input the decoder reads: the self pose's position and velocity of each
        joint (6 of its 12 numbers), then the music block with decoder_music; none without
        decoder_state."""
        if not self.decoder_state:
            return []
        layout = LEADER_INPUT_LAYOUT if self.role == "leader" else FOLLOWER_INPUT_LAYOUT
        start, per_joint = block_slices(layout)["self_pose"].start, POSE_SIZE // N_JOINTS   # features.pose_block
        return [start + per_joint * j + k for j in range(N_JOINTS) for k in range(6)] + self.music_columns

    @property
    def music_columns(self) -> list[int]:
        """Columns of the input's music block the decoder reads after the pose (decoder_music)."""
        if not self.decoder_music:
            return []
        layout = LEADER_INPUT_LAYOUT if self.role == "leader" else FOLLOWER_INPUT_LAYOUT
        music = block_slices(layout)["music"]
        return list(range(music.start, music.stop))

    def to_dict(self) -> dict:
        return asdict(self)


def mlp(sizes: list[int], dropout: float) -> nn.Sequential:
    """Fully connected layers with ELU between them (none after the last)."""
    layers: list[nn.Module] = []
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
        if i > 0:
            layers += [nn.ELU(), nn.Dropout(dropout)]
        layers.append(nn.Linear(a, b))
    return nn.Sequential(*layers)


class IntentionPredictor(nn.Module):
    """I -> the partner's key joints over the next second (3 layers, trained alone with MSE)."""

    def __init__(self, cfg: ModelConfig):
        super().__init__()
        h = cfg.intention_hidden
        self.net = mlp([cfg.input_size, h, h, cfg.intention_size], cfg.dropout)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.net(x)


def gumbel_noise(shape, device=None, generator=None) -> torch.Tensor:
    u = torch.rand(shape, device=device, generator=generator).clamp(1e-9, 1 - 1e-9)
    return -torch.log(-torch.log(u))


def sample_codes(logits: torch.Tensor, channels: int, temperature: float = 1.0,
                 noise: torch.Tensor | None = None) -> torch.Tensor:
    """Per-channel categorical sample as a hard one-hot [B, C*D] with a straight-through gradient.

    The forward value is argmax(logits + temperature * gumbel) per channel (the Gumbel-max
    trick: temperature 1 samples the categorical exactly, 0 is the argmax); the backward pass
    uses the softmax of the same perturbed logits, which is Gumbel-softmax with hard one-hot.
    """
    b = logits.shape[0]
    z = logits.reshape(b, channels, -1)
    if temperature > 0:
        g = gumbel_noise(z.shape, z.device) if noise is None else noise.reshape(z.shape)
        z = z + temperature * g
    soft = F.softmax(z, -1)
    hard = F.one_hot(z.argmax(-1), z.shape[-1]).to(soft.dtype)
    return (hard - soft.detach() + soft).reshape(b, -1)


class CodebookMatching(nn.Module):
    """Output encoder (O, I, intention) -> logits S; input encoder (I, intention) -> logits Ŝ;
    both sampled into one-hot codes; the decoder turns a code back into O.
    """

    def __init__(self, cfg: ModelConfig):
        super().__init__()
        self.cfg = cfg
        h, extra = cfg.hidden, (cfg.intention_size if cfg.intention else 0)
        self.input_encoder = mlp([cfg.input_size + extra, h, h, cfg.latent], cfg.dropout)
        self.output_encoder = mlp([cfg.output_size + cfg.input_size + extra, h, h, cfg.latent], cfg.dropout)
        self.decoder = mlp([cfg.latent + len(cfg.state_columns), h, h, cfg.output_size], cfg.dropout)
        self.register_buffer("state_columns", torch.tensor(cfg.state_columns, dtype=torch.long), persistent=False)

    def decode(self, code, x, state_keep: torch.Tensor | None = None):
        """One-hot code [B, C*D] (and the normalized input x, read when the decoder reads the state) -> O.
        state_keep [B, 1] (training only): 0 hides a sample's state from the decoder (the mean pose)."""
        state = x[:, self.state_columns]
        if state_keep is not None:   # hides the pose, never the music
            music = len(self.cfg.music_columns)
            if music:
                state_keep = torch.cat([state_keep.expand(-1, state.shape[1] - music),
                                        torch.ones(len(state), music, device=state.device)], 1)
            state = state * state_keep
        return self.decoder(torch.cat([code, state], -1))

    def _cond(self, x, intention):
        return torch.cat([x, intention], -1) if self.cfg.intention else x

    def estimate_logits(self, x, intention=None):
        return self.input_encoder(self._cond(x, intention))

    def target_logits(self, x, y, intention=None):
        return self.output_encoder(torch.cat([y, self._cond(x, intention)], -1))

    def forward(self, x, y, intention=None, temperature: float = 1.0, state_keep=None):
        s = self.target_logits(x, y, intention)
        s_hat = self.estimate_logits(x, intention)
        code = sample_codes(s, self.cfg.channels, temperature)
        code_hat = sample_codes(s_hat, self.cfg.channels, temperature)
        return self.decode(code, x, state_keep), s, s_hat, code, code_hat

    def generate(self, x, intention=None, temperature: float = 0.0, noise=None):
        code = sample_codes(self.estimate_logits(x, intention), self.cfg.channels, temperature, noise)
        return self.decode(code, x), code


class Logits(NamedTuple):
    estimate: torch.Tensor               # Ŝ from the input encoder [B, C*D]
    target: torch.Tensor | None          # S from the output encoder, when an output was given
    intention: torch.Tensor | None       # the predictor's (normalized) intention; None for CCM


def code_logits(predictor: IntentionPredictor | None, matching: CodebookMatching, xn: torch.Tensor,
                yn: torch.Tensor | None = None) -> Logits:
    """Normalized input (and output) -> intention -> code logits: the one way every caller
    (training's validation, the step model, evaluation, plots) reads the encoders."""
    intention = predictor(xn) if matching.cfg.intention else None
    estimate = matching.estimate_logits(xn, intention)
    target = None if yn is None else matching.target_logits(xn, yn, intention)
    return Logits(estimate, target, intention)


class Discriminator(nn.Module):
    """Tells target logits S from estimated Ŝ (2 layers). It sees per-channel log-softmax: the
    logits without their arbitrary per-channel offset, so it judges the distribution itself."""

    def __init__(self, cfg: ModelConfig, hidden: int = 256):
        super().__init__()
        self.channels = cfg.channels
        self.net = nn.Sequential(nn.Linear(cfg.latent, hidden), nn.LeakyReLU(0.2), nn.Linear(hidden, 1))

    def forward(self, logits):
        b = logits.shape[0]
        z = F.log_softmax(logits.reshape(b, self.channels, -1), -1).reshape(b, -1)
        return self.net(z)


class StepModel(nn.Module):
    """One animation step on raw features: normalize -> intention -> input encoder -> sample ->
    decoder -> de-normalize. Inputs: input [B, 660], temperature [1], noise [B, C*D] uniform (0,1):
    one sample per input row; or input [1, ...] with noise [K, C*D]: K samples of one input, the
    encoders run once and only the sampling and the decoder K times (the guards' and the count's
    choices, web/mirror/guard.ts and on_count.ts). Outputs output and code have noise's rows,
    intention input's (it does not depend on the noise).
    """

    def __init__(self, cfg: ModelConfig, predictor: IntentionPredictor | None,
                 matching: CodebookMatching, stats: dict[str, torch.Tensor]):
        super().__init__()
        self.cfg = cfg
        self.predictor = predictor
        self.matching = matching
        for k, v in stats.items():
            self.register_buffer(k, v.float())

    def logits(self, x: torch.Tensor, y: torch.Tensor | None = None) -> Logits:
        """code_logits on raw features: normalized here with the model's own statistics."""
        xn = (x - self.input_mean) / self.input_std
        yn = None if y is None else (y - self.output_mean) / self.output_std
        return code_logits(self.predictor, self.matching, xn, yn)

    def forward(self, x, temperature, noise):
        xn = (x - self.input_mean) / self.input_std
        logits, _, intention_n = code_logits(self.predictor, self.matching, xn)
        c, d = self.cfg.channels, self.cfg.classes
        u = noise.clamp(1e-7, 1 - 1e-7)
        # [B or 1, C, D] + [B or K, C, D]: one input's logits broadcast over its K draws
        z = logits.reshape(-1, c, d) + temperature.reshape(1, 1, 1) * -torch.log(-torch.log(u.reshape(-1, c, d)))
        code = z.argmax(-1)
        y = self.decode(code, xn)
        out = y * self.output_std + self.output_mean
        if self.cfg.intention:
            k = self.cfg.intention_size   # the key joints the page draws (the led turn stays inside)
            return out, intention_n[:, :k] * self.intention_std[:k] + self.intention_mean[:k], code
        return out, code

    def decode(self, code, xn):
        """Decoder on a one-hot code given by indices [B, C] (and the normalized input xn): the
        code's part of the first layer is a sum of C weight columns (a gather), not a product
        with a mostly-zero [C*D] vector; the state's part is an ordinary product."""
        first, rest = self.matching.decoder[0], self.matching.decoder[1:]
        d, latent = self.cfg.classes, self.cfg.latent
        columns = code + torch.arange(self.cfg.channels, device=code.device) * d   # [B, C]
        h = first.weight[:, :latent].t()[columns].sum(1) + first.bias
        if self.cfg.decoder_state:
            h = h + xn[:, self.matching.state_columns] @ first.weight[:, latent:].t()
        return rest(h)


class OutputEncoderStep(nn.Module):
    """Evaluation only: raw input I [B, 660] and the recorded output O [B, 323] -> the output
    encoder's target logits S [B, C*D], normalization and intention inside (export writes it as
    eval/NAME.output_encoder.onnx; the page never loads it). Its argmax is the code the recorded
    motion gets, against which a step model's own code is scored (codebook error)."""

    def __init__(self, step: StepModel):
        super().__init__()
        self.step = step

    def forward(self, x, y):
        return self.step.logits(x, y).target

