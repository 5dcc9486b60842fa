"""The dancers' upright guard, the follower's first (web/mirror/guard.ts mirrors it name for name).

A follower whose decoder is kept reading its code (train.py's `follower`: state dropout) is as
varied as the recording, but now and then, left alone, it sinks or tips over (docs/plausibility.md).
The guard asks whether a sample the network already offers would have stayed up: when the body a
step draws (the decoded hip and joint rotations through the dancer's bones) comes within MARGIN of
the recording's range (hips low, head low over the hips, feet too wide, the torso leaning further
than the recording's steepest), the same input is run again with SAMPLES fresh Gumbel draws and the
most upright of them is taken. Every candidate is one step on from the current pose, decoded by
the network from the same state, so the body never jumps; the guard only chooses among the
network's own reactions, and it counts every step it chose (the page shows the count under
"details", the evaluation reports it beside the flags).

It acts before the pose leaves the range because once the body is low, every sample the network
offers from there is low too. SAMPLES and MARGIN ship in the manifest ("guard"); the evaluation
commands take them from there (training/evaluation/options.py).
"""
from __future__ import annotations

import numpy as np

from . import features as feat
from .on_count import OnCount, drawn_footwork, drawn_steps, hips_turn_back, nearest_count, planted
from .rollout import MIN_ANKLE_HEIGHT, rotations_from_vectors
from .skeleton import FEET, HANDS, HEAD, forward_kinematics_reduced
from ..evaluation.plausibility import CHEST

