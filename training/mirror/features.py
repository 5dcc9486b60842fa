"""Feature vectors of the paper, in the root space of the character being predicted ("self").

Layout and conventions: docs/features.md. web/mirror/features.ts mirrors every public function here
with the same name in camelCase and the same order of numbers; tests/fixtures pin them together.

Functions take numpy arrays with optional leading batch dimensions, so training builds all
frames of a take at once while the page calls the same math for one frame.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .music import MUSIC_SIZE, music_at
from .skeleton import FEET, FPS, HANDS, JOINT_NAMES, KEY_JOINTS, Motion, root_from_motion

KEYS = 6                                     # trajectory keys per second (the paper's k)
KEY_STEP = FPS // KEYS                       # 5 frames between keys at 30 fps
PAST_OFFSETS = np.arange(-KEYS, 0) * KEY_STEP        # t-30 ... t-5
FUTURE_OFFSETS = np.arange(1, KEYS + 1) * KEY_STEP   # t+5 ... t+30
HISTORY = KEYS * KEY_STEP                    # 30 frames of past are needed
N_JOINTS = len(JOINT_NAMES)                  # 17
N_KEY_JOINTS = len(KEY_JOINTS)

TRAJECTORY_SIZE = KEYS * 4                   # 24
KEY_JOINTS_SIZE = KEYS * N_KEY_JOINTS * 3    # 90
POSE_SIZE = N_JOINTS * 12                    # 204
ROOT_UPDATE_SIZE = 3
CONTACTS_SIZE = 2
# The figure being led (figure_block), one of FIGURE_KINDS: her turn or his, to the dancer's left
# (way +1, counterclockwise seen from above) or right (-1), read at each key of the past second,
# now, and each key of the next second, as (inside, progress).
FIGURE_KINDS = (("her_turn", 1), ("her_turn", -1), ("his_turn", 1), ("his_turn", -1))
FIGURE_OFFSETS = np.arange(-KEYS, KEYS + 1) * KEY_STEP                 # t-30 ... t ... t+30
FIGURE_SIZE = len(FIGURE_OFFSETS) * len(FIGURE_KINDS) * 2              # 104
HANDS_PLAN_SIZE = 1 + KEYS * len(HANDS) * 3  # 37: shown, then where each hand is to go at each key

# (name, size) in order; docs/features.md explains each block.
FOLLOWER_INPUT_LAYOUT = [
    ("partner_trajectory_past", TRAJECTORY_SIZE), ("partner_trajectory_future", TRAJECTORY_SIZE),
    ("partner_key_joints_past", KEY_JOINTS_SIZE), ("partner_pose", POSE_SIZE),
    ("self_trajectory_past", TRAJECTORY_SIZE), ("self_key_joints_past", KEY_JOINTS_SIZE),
    ("self_pose", POSE_SIZE), ("figure", FIGURE_SIZE), ("music", MUSIC_SIZE),
]
LEADER_INPUT_LAYOUT = [
    ("partner_trajectory_past", TRAJECTORY_SIZE), ("partner_key_joints_past", KEY_JOINTS_SIZE),
    ("partner_pose", POSE_SIZE),
    ("self_trajectory_past", TRAJECTORY_SIZE), ("self_key_joints_past", KEY_JOINTS_SIZE),
    ("self_pose", POSE_SIZE), ("control", TRAJECTORY_SIZE), ("figure", FIGURE_SIZE),
    ("hands_plan", HANDS_PLAN_SIZE), ("music", MUSIC_SIZE),
]
OUTPUT_LAYOUT = [
    ("root_update", ROOT_UPDATE_SIZE), ("trajectory_future", TRAJECTORY_SIZE),
    ("key_joints_future", KEY_JOINTS_SIZE), ("pose", POSE_SIZE), ("contacts", CONTACTS_SIZE),
]
INTENTION_LAYOUT = [("partner_key_joints_future", KEY_JOINTS_SIZE)]
INPUT_SIZE = sum(s for _, s in FOLLOWER_INPUT_LAYOUT)     # 817: the follower's input
LEADER_INPUT_SIZE = sum(s for _, s in LEADER_INPUT_LAYOUT)  # 854: the same blocks, control, figure, hands plan, music
OUTPUT_SIZE = sum(s for _, s in OUTPUT_LAYOUT)            # 323
INTENTION_SIZE = KEY_JOINTS_SIZE                          # 90
INPUT_SIZES = {"follower": INPUT_SIZE, "leader": LEADER_INPUT_SIZE}

# Foot contact: ankle joint near the floor and nearly still. The ankle of a flat foot sits
# 7-11 cm up in this data (heels included), so 15 cm leaves room; 0.5 m/s separates a planted
# foot from a stepping one at 30 fps.
CONTACT_HEIGHT = 0.15
CONTACT_SPEED = 0.5


# ---------------------------------------------------------------- root space

def to_root_space_points(points, root, heading):
    """World points [..., 3] -> root space. root (x, z) [..., 2] and heading [...] must broadcast
    against points[..., 0] (callers add the axes)."""
    c, s = np.cos(heading), np.sin(heading)
    dx, dz = points[..., 0] - root[..., 0], points[..., 2] - root[..., 1]
    # R_y(-heading): the heading direction (sin h, 0, cos h) maps to +Z.
    return np.stack([c * dx - s * dz, np.broadcast_to(points[..., 1], dx.shape), s * dx + c * dz], -1)


def to_root_space_directions(dirs, heading):
    """World directions [..., 3] -> root space (rotation only); heading broadcasts as above."""
    c, s = np.cos(heading), np.sin(heading)
    x, z = dirs[..., 0], dirs[..., 2]
    return np.stack([c * x - s * z, np.broadcast_to(dirs[..., 1], x.shape), s * x + c * z], -1)


def from_root_space_points(points, root, heading):
    """Inverse of to_root_space_points."""
    c, s = np.cos(heading), np.sin(heading)
    x, z = points[..., 0], points[..., 2]
    return np.stack([c * x + s * z + root[..., 0], np.broadcast_to(points[..., 1], x.shape),
                     -s * x + c * z + root[..., 1]], -1)


def from_root_space_directions(dirs, heading):
    return to_root_space_directions(dirs, -heading)


# ---------------------------------------------------------------- blocks

def trajectory_block(key_roots, key_headings, root, heading):
    """Root keys (x, z) [..., K, 2] and headings [..., K] -> [..., K*4] (x, z, fwd x, fwd z)."""
    pos = np.concatenate([key_roots[..., :1], np.zeros_like(key_roots[..., :1]), key_roots[..., 1:]], -1)
    local = to_root_space_points(pos, root[..., None, :], heading[..., None])
    fwd = np.stack([np.sin(key_headings), np.zeros_like(key_headings), np.cos(key_headings)], -1)
    fwd_local = to_root_space_directions(fwd, heading[..., None])
    block = np.stack([local[..., 0], local[..., 2], fwd_local[..., 0], fwd_local[..., 2]], -1)
    return block.reshape(block.shape[:-2] + (block.shape[-2] * 4,))


def key_joints_block(key_positions, root, heading):
    """Key-joint positions [..., K, 5, 3] -> [..., K*5*3] in root space."""
    local = to_root_space_points(key_positions, root[..., None, None, :], heading[..., None, None])
    return local.reshape(local.shape[:-3] + (local.shape[-3] * local.shape[-2] * 3,))


def pose_block(positions, previous_positions, rotations, root, heading, fps=FPS):
    """Joints [..., 17, 3], the frame before, world rotations [..., 17, 3, 3] -> [..., 204].

    Per joint: position, velocity (finite difference, m/s), forward (R ez) and up (R ey) vectors.
    """
    h = heading[..., None]
    pos = to_root_space_points(positions, root[..., None, :], h)
    vel = to_root_space_directions((positions - previous_positions) * fps, h)
    fwd = to_root_space_directions(rotations[..., :, 2], h)
    up = to_root_space_directions(rotations[..., :, 1], h)
    block = np.concatenate([pos, vel, fwd, up], -1)
    return block.reshape(block.shape[:-2] + (block.shape[-2] * 12,))


def root_update(root, heading, next_root, next_heading):
    """(dx, dz) of the next root in this root's space, and the wrapped heading change."""
    d = np.concatenate([next_root[..., :1] - root[..., :1], np.zeros_like(root[..., :1]),
                        next_root[..., 1:] - root[..., 1:]], -1)
    local = to_root_space_directions(d, heading)
    dtheta = np.angle(np.exp(1j * (next_heading - heading)))
    return np.stack([local[..., 0], local[..., 2], dtheta], -1)


