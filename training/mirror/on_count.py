"""Steps on the count, the hips going on: of a few samples of the next step, the one whose feet
follow the beat (web/mirror/on_count.ts mirrors it name for name).

Both networks hear the music (music.py), yet the last second of motion says more about when the
next step falls than the count does, so left to their own samples each keeps a tempo of its own
(docs/music.md). A dancer on the count moves the feet between beats and lands them on the beat:
the recorded footwork (the summed speed of both ankles, training/data/count.py) swings once a
beat, lowest where a foot lands. So each step the dancer's guard draws SAMPLES of the network's
next step from the same input, as it does when it guards (guard.py), draws each sample's body as
the rollout will (its bones, carried by its root update: drawn_steps), and takes the standing one
whose footwork is nearest

    mean * (1 - STRENGTH * cos(2 pi * the count at the next step))

where `mean` is the dancer's own footwork over about the last MEAN_SECONDS. The footwork is read
from the drawn ankles, not from the ankle velocities the network writes beside its pose: those
follow the drawn ankles only loosely (correlation 0.5 for the leader, 0.8 for the follower, over
one duet), and choosing on them landed the steps on the beat at +0.27 / +0.24 where the drawn
ankles give +0.70 / +0.45 (python -m training.evaluation.rhythm --seeds 20 --seconds 30 --tempos
170, steered; the recording +0.27 / +0.36).

A sample whose hips would turn back the way they came (more than 90 degrees from their last step,
as evaluation/jitter.py counts a reversal) has HIPS m/s added to its miss: the networks' own hips
turn back 2.5-3.5x as often a second as the recorded dancers'. A penalty on each m/s the hips'
velocity changes smoothed them further but took the beat from her feet (her pulse 0.39x and 0.29x
the recording's at 1 and 2 m/s a m/s); passing over a reversal leaves it (0.49x; 20 seeds x 30 s
of `rhythm` at 170, steered, both turning limits then at 3 rad/s).

While a dancer turns faster than its TURNING, the footwork is left to the network and only the hips
are weighed (the first standing sample whose hips go on): a spin moves the ankles fast whatever the
count, and the pull on it broke her turns off (15.0 turns a minute, 0.65x the recorded follower's,
against 16.5 with her spins left alone; 10 seeds of `seeds`); his walks round went from 9.6 to 4.6
a minute, nobody steering, with his feet pulled from 3 rad/s (50 seeds of `lead`).

Outside a turn the choice also reads the figure being led (features.figure_block), as a dancer
feels it through the hands (`figure_turn`, FIGURE_TURN): while a turn of the dancer's own runs or
begins within FIGURE_AHEAD (hers for the follower, his own for the leader), the candidates whose
planned path turns FIGURE_TURN degrees or more its way are preferred; while no figure runs or comes,
those that turn less than that either way. It only chooses among the network's own samples, so
her body and timing stay her network's. Read by the networks alone, the figure moved her turns
little: with his own figures off she turned in 57 % of 4 s windows never asked and after 60 % of
requests (`lead --seeds 40`); chosen at 120 degrees, 50 % / 74 % (69 % the asked way; 40 seeds).
Over seeds 0-19 alone: at 90 degrees 45 % / 68 %, at 120 38 % / 78 %, at 180 52 % / 78 %
(--on-count-figure DEG); seeds 20-39 at 120 gave 62 % / 70 %, so 20 seeds do not tell them apart.

The feet are read as the contact layer draws them: a foot the network calls planted (its contact
above footik.CONTACT_THRESHOLD, where the layer locks it) counts as still, in each candidate and in
the dancer's footwork now (the feet planted in the step last taken, OnCount.took). The networks'
feet move about 1 m/s in the frames they call planted (docs/music.md), so a choice that read only
where the network drew them timed the steps by feet the page holds still. Read as drawn, over 15
seeds x 40 s at 170 (`rhythm --seeds 15 --seconds 40 --tempos 170`), nobody steering, her drawn
steps land on the beat at +0.45 against +0.38 and his at +0.14 against +0.09, his drawn footwork
repeats at 0.75x the recorded leader's pulse against 0.62x, hers 0.58x against 0.52x.

Two choices were measured and not shipped: her spins aimed at the count among the samples that keep
them, and her turn starts taken outside a spin (docs/results.md's tried table, "Her spins on the
count" and "Her turn starts taken"; their code is in the commits there).
"""
from __future__ import annotations