# 0 of 100 steered seeds with a bad second and no fall in the soaks measured with these (a margin
# of 0.02 m let one seed fall, 0.1 m chose in every step and became a different sampler):
# docs/plausibility.md. 32 samples did no better than 8 then, beside the stiff leader; beside the
# leader who lunges (LEADER_HEAD_MARGIN below) they do: continued 20 times each from four moments
# just before the soak's falls of seeds 49 and 86, she fell in 20 of 80 with 8 samples, 13 with
# 16, 5 with 32 and 3 with 64 (docs/results.md, "Her guard beside his lunge"). The guard acts in
# under 1 % of her steps, so the larger batch costs the page nothing in the median step. Beside the
# leader who turns on his own (not shipped), 128 samples took her falls from 11 to 2 of 30
# continuations of one soak fall (scripts/fall_continuations.py), yet the soak still lost a seed
# (docs/results.md, "Her guard of 128 samples").
SAMPLES = 32
MARGIN = 0.05   # m
# Her hips, though, go down fast once she falls (0.39 m in a quarter second before the soak's fall
# of seed 9), and once they are low no sample brings them up: judged from FOLLOWER_HIP_MARGIN, the
# guard catches the drop earlier. Her hips stand above 0.898 m in 99 % of the recorded frames, so
# from 0.15 m over the range's low end (0.713 m) it acts in 0.25 % of her steered steps. Beside the
# leader who lunges (LEADER_HEAD_MARGIN below) she then fell in 1 of the 66 soak rollouts that lost
# 7 with her hips judged from 0.05 m, and in 3 of all 100 (1 of 100 beside the stiff leader before):
# docs/results.md, "Room for his head, her hips guarded". The networks that read the figure fall
# from 0.15 m more often than those did: 5 of 18 one-minute steered soak rollouts (seeds 0-17),
# her hips 0.93 -> 0.41 m within half a second with his upright beside her. Judged from 0.20 m
# (0.913 m, between her recorded hips' 1st and 2.5th percentiles, 0.898 and 0.921 m), 1 of 17, her
# guard choosing in 0.19 % of her steps (2.45 % from 0.15 m: caught earlier, she falls less) and her
# rhythm as before; from 0.25 m 0 of 18, but her footwork pulse halved (docs/results.md, tried).
# It does not end her falls: 6 of 12 ten-minute steered rollouts still fell (docs/reliability.md).
# None: the hips judged from MARGIN like the rest.
FOLLOWER_HIP_MARGIN: float | None = 0.20   # m
# With her hips judged from 0.15 m every fall left in the soak came a second or two after his lunge,
# and while her input showed his hips below 0.88 m they were judged from 0.20 m instead. Judged from
# 0.20 m always, she needs no such rule (0.25 m while he is low: 2 of 18 fell, against 1 of 17
# without it; docs/results.md, tried).
# The leader trained on his own rollouts dances (steered, body motion 0.54 m/s over 100 seeds against 0.33 before) but,
# steered, a few seeds had a second with his hips low. The same guard, acting from LEADER_MARGIN
# before the range's edge (40 steered seeds): 0.05 m acted in 3.9 % of his steps and left 1 seed
# with a bad second; 0.07 m acted in 44 % and left none; 0.1 m acted in every step (a different
# sampler: the most upright of 8) and cost the page 0.3 ms a step (docs/results.md).
LEADER_SAMPLES = 8
LEADER_MARGIN = 0.07   # m
# His head over his hips has a narrow range, though (the recorded leader's head stands 0.65-0.72 m
# over his hips, within 0.07 m of the low end in 67 % of his frames): judged from 0.07 m there, the
# guard acts in 43 % of his steps, in 59 % of those none of its 8 samples passes, and it takes the
# one standing straightest, a stiff leader (2.0 turns a minute nobody steering, 100 seeds). A
# head_margin judges that part from less: at 0.03 m (the full margin while a request runs) he turns
# 6.1 times a minute nobody steering (2.0 at 0.07 m; 100 seeds). Beside him, lunging now, his
# partner fell in 7 of 66 soak rollouts until her hips were guarded from FOLLOWER_HIP_MARGIN.
# docs/results.md, "The leader's guard" and "Room for his head, her hips guarded".
LEADER_HEAD_MARGIN: float | None = 0.03   # m; None: the head is judged from LEADER_MARGIN
# His hips, like hers, go down in a crouch that no sample brings back up once it is low: the one
# steered seed with a bad second while his hips were judged from LEADER_MARGIN (seed 61) crouched from 55.5 s on,
# hips down to 0.47 m, his guard choosing in 70 steps without finding a standing sample. Judged
# from 0.10 m (it acts while the drawn hips are under 0.813 m, below his lunges at 0.84-0.86 m), 100
# steered seeds had no bad second and his guard chose in 0.20 % of his steps (0.23 % from LEADER_MARGIN);
# nobody steering he turns and moves as before (docs/results.md, "His hips guarded").
LEADER_HIP_MARGIN: float | None = 0.10    # m; None: the hips are judged from LEADER_MARGIN
# While a request runs, his guard also keeps his lead hand to the hands plan: every step it draws
# its LEADER_SAMPLES samples and, of those that stand, takes the one whose lead hand is nearest the
# height the plan puts it at one step on. Planned alone, his hand went above 1.6 m after 85 % of
# 500 requests (the network stops short of the plan, and in a closed hold keeps both hands at his
# chest); kept to it, after 98 %, and she turned within 2.5 s after 78 % of them against 71 %
# (61-62 % at the same moments unasked; lead, 100 seeds; docs/results.md, "His lead hand kept to
# the plan"). It only chooses among his own network's steps, and only while someone asks.
# Taking the nearest alone, his feet lost the count while a figure ran: his steps on the beat +0.06
# as drawn, steered (+0.11 on his network's body; the recording +0.27). Of the
# LEADER_KEEP_PLAN standing samples nearest the plan (near_plan), his chooser on the count takes the
# one on the beat: with 2, +0.20 drawn (+0.25), his hand above 1.6 m after 40 % of 160 requests
# against 46 % with the nearest, and she turns as often the asked way (63 % against 65 %); with 3,
# his hand 34 % (docs/results.md, "Leading a turn"). 1: the nearest alone.
LEADER_KEEP_PLAN = 2

POSE = feat.block_slices(feat.OUTPUT_LAYOUT)["pose"]
HANDS_PLAN_SHOWN = feat.block_slices(feat.LEADER_INPUT_LAYOUT)["hands_plan"].start   # 1 while a request runs
# In a leader's input: each hand's height now (his own pose block, y, his root space) and its planned
# move to the first future key (the hands plan's first key, y), left then right.
HAND_HEIGHTS = [feat.block_slices(feat.LEADER_INPUT_LAYOUT)["self_pose"].start + 12 * h + 1 for h in HANDS]
HAND_PLAN_FIRST = [HANDS_PLAN_SHOWN + 1 + 3 * k + 1 for k in range(len(HANDS))]