def foot_contacts(positions, previous_positions, fps=FPS):
    """[..., 17, 3] -> [..., 2] in {0, 1}: ankle low and slow."""
    feet, prev = positions[..., FEET, :], previous_positions[..., FEET, :]
    speed = np.linalg.norm(feet - prev, axis=-1) * fps
    return ((feet[..., 1] < CONTACT_HEIGHT) & (speed < CONTACT_SPEED)).astype(np.float64)


# ---------------------------------------------------------------- one dancer over time

@dataclass
class Track:
    """A dancer as the features see it: motion plus the root per frame (30 fps), and the count of
    the music it dances to when it is known (a recorded take's, training/data/count.py)."""
    positions: np.ndarray   # [F, 17, 3]
    rotations: np.ndarray   # [F, 17, 3, 3]
    root: np.ndarray        # [F, 2]
    heading: np.ndarray     # [F]
    beat: np.ndarray | None = None   # [F] the count, beats since the music started

    @classmethod
    def from_motion(cls, motion: Motion, beat: np.ndarray | None = None) -> "Track":
        root, heading = root_from_motion(motion)
        return cls(motion.positions, motion.rotations, root, heading, beat)

    @property
    def frames(self) -> int:
        return self.root.shape[0]


def valid_frames(frames: int) -> np.ndarray:
    """Frames t with a full second of past and a full second of future after t+1."""
    return np.arange(HISTORY, frames - HISTORY - 1)