import numpy as np

from . import features as feat
from .music import MUSIC_OFFSETS, MUSIC_SIZE
from .footik import CONTACT_THRESHOLD
from .skeleton import FEET, FPS

SAMPLES = 8           # candidates each step (one batched run of the network)
STRENGTH = 1.0        # 0: the footwork's own mean; 1: from still on the beat to twice the mean between
MEAN_SECONDS = 1.0    # how long the dancer's own footwork is averaged over (about three steps)
# rad/s: turning faster than this, the dancer's footwork is left to the network: his turns are walks
# round (1.5-3 rad/s), hers spins (6-9).
TURNING = {"leader": 1.5, "follower": 6.0}
HIPS = 1.0            # m/s added to the footwork's miss of a candidate whose hips turn back
STILL = 0.002         # m a frame (6 cm/s): a shorter step of the hips stands still, and turns no way
FIGURE_TURN = 120.0   # degrees over the next second: a candidate whose planned path turns this much starts a turn
FIGURE_AHEAD = 2      # future keys (of KEY_STEP frames) within which a figure coming counts as running

# Where each role's input holds its own ankles' velocity (pose block: position, velocity, forward,
# up per joint; the step into this frame as drawn, so the footwork now and the drawn footwork of a
# sample agree); the count now is the music block's key at offset 0 (sin, cos of 2 pi count), the
# tempo (beats a second) the block's last number.
_POSE_JOINT = feat.POSE_SIZE // feat.N_JOINTS
_NOW_KEY = int(np.nonzero(MUSIC_OFFSETS == 0)[0][0]) * 4
ANKLE_VELOCITY_IN = {
    role: [feat.block_slices(layout)["self_pose"].start + _POSE_JOINT * j + 3 for j in FEET]
    for role, layout in (("leader", feat.LEADER_INPUT_LAYOUT), ("follower", feat.FOLLOWER_INPUT_LAYOUT))}
# The facing of the dancer's newest past trajectory key (KEY_STEP frames ago) in its root space now.
LAST_FACING = {
    role: feat.block_slices(layout)["self_trajectory_past"].start + (feat.KEYS - 1) * 4 + 2
    for role, layout in (("leader", feat.LEADER_INPUT_LAYOUT), ("follower", feat.FOLLOWER_INPUT_LAYOUT))}
# The joints whose steps the choice reads, the hips and both ankles, and where each role's input
# holds their positions [3, 3] and the hips' velocity (its own pose block, its root space now).
STEPPED = [0, *FEET]
POSITION_IN = {role: np.array([[feat.block_slices(layout)["self_pose"].start + _POSE_JOINT * j + k for k in range(3)]
                               for j in STEPPED])
               for role, layout in (("leader", feat.LEADER_INPUT_LAYOUT), ("follower", feat.FOLLOWER_INPUT_LAYOUT))}
HIP_VELOCITY_IN = {role: POSITION_IN[role][0] + 3 for role in POSITION_IN}
_ROOT_UPDATE_OUT = feat.block_slices(feat.OUTPUT_LAYOUT)["root_update"].start
_CONTACTS_OUT = feat.block_slices(feat.OUTPUT_LAYOUT)["contacts"]
# Where each role's input holds the figure block, and the figure kinds that are the dancer's own
# turn: hers for the follower, his own for the leader (features.FIGURE_KINDS).
FIGURE_IN = {role: feat.block_slices(layout)["figure"].start
             for role, layout in (("leader", feat.LEADER_INPUT_LAYOUT), ("follower", feat.FOLLOWER_INPUT_LAYOUT))}
OWN_TURN = {"leader": "his_turn", "follower": "her_turn"}
_NOW_FIGURE_KEY = int(np.nonzero(feat.FIGURE_OFFSETS == 0)[0][0])


def planted(outputs: np.ndarray) -> np.ndarray:
    """Which feet (left, right) each output [B, 323] plants [B, 2]: its contact above the contact
    layer's CONTACT_THRESHOLD, where footik.FootLock locks the drawn foot."""
    return np.atleast_2d(outputs)[:, _CONTACTS_OUT] > CONTACT_THRESHOLD