def drawn_joints(outputs: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """[B, 323] raw outputs -> [B, 17, 3] the body the rollout draws in the next root's space: the
    decoded hip and joint rotations through the dancer's bones, lifted as mirror/rollout.apply_output
    lifts a body whose ankles would go below the floor."""
    pose = np.atleast_2d(outputs)[:, POSE].reshape(-1, feat.N_JOINTS, 12)
    joints = forward_kinematics_reduced(np.asarray(offsets, float), pose[:, 0, :3],
                                        rotations_from_vectors(pose[..., 6:9], pose[..., 9:12]))
    joints[..., 1] += np.maximum(MIN_ANKLE_HEIGHT - joints[:, FEET, 1].min(-1), 0)[:, None]
    return joints


def upright_margin(outputs: np.ndarray, r: dict, offsets: np.ndarray | None = None,
                   head_slack: float = 0.0, hip_slack: float = 0.0) -> np.ndarray:
    """[B, 323] raw outputs -> [B] metres by which the decoded pose stays inside the recording's
    range on hips, head over hips, feet apart and the torso's lean (negative: that far outside).
    The pose is in the next root's space, whose y is the height above the floor. `head_slack`
    metres are added to the head-over-hips part alone (a guard that judges it from a smaller margin),
    `hip_slack` metres to the hips' part alone (negative: a guard that judges them from a larger one).

    With the dancer's bone `offsets`, the body judged is the one the rollout draws: the decoded hip
    and the decoded joint rotations through the bones, lifted as mirror/rollout.apply_output lifts. Without them,
    the decoded joint positions, which the drawn body does not use: the soak's falls of seeds 3
    and 13 happened with those positions upright throughout (docs/plausibility.md).

    The lean is measured in metres too: how far the chest may still move sideways over the hips
    before the torso leans more than the recording's steepest (plausibility's last angle)."""
    if offsets is None:
        joints = np.atleast_2d(outputs)[:, POSE].reshape(-1, feat.N_JOINTS, 12)[..., :3]
    else:
        joints = drawn_joints(outputs, offsets)
    return drawn_margin(joints, r, head_slack, hip_slack)


def drawn_margin(joints: np.ndarray, r: dict, head_slack: float = 0.0, hip_slack: float = 0.0) -> np.ndarray:
    """upright_margin of bodies already drawn [B, 17, 3] (drawn_joints)."""
    hip, head = joints[:, 0, 1], joints[:, HEAD, 1]
    feet = np.linalg.norm(joints[:, FEET[0]] - joints[:, FEET[1]], axis=-1)
    torso = joints[:, CHEST] - joints[:, 0]
    sideways = np.linalg.norm(torso[:, [0, 2]], axis=-1)
    allowed = np.linalg.norm(torso, axis=-1) * np.sin(r["angle_high"][-1])
    return np.minimum.reduce([hip - r["hip_low"] + hip_slack, head - hip - r["head_above_hip_low"] + head_slack,
                              r["feet_wide"] - feet, allowed - sideways])


def most_upright(outputs: np.ndarray, r: dict, offsets: np.ndarray | None = None, head_slack: float = 0.0,
                 hip_slack: float = 0.0) -> int:
    """The index of the most upright of the outputs [B, 323]."""
    return int(np.argmax(upright_margin(outputs, r, offsets, head_slack, hip_slack)))


def shows_plan(x: np.ndarray) -> bool:
    """Whether x is a leader's input that shows a hands plan (a request runs)."""
    first = np.atleast_2d(x)[0]
    return len(first) == feat.LEADER_INPUT_SIZE and bool(first[HANDS_PLAN_SHOWN] >= 0.5)


def lead_hand_miss(outputs: np.ndarray, x: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """[B, 323] raw outputs and a leader's input x that shows a hands plan -> [B] metres by which the
    lead hand each output draws misses the height the plan puts it at one step on (a KEY_STEP-th of
    its move to the first key). The lead hand is the one the plan puts higher at that key. Height
    alone: it is the same in this root's space and the next one's, and it is what she sees rise."""
    return drawn_miss(drawn_joints(outputs, offsets), x)


def drawn_miss(joints: np.ndarray, x: np.ndarray) -> np.ndarray:
    """lead_hand_miss of bodies already drawn [B, 17, 3] (drawn_joints)."""
    first = np.atleast_2d(x)[0]
    now, move = first[HAND_HEIGHTS], first[HAND_PLAN_FIRST]
    lead = int(np.argmax(now + move))
    target = now[lead] + move[lead] / feat.KEY_STEP
    return np.abs(joints[:, HANDS[lead], 1] - target)


def nearest_plan(outputs: np.ndarray, x: np.ndarray, r: dict, offsets: np.ndarray, margin: float,
                 head_slack: float = 0.0, hip_slack: float = 0.0) -> int:
    """The index of the output [B, 323] whose lead hand is nearest the plan (lead_hand_miss) among
    those standing at least `margin` inside the range; the most upright when none does. Each body
    is drawn once for both judgements."""
    joints = drawn_joints(outputs, offsets)
    standing = drawn_margin(joints, r, head_slack, hip_slack)
    if not (standing >= margin).any():
        return int(np.argmax(standing))
    return int(np.argmin(np.where(standing >= margin, drawn_miss(joints, x), np.inf)))


def near_plan(joints: np.ndarray, x: np.ndarray, standing: np.ndarray, margin: float, n: int) -> np.ndarray:
    """[B] bool: the n bodies drawn [B, 17, 3] standing at least `margin` inside the range (their
    upright margins `standing` [B]) whose lead hand is nearest the plan (drawn_miss); fewer when
    fewer stand."""
    ok = np.asarray(standing) >= margin
    order = np.argsort(np.where(ok, drawn_miss(joints, x), np.inf), kind="stable")[:n]
    near = np.zeros(len(ok), dtype=bool)
    near[order] = True
    return near & ok


def slack_for(x: np.ndarray, margin: float, head_margin: float | None) -> float:
    """Metres a guard lets off the head-over-hips part for input x: margin - head_margin; none
    when it has no head_margin, or while x is a leader's input that shows a hands plan (he leads)."""
    first = np.atleast_2d(x)[0]
    if head_margin is None or shows_plan(first):
        return 0.0
    return margin - head_margin


def hip_slack_for(margin: float, hip_margin: float | None) -> float:
    """Metres a guard adds to the hips' part (negative: they are judged from a larger margin):
    margin - hip_margin; none without a hip margin."""
    return 0.0 if hip_margin is None else margin - hip_margin


class UprightGuard:
    """Wraps a policy (x, temperature, rng) -> {output, intention, ...}; `guarded` counts the steps
    in which it picked another sample (reset it per duet). `temperature` overrides the one the
    duet's step asks for (the follower's own variety; the leader keeps the duet's). `head_margin`
    (the leader's): the head over the hips is judged from that margin instead, except while his
    input shows a hands plan. `hip_margin` (both dancers'): the hips are judged from that margin.
    `keep_plan` (his): while his input shows a hands plan, every step draws the samples and takes
    the standing one whose lead hand is nearest the plan (nearest_plan), or with `on_count` and
    keep_plan > 1 the one on the count of the keep_plan nearest (near_plan); `kept` counts those
    steps, `guarded` the ones among them where none stood. `on_count` (both dancers', an
    on_count.OnCount): every step draws its samples and takes the standing one whose footwork
    follows the count, one whose hips turn back passed over (while the dancer turns: the first
    standing one whose hips go on; on_count.nearest_count); when none of them stands, the guard
    draws its own samples and takes the most upright, as it always does."""

    def __init__(self, policy, ranges: dict, samples: int = SAMPLES, temperature: float | None = None,
                 margin: float = MARGIN, offsets: np.ndarray | None = None, head_margin: float | None = None,
                 hip_margin: float | None = None, keep_plan: int = 0,
                 on_count: OnCount | None = None):
        if samples < 2:
            raise ValueError("the guard needs at least 2 samples to choose from")
        self.policy, self.ranges, self.samples, self.temperature = policy, ranges, samples, temperature
        self.margin, self.offsets, self.head_margin = margin, offsets, head_margin
        self.hip_margin = hip_margin
        self.hip_slack = hip_slack_for(margin, hip_margin)
        self.keep_plan = int(keep_plan)
        if keep_plan and offsets is None:
            raise ValueError("keeping the hand to the plan needs the dancer's bones (offsets)")
        if on_count is not None and offsets is None:
            raise ValueError("stepping on the count needs the dancer's bones (offsets)")
        self.on_count = on_count
        self.guarded = self.kept = 0

    def __call__(self, x: np.ndarray, temperature: float, rng: np.random.Generator) -> dict:
        out = self._step(x, temperature, rng)
        if self.on_count is not None:   # the feet it plants, for the next step's footwork now
            self.on_count.took(out["output"])
        return out

    def _step(self, x: np.ndarray, temperature: float, rng: np.random.Generator) -> dict:
        t = temperature if self.temperature is None else self.temperature
        slack = slack_for(x, self.margin, self.head_margin)
        hips = self.hip_slack
        if self.keep_plan and shows_plan(x):
            many = self.policy(np.repeat(np.atleast_2d(x), self.samples, 0), t, rng)
            best = -1
            if self.on_count is not None and self.keep_plan > 1:
                # Among the keep_plan standing samples nearest the plan, the one on the count: his
                # hand keeps to the lead and his feet to the beat.
                joints = drawn_joints(many["output"], self.offsets)
                standing = drawn_margin(joints, self.ranges, slack, hips)
                near = near_plan(joints, x, standing, self.margin, self.keep_plan)
                target = self.on_count.target(x)
                steps = drawn_steps(many["output"], joints, x, self.on_count.role)
                best = nearest_count(drawn_footwork(steps, planted(many["output"])),
                                     hips_turn_back(steps, x, self.on_count.role), target,
                                     np.where(near, standing, -np.inf), self.margin, self.on_count.hips,
                                     self.on_count.prefers(many["output"], x))
            if best < 0:
                best = nearest_plan(many["output"], x, self.ranges, self.offsets, self.margin, slack, hips)
            self.kept += 1
            if upright_margin(many["output"][best], self.ranges, self.offsets, slack, hips)[0] < self.margin:
                self.guarded += 1
            return {k: v[best:best + 1] for k, v in many.items()}
        target = None if self.on_count is None else self.on_count.target(x)
        if self.on_count is not None and (target is not None or self.on_count.hips > 0):
            many = self.policy(np.repeat(np.atleast_2d(x), self.on_count.samples, 0), t, rng)
            joints = drawn_joints(many["output"], self.offsets)
            standing = drawn_margin(joints, self.ranges, slack, hips)
            steps = drawn_steps(many["output"], joints, x, self.on_count.role)
            best = nearest_count(drawn_footwork(steps, planted(many["output"])),
                                 hips_turn_back(steps, x, self.on_count.role), target, standing,
                                 self.margin, self.on_count.hips, self.on_count.prefers(many["output"], x))
            if best >= 0:
                return {k: v[best:best + 1] for k, v in many.items()}
            self.guarded += 1
            many = self.policy(np.repeat(np.atleast_2d(x), self.samples, 0), t, rng)
            best = most_upright(many["output"], self.ranges, self.offsets, slack, hips)
            return {k: v[best:best + 1] for k, v in many.items()}
        out = self.policy(x, t, rng)
        if upright_margin(out["output"], self.ranges, self.offsets, slack, hips)[0] >= self.margin:
            return out
        self.guarded += 1
        many = self.policy(np.repeat(np.atleast_2d(x), self.samples, 0), t, rng)
        best = most_upright(many["output"], self.ranges, self.offsets, slack, hips)
        return {k: v[best:best + 1] for k, v in many.items()}


class Variety:
    """A policy run at its own temperature, whatever the duet's step asks for (no guard)."""

    def __init__(self, policy, temperature: float):
        self.policy, self.temperature, self.guarded = policy, temperature, 0

    def __call__(self, x: np.ndarray, temperature: float, rng: np.random.Generator) -> dict:
        return self.policy(x, self.temperature, rng)