def _trajectory_at(track, frames, offsets, root, heading):
    idx = frames[:, None] + offsets[None]
    return trajectory_block(track.root[idx], track.heading[idx], root, heading)


def _key_joints_at(track, frames, offsets, root, heading):
    idx = frames[:, None] + offsets[None]
    return key_joints_block(track.positions[idx][:, :, KEY_JOINTS], root, heading)


def _pose_at(track, frames, root, heading):
    return pose_block(track.positions[frames], track.positions[frames - 1],
                      track.rotations[frames], root, heading)


def music_of(partner: Track, me: Track, frames: np.ndarray, music: np.ndarray | None) -> np.ndarray:
    """The music block [N, 53]: as given (the rollout's clock), else from the count the tracks carry."""
    if music is not None:
        return np.broadcast_to(np.asarray(music, float), (len(frames), MUSIC_SIZE))
    for track in (me, partner):
        if track.beat is not None:
            return music_at(track.beat, frames)
    raise ValueError("no count: the tracks carry no beat and no music block was given "
                     "(a recorded take's count: training/data/count.py; a rollout's: its clock)")


def follower_input(partner: Track, me: Track, frames: np.ndarray, figure: np.ndarray | None = None,
                   music: np.ndarray | None = None) -> np.ndarray:
    """Input I [N, 817] for the follower at `frames` (partner = leader, whose future is steered),
    then the figure being led (figure_block's [N, 104]; None: none) and the music last
    (music_block's [N, 53]; None: the count the tracks carry)."""
    root, heading = me.root[frames], me.heading[frames]
    return np.concatenate([
        _trajectory_at(partner, frames, PAST_OFFSETS, root, heading),
        _trajectory_at(partner, frames, FUTURE_OFFSETS, root, heading),
        _key_joints_at(partner, frames, PAST_OFFSETS, root, heading),
        _pose_at(partner, frames, root, heading),
        _trajectory_at(me, frames, PAST_OFFSETS, root, heading),
        _key_joints_at(me, frames, PAST_OFFSETS, root, heading),
        _pose_at(me, frames, root, heading),
        figure_block(None, frames) if figure is None else figure,
        music_of(partner, me, frames, music),
    ], -1)


def figure_block(figures: np.ndarray | None, frames: np.ndarray) -> np.ndarray:
    """The figure being led [N, 104], which both dancers read: at each of FIGURE_OFFSETS from each
    frame (the past second, now, the next second), for each of FIGURE_KINDS, `inside` (1 while a
    figure of that kind runs) and `progress` (0 at its start to 1 at its end; 0 outside).

    `figures` [M, 3] holds (kind, start, end) per figure, kind an index into FIGURE_KINDS, start
    and end in the frames of `frames` (both danced); None or empty: no figure. In training they
    are the recorded couple's (training/data/led_figures.py: her turns from his preparation to her
    finish, his own turns); at run time the visitor's and the leader's own (rollout.Figures). A
    salsa lead reaches the follower through the joined hands, which a capture of positions does
    not hold: this block stands for what her hand feels and his hand does. It asks nothing of her
    body or timing."""
    frames = np.asarray(frames)
    out = np.zeros((len(frames), len(FIGURE_OFFSETS), len(FIGURE_KINDS), 2))
    t = frames[:, None] + FIGURE_OFFSETS[None]
    for w, start, end in (np.zeros((0, 3), np.int64) if figures is None else np.asarray(figures, np.int64)):
        inside = (t >= start) & (t <= end)
        out[..., w, 0] = np.maximum(out[..., w, 0], inside)
        out[..., w, 1] = np.where(inside, (t - start) / max(end - start, 1), out[..., w, 1])
    return out.reshape(len(frames), FIGURE_SIZE)


