"""How the follower sees her leader's height (web/mirror/view.ts mirrors it name for name).

Our leader lunges deeper and more often than the recorded one: his hips reach the recorded
leader's lowest 2 % of heights, his feet a metre apart. Beside such a lunge the follower went down
with him and fell: reading his low body, she danced what the recording shows beside a low leader
(docs/results.md, "She follows his lunge down"). Measured from saved duets a second before her
fall: with his body lifted in her input so that his hips read at least 0.95 m, 0 of 10
continuations fell, against 4 of 10 as he was.

So her input shows him no lower than PARTNER_HIP_FLOOR: when his hips (in the pose block) are
lower, his whole body in her input, the pose and the past key joints, is raised by the difference,
as one rigid lift. His path on the floor, his velocities and directions stay, and she still reads
every lunge down to the floor's height, which the recorded leader's hips pass in 9 of 10 frames.
It is her reading, not a command: what she does still comes from his motion alone.

The floor ships in the manifest ("followerView": {"partnerHipFloor": m}); without it the input is
left as it is.
"""
from __future__ import annotations

import numpy as np

from . import features as feat

# The recorded leader's hips are above 0.905 m in 90 % of his frames (0.948 m the median, 0.795 m
# the lowest 2 %): a lunge deeper than that reads as that deep.
PARTNER_HIP_FLOOR = 0.90   # m

_SLICES = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)
PARTNER_POSE = _SLICES["partner_pose"]
PARTNER_KEY_JOINTS = _SLICES["partner_key_joints_past"]
POSE_WIDTH = 12       # position, velocity, forward, up per joint
KEY_WIDTH = 3         # a key joint's position


def partner_lift(x: np.ndarray, floor: float) -> np.ndarray:
    """Follower inputs [B, 660] (raw) -> [B] metres her leader's body is to be raised: how far his
    hips are below `floor`, 0 where they are not."""
    x = np.atleast_2d(x)
    return np.maximum(0.0, floor - x[:, PARTNER_POSE.start + 1])


def lift_partner(x: np.ndarray, floor: float) -> np.ndarray:
    """Follower inputs [B, 660] or [660] (raw) -> a copy in which her leader's hips read at least
    `floor` metres high: every height of his pose and past key joints raised by partner_lift."""
    out = np.array(x, copy=True)
    flat = np.atleast_2d(out)
    lift = partner_lift(flat, floor)
    flat[:, PARTNER_POSE.start + 1:PARTNER_POSE.stop:POSE_WIDTH] += lift[:, None]
    flat[:, PARTNER_KEY_JOINTS.start + 1:PARTNER_KEY_JOINTS.stop:KEY_WIDTH] += lift[:, None]
    return out


class PartnerView:
    """Wraps the follower's policy (x, temperature, rng) -> {...}: it reads x with her leader lifted
    to `floor` (lift_partner). `lifted` counts the steps in which he was raised (one-row calls: a
    guard's batch of the same input is not another step)."""

    def __init__(self, policy, floor: float = PARTNER_HIP_FLOOR):
        self.policy, self.floor = policy, floor
        self.lifted = 0

    def __call__(self, x: np.ndarray, temperature: float, rng: np.random.Generator) -> dict:
        if len(np.atleast_2d(x)) == 1 and partner_lift(x, self.floor)[0] > 0:
            self.lifted += 1
        return self.policy(lift_partner(x, self.floor), temperature, rng)
