"""Training terms that know about the partner's body and the floor, on the decoded output.

Reconstruction alone treats the 323 output numbers as independent: a pose 3 cm off in the
follower's hand costs the same whether the hand then meets the leader's hand or not, and a foot
that slides 3 cm while planted costs no more than one that lifts. These terms read the decoded
output as a body, the way the run-time loop uses it (joint positions by forward kinematics from
the decoded hip and rotations: training/mirror/rollout.py apply_output), and compare it with the partner
body and the own body of the frame before, both given in the input:

- penetration: the dancer's spine (hip-abdomen-chest-neck) must stay 2 x TORSO_RADIUS from the
  partner's spine (metrics.interaction counts frames closer than that as interpenetrating);
- foot contact: where a foot is planted, the decoded foot must not move horizontally from where
  the input says it was. "Planted" is the recorded contact label (what the decoded contact learns
  to say); weighting by the decoded contact instead let the model stiffen its whole motion
  (train.py, PARTNER);
- interaction: where a joint pair of the two dancers is within reach in the recording, its
  decoded distance keeps the recorded one (hands that meet stay met).

All in the dancer's root space at frame t (the input's space), metres.
"""
from __future__ import annotations

import torch

from ..mirror import features as feat
from ..evaluation.metrics import TORSO_RADIUS
from ..mirror.skeleton import FEET, HANDS, PARENTS, SPINE

OUT = feat.block_slices(feat.OUTPUT_LAYOUT)
REACH = 0.5              # m: joint pairs closer than this in the recording keep their distance
SPINE_SAMPLES = 5        # points per spine segment for the penetration distance
# Joints of each dancer whose mutual distances the interaction term keeps: head, chest, hands.
INTERACTION_JOINTS = [4, 2, *HANDS]
HEADING_CHANGE = OUT["root_update"].start + 2   # the output's heading change (radians per frame)


def input_slices(role: str) -> dict[str, slice]:
    return feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT if role == "follower" else feat.LEADER_INPUT_LAYOUT)


def block_positions(x: torch.Tensor, block: slice) -> torch.Tensor:
    """Joint positions [B, 17, 3] of a raw pose block (position, velocity, forward, up per joint)."""
    return x[:, block].reshape(len(x), feat.N_JOINTS, 12)[..., :3]


def rotations_from_vectors(forward: torch.Tensor, up: torch.Tensor) -> torch.Tensor:
    """[..., 3] forward and up -> [..., 3, 3] with columns x, y, z (rollout.rotations_from_vectors)."""
    z = forward / forward.norm(dim=-1, keepdim=True).clamp_min(1e-6)
    x = torch.linalg.cross(up, z)
    x = x / x.norm(dim=-1, keepdim=True).clamp_min(1e-6)
    y = torch.linalg.cross(z, x)
    return torch.stack([x, y, z], -1)


def decoded_positions(out: torch.Tensor, offsets: torch.Tensor) -> torch.Tensor:
    """Raw decoded outputs [B, 323] and bone offsets [B, 17, 3] -> joint positions [B, 17, 3] at
    t+1 by forward kinematics, moved into the root space of frame t by the decoded root update."""
    pose = out[:, OUT["pose"]].reshape(len(out), feat.N_JOINTS, 12)
    rot = rotations_from_vectors(pose[..., 6:9], pose[..., 9:12])
    joints = [pose[:, 0, :3]]
    for j in range(1, feat.N_JOINTS):
        p = PARENTS[j]
        joints.append(joints[p] + (rot[:, p] @ offsets[:, j, :, None])[..., 0])
    pos = torch.stack(joints, 1)
    dx, dz, dtheta = out[:, 0], out[:, 1], out[:, 2]
    c, s = torch.cos(dtheta)[:, None], torch.sin(dtheta)[:, None]
    x, y, z = pos[..., 0], pos[..., 1], pos[..., 2]
    return torch.stack([c * x + s * z + dx[:, None], y, -s * x + c * z + dz[:, None]], -1)


def spine_points(pos: torch.Tensor) -> torch.Tensor:
    """[B, 17, 3] -> [B, 3 * SPINE_SAMPLES, 3] points along the spine segments."""
    a, b = pos[:, SPINE[:-1]], pos[:, SPINE[1:]]                                 # [B, 3, 3]
    u = torch.linspace(0, 1, SPINE_SAMPLES, device=pos.device)[None, None, :, None]
    return (a[:, :, None] + (b - a)[:, :, None] * u).reshape(len(pos), -1, 3)


def penetration_loss(me: torch.Tensor, partner: torch.Tensor) -> torch.Tensor:
    """Mean squared depth (m^2) by which the spines come closer than 2 x TORSO_RADIUS."""
    d = torch.cdist(spine_points(me), spine_points(partner)).flatten(1).min(1).values
    return torch.relu(2 * TORSO_RADIUS - d).pow(2).mean()


def foot_contact_loss(me: torch.Tensor, before: torch.Tensor, contacts: torch.Tensor) -> torch.Tensor:
    """Squared horizontal foot motion (m^2) weighted by the contacts [B, 2] (detached: a decoded
    contact is never pushed lower by this term)."""
    slide = (me[:, FEET][..., [0, 2]] - before[:, FEET][..., [0, 2]]).pow(2).sum(-1)   # [B, 2]
    return (contacts.detach().clamp(0, 1) * slide).mean()


def interaction_loss(me: torch.Tensor, target: torch.Tensor, partner: torch.Tensor,
                     joints: list[int] = INTERACTION_JOINTS) -> torch.Tensor:
    """Squared error (m^2) of the distances between the two dancers' `joints`, over the pairs
    within REACH in the recording (target = the recorded own body)."""
    d_hat = torch.cdist(me[:, joints], partner[:, joints])
    d = torch.cdist(target[:, joints], partner[:, joints])
    near = (d < REACH).float()
    return ((d_hat - d).pow(2) * near).sum() / near.sum().clamp_min(1.0)


def partner_terms(out: torch.Tensor, target: torch.Tensor, x: torch.Tensor, offsets: torch.Tensor,
                  role: str, recorded_contacts: bool = False,
                  interaction_joints: list[int] = INTERACTION_JOINTS,
                  spare_turning: float = 0.0) -> dict[str, torch.Tensor]:
    """Raw decoded output, raw target output [B, 323], raw input [B, 660], offsets [B, 17, 3] ->
    the three terms (scalars). The foot-contact term is weighted by the decoded contacts, or by
    the recorded ones with `recorded_contacts`; with `spare_turning` (radians per frame) it skips
    the samples whose recorded heading turns faster than that (a dancer pivoting on a planted foot)."""
    sl = input_slices(role)
    me = decoded_positions(out, offsets)
    recorded = decoded_positions(target, offsets)
    partner = block_positions(x, sl["partner_pose"])
    before = block_positions(x, sl["self_pose"])
    contacts = (target if recorded_contacts else out)[:, OUT["contacts"]]
    if spare_turning > 0:
        turning = target[:, HEADING_CHANGE].abs() > spare_turning
        contacts = contacts * (~turning)[:, None]
    return {"penetration": penetration_loss(me, partner),
            "foot_contact": foot_contact_loss(me, before, contacts),
            "interaction": interaction_loss(me, recorded, partner, interaction_joints)}