def footwork_now(x: np.ndarray, role: str, still: np.ndarray | None = None) -> float:
    """The dancer's footwork now (m/s: the summed speed of both ankles) from its input [I]; a foot
    `still` [2] says is planted counts 0."""
    return float(sum(np.linalg.norm(x[c:c + 3]) for k, c in enumerate(ANKLE_VELOCITY_IN[role])
                     if still is None or not still[k]))


def drawn_steps(outputs: np.ndarray, joints: np.ndarray, x: np.ndarray, role: str) -> np.ndarray:
    """How far the hips and each ankle move [B, 3, 3] (m, in the dancer's root space now) from
    where input x [I] has them to where each output [B, 323] draws them, its body `joints` [B, 17, 3]
    (guard.drawn_joints, in the next root's space) carried by the output's root update."""
    outputs, x = np.atleast_2d(outputs), np.atleast_2d(x)[0]
    dx, dz, dtheta = (outputs[:, _ROOT_UPDATE_OUT + i] for i in range(3))
    nxt = feat.from_root_space_directions(joints[:, STEPPED], dtheta[:, None])
    nxt[..., 0] += dx[:, None]
    nxt[..., 2] += dz[:, None]
    return nxt - x[POSITION_IN[role]]


def drawn_footwork(steps: np.ndarray, still: np.ndarray | None = None) -> np.ndarray:
    """The footwork [B] (m/s) of the steps drawn_steps gives: the summed speed of both ankles, a
    foot `still` [B, 2] says is planted counting 0."""
    speed = np.linalg.norm(steps[:, 1:], axis=-1)
    return (speed if still is None else np.where(still, 0.0, speed)).sum(-1) * FPS


def hips_turn_back(steps: np.ndarray, x: np.ndarray, role: str) -> np.ndarray:
    """Whether each of the steps drawn_steps gives [B] takes the hips back the way they came: more
    than 90 degrees from their step into this frame (input x's own hip velocity), both longer than
    STILL (evaluation/jitter.py counts the same turns)."""
    before = np.atleast_2d(x)[0][HIP_VELOCITY_IN[role]] / FPS
    step = steps[:, 0]
    return (step @ before < 0) & (np.linalg.norm(step, axis=-1) > STILL) & (np.linalg.norm(before) > STILL)


def turn_now(x: np.ndarray, role: str) -> float:
    """How fast and which way the dancer turns now (rad/s, signed as the output's root update turns)
    from its input [I]: its facing KEY_STEP frames ago, seen from its root now, lies the other way."""
    c = LAST_FACING[role]
    return float(-np.arctan2(x[c], x[c + 1]) * FPS / feat.KEY_STEP)


def turn_rate(x: np.ndarray, role: str) -> float:
    """How fast the dancer turns now (rad/s, unsigned): turn_now's size."""
    return abs(turn_now(x, role))


_FUTURE_OUT = feat.block_slices(feat.OUTPUT_LAYOUT)["trajectory_future"]


def planned_turn(outputs: np.ndarray) -> np.ndarray:
    """How far each output's [B, 323] planned path turns over the next second (degrees, signed as
    the root update turns): its facing at each future key (sin, cos), from 0 now, summed key to key
    so that a whole turn counts whole."""
    keys = np.atleast_2d(outputs)[:, _FUTURE_OUT].reshape(-1, feat.KEYS, 4)
    h = np.concatenate([np.zeros((len(keys), 1)), np.arctan2(keys[..., 2], keys[..., 3])], 1)
    return np.degrees(np.angle(np.exp(1j * np.diff(h, axis=1))).sum(1))


def starts_turn(outputs: np.ndarray, degrees: float) -> np.ndarray:
    """Whether each output [B, 323] starts a turn: its planned path turns `degrees` or more over
    the next second, either way [B]."""
    return np.abs(planned_turn(outputs)) >= degrees


def figure_way(x: np.ndarray, role: str) -> int | None:
    """The dancer's own turn the figure block of input x [I] says runs now or begins within
    FIGURE_AHEAD keys: its way (+1, -1); 0 when another figure runs or comes (her turn, for him);
    None when no figure does."""
    kinds = len(feat.FIGURE_KINDS)
    block = x[FIGURE_IN[role]:FIGURE_IN[role] + feat.FIGURE_SIZE].reshape(len(feat.FIGURE_OFFSETS), kinds, 2)
    inside = block[_NOW_FIGURE_KEY:_NOW_FIGURE_KEY + FIGURE_AHEAD + 1, :, 0].max(0)
    for k, (name, way) in enumerate(feat.FIGURE_KINDS):
        if name == OWN_TURN[role] and inside[k] > 0:
            return way
    return 0 if inside.max() > 0 else None