def hands_plan_block(moves: np.ndarray | None, n: int) -> np.ndarray:
    """The leader's hands plan [n, 37]: `shown` (1 when a plan is given), then how far each hand
    (left, right) is to move from where it is now to where it is at each future key, in his root
    space now ([n, KEYS, 2, 3] flattened key by key). None: no plan (zeros), and his hands go
    where he likes, as he learnt from the samples whose plan was hidden. A raised hand is how a
    salsa leader leads her turn; this block is how a visitor raises it."""
    out = np.zeros((n, HANDS_PLAN_SIZE))
    if moves is not None:
        out[:, 0] = 1.0
        out[:, 1:] = np.asarray(moves).reshape(n, -1)
    return out


def hands_moves(me: Track, frames: np.ndarray) -> np.ndarray:
    """[N, KEYS, 2, 3] the recorded hands' moves from each frame to each future key, in the root
    space at the frame: the hands plan of the leader's samples."""
    root, heading = me.root[frames], me.heading[frames]
    idx = frames[:, None] + FUTURE_OFFSETS[None]
    future = to_root_space_points(me.positions[idx][:, :, HANDS], root[:, None, None], heading[:, None, None])
    now = to_root_space_points(me.positions[frames][:, HANDS], root[:, None], heading[:, None])
    return future - now[:, None]


def leader_input(partner: Track, me: Track, frames: np.ndarray, figure: np.ndarray | None = None,
                 hands_plan: np.ndarray | None = None, music: np.ndarray | None = None) -> np.ndarray:
    """Input I [N, 854] for the leader (partner = follower, control = own future trajectory, then
    the figure being led: figure_block's [N, 104], and the hands plan: hands_plan_block's [N, 37],
    none when not given; the music last, as the follower's)."""
    root, heading = me.root[frames], me.heading[frames]
    return np.concatenate([
        _trajectory_at(partner, frames, PAST_OFFSETS, root, heading),
        _key_joints_at(partner, frames, PAST_OFFSETS, root, heading),
        _pose_at(partner, frames, root, heading),
        _trajectory_at(me, frames, PAST_OFFSETS, root, heading),
        _key_joints_at(me, frames, PAST_OFFSETS, root, heading),
        _pose_at(me, frames, root, heading),
        _trajectory_at(me, frames, FUTURE_OFFSETS, root, heading),
        figure_block(None, frames) if figure is None else figure,
        hands_plan_block(None, len(frames)) if hands_plan is None else hands_plan,
        music_of(partner, me, frames, music),
    ], -1)


def output_features(me: Track, frames: np.ndarray) -> np.ndarray:
    """Output O [N, 323]: the self at t+1, in the root space of t+1 (root update in t's)."""
    nxt = frames + 1
    root, heading = me.root[nxt], me.heading[nxt]
    return np.concatenate([
        root_update(me.root[frames], me.heading[frames], root, heading),
        _trajectory_at(me, nxt, FUTURE_OFFSETS, root, heading),
        _key_joints_at(me, nxt, FUTURE_OFFSETS, root, heading),
        _pose_at(me, nxt, root, heading),
        foot_contacts(me.positions[nxt], me.positions[frames]),
    ], -1)


def intention_target(partner: Track, me: Track, frames: np.ndarray) -> np.ndarray:
    """The partner's key joints 1 s ahead [N, 90], in the self root space at t."""
    return _key_joints_at(partner, frames, FUTURE_OFFSETS, me.root[frames], me.heading[frames])


def block_slices(layout):
    """{name: slice} for a layout list."""
    out, start = {}, 0
    for name, size in layout:
        out[name] = slice(start, start + size)
        start += size
    return out


# ---------------------------------------------------------------- normalization

STD_FLOOR = 1e-2


def normalization(x: np.ndarray, floor: float = STD_FLOOR):
    """Mean and std per feature; the floor keeps near-constant features (a contact that is
    always 1, the y of a root key) from being blown up into noise."""
    mean = x.mean(0)
    std = np.maximum(x.std(0), floor)
    return mean.astype(np.float32), std.astype(np.float32)