def count_next(x: np.ndarray) -> float:
    """The count at the next step (beats, its fraction only) from the music block ending input x."""
    music = x[len(x) - MUSIC_SIZE:]
    now = np.arctan2(music[_NOW_KEY], music[_NOW_KEY + 1]) / (2 * np.pi)
    return float(now + music[-1] / FPS)


class OnCount:
    """One dancer's footwork mean, kept across steps, and the footwork its next step aims at.
    `figure_turn` (None: the figure not read): outside a turn, the candidates the figure being led
    asks for are preferred (prefers)."""

    def __init__(self, role: str, samples: int = SAMPLES, strength: float = STRENGTH, hips: float = HIPS,
                 figure_turn: float | None = None):
        if role not in ANKLE_VELOCITY_IN:
            raise ValueError(f"role must be 'leader' or 'follower', got {role!r}")
        if samples < 2:
            raise ValueError("choosing on the count needs at least 2 samples")
        if figure_turn is not None and not figure_turn > 0:
            raise ValueError(f"figure_turn must be more than 0 degrees, got {figure_turn}")
        self.role, self.samples, self.strength, self.hips = role, samples, strength, hips
        self.figure_turn = figure_turn
        self.mean: float | None = None
        self.feet: np.ndarray | None = None   # [2] the feet planted in the step last taken (took)
        self.turning = False                  # this step the dancer turns faster than its TURNING

    def target(self, x: np.ndarray) -> float | None:
        """The footwork the next step aims at, for input x [I] (this step's: it moves the mean on);
        None while the dancer turns faster than its TURNING (its footwork is left to the network)."""
        x = np.atleast_2d(x)[0]
        now = footwork_now(x, self.role, self.feet)
        self.mean = now if self.mean is None else self.mean + (now - self.mean) / (MEAN_SECONDS * FPS)
        self.turning = turn_rate(x, self.role) > TURNING[self.role]
        if self.turning:
            return None
        return self.mean * (1.0 - self.strength * np.cos(2 * np.pi * count_next(x)))

    def restart(self) -> None:
        """Forget the dancer's footwork and feet before a new duet (its first step starts the mean)."""
        self.mean, self.feet = None, None

    def took(self, output: np.ndarray) -> None:
        """The step the dancer took (its output [323]): the feet it plants count as still in the
        footwork now of the next step's target."""
        self.feet = planted(output)[0]

    def prefers(self, outputs: np.ndarray, x: np.ndarray | None = None) -> np.ndarray | None:
        """Outside a turn, which candidates [B, 323] are preferred: with figure_turn, those that turn
        the way of the dancer's own turn the figure of input x [I] says runs or comes, or, no figure
        running or coming, those that start no turn (figure_way); None otherwise (no candidate
        preferred)."""
        if self.turning or self.figure_turn is None or x is None:
            return None
        way = figure_way(np.atleast_2d(x)[0], self.role)
        if way is None:
            return ~starts_turn(outputs, self.figure_turn)
        if way != 0:
            return planned_turn(outputs) * way >= self.figure_turn
        return None


def nearest_count(footwork: np.ndarray, turn_back: np.ndarray, target: float | None, standing: np.ndarray,
                  margin: float, hips: float = HIPS, prefers: np.ndarray | None = None) -> int:
    """The index of the candidate whose drawn footwork [B] (m/s) is nearest the target, `hips` m/s
    added to the miss of each whose hips turn back [B] (hips_turn_back), among those standing [B]
    (their upright margins, guard.py) at least `margin` inside the range; -1 when none does. With
    no target (the dancer turns) the footwork is left alone: the first standing one whose hips go on.
    With `prefers` [B] (OnCount.prefers: the candidates the figure asks for), only the standing ones
    among them are aimed when there are any; otherwise all the standing ones, as without it."""
    ok = np.asarray(standing) >= margin
    if not ok.any():
        return -1
    if prefers is not None and (ok & prefers).any():
        ok = ok & prefers
    miss = np.zeros(len(ok)) if target is None else np.abs(np.asarray(footwork) - target)
    return int(np.argmin(np.where(ok, miss + hips * np.asarray(turn_back), np.inf)))
