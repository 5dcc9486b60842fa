"""The duet at run time, in Python: the same loop the page runs (web/mirror/rollout.ts mirrors it).

Each dancer is a `Track` of 61 frames: 30 past, the current frame at index NOW = 30, and 30 slots
of planned future of which only the key frames (NOW+5, ..., NOW+30) are filled. The features are
then the very functions training used, read at frame NOW, so training and run time cannot differ.

One step: the leader's plan is its last predicted future bent toward the user's steering; both
models read the current state (the follower sees that plan as the leader's future); both outputs
move their dancer one frame on. Absurd output (non-finite, a joint > 3 m from the root, a root
jump > 1 m) resets that dancer beside its partner and is counted, never drawn.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import features as feat
from . import music
from .contact import ContactLayer
from .features import (FUTURE_OFFSETS, HISTORY, KEYS, Track, follower_input, from_root_space_directions,
                       from_root_space_points, leader_input)
from .skeleton import FEET, FPS, HANDS, KEY_JOINTS, forward_kinematics_reduced

NOW = HISTORY
TRACK_FRAMES = 2 * HISTORY + 1
OUT = feat.block_slices(feat.OUTPUT_LAYOUT)

MAX_SPEED = 0.8            # m/s of the steered path at full stick (the recorded leaders cover
                           # 0.49 m in a second at the median and 0.96 m at the 90th percentile)
STEER_HALFLIFE = 0.25      # s for the steered velocity to get halfway to the stick's
MAX_JOINT_DISTANCE = 3.0   # m from the root: beyond this the output is absurd
MAX_ROOT_JUMP = 1.0        # m in one step
MIN_ANKLE_HEIGHT = 0.04    # m: the lowest ankle height in the recordings
ANCHOR_RATE = 0.3          # share of the leader's distance to its anchor closed every frame
ANCHOR_FREE = 0.75         # m around the anchor where a leader nobody steers is not drawn at all
                           # in which neither foot is planted (scaled down by the contacts)
LEASH_DISTANCE = 2.0       # m: beyond this a follower is drawn toward its leader ...
LEASH_RATE = 0.1           # ... closing this share of the excess every frame
START_DISTANCE = 0.8       # m between the partners at the start and after a reset
# The figures both dancers read (features.figure_block, rollout.Figures): her turn, from his
# preparation to her finish, or his own turn, one way or the other, FIGURE_BEATS long. In the
# recording (training/data/led_figures.py) her turns last a median 3.3 beats (10-90 %: 2.0-8.2),
# 16.9 a minute, his 2.0 beats, 6.3 a minute, and both start anywhere in the two-beat group (her
# turns 4 7 6 9 7 9 4 10 per quarter beat): a figure the visitor asks for (her turn) starts on the
# next whole beat (under 0.4 s of waiting at 170 beats a minute), or when the figure running ends.
# Nobody asking, the leader leads figures of his own (Figures.own): after each figure he waits
# OWN_GAP_BEATS (drawn uniformly) and leads the next, his own turn in HIS_SHARE of them, either way
# alike: a figure every 7.2 beats on average (the wait for a beat included), as the recorded 23 a
# minute at 170 (16.9 hers, 6.3 his; plan_figures alone for an hour: 16.9 and 6.6).
FIGURE_BEATS = {"her_turn": 3.5, "his_turn": 2.0}
OWN_GAP_BEATS = (0.5, 6.5)
HIS_SHARE = 0.27
# A figure also becomes his hands plan (features.hands_plan_block): his lead hand (the left for
# her turn to the left, +1, the right for -1) rises above his head and comes down again, the other
# stays where it was. In the recording (training.evaluation.recorded_leads) his higher hand peaks
# above 1.6 m in 84 % of her turns (median 1.83 m; in 17 % of all frames), a third of a second
# before the turn completes: the left hand for 60 % of her turns to the left, at (0.02, 1.80, 0.28)
# m in his root space (x to his left, z ahead), the right hand mirrored for her turns to the right.
# RAISE: (up, down) in s: his hand goes up over the figure's first `up` seconds, is held until
# the figure ends and comes down over `down` after it. The plan asks 1.90 m, above the recorded
# 1.80: the network stops short of a planned hand (a median 1.76 m asked for 1.90). In the recording the hand also circles the way she turns; a
# planned circle (12 or 25 cm) left his hand's path as it was, so the plan holds none
# (docs/results.md, "The hands plan").
LEAD_HAND_RAISED = (0.02, 1.90, 0.28)  # m, the left hand, root space
RAISE = (0.4, 0.5)                     # s
# A figure also bends his planned path (lead_plan): it turns LEAD_TURN her way and moves
# LEAD_SIDE to his other side (his right for her turn to the left), eased as her planned turn. The
# recorded leader turns with her: over the 2.5 s from 1.7 s before her turn completes his facing
# goes her way by a median 38 degrees (quartiles -103 and +205, the 160 turns of the 12 takes as
# recorded and mirrored; training.evaluation.recorded_leads), and she reads the way from his body
# over the second before her turn (docs/results.md, "Which way she turns").
# With his plan left as it was she turned the asked way after 32 % of requests (18 % for her
# left); with it turned and moved aside (scripts/lead_way_probe.py plan DEG SIDE at commit
# 0c0428a, 20 seeds x 30 s, nobody steering): 45 degrees and 0 m 33 %, 0 and 0.6 m 29 %, 60 and
# 0.6 m 35 %, 90 and 0.3 m 44 %, 90 and 0.6 m 48 %, 90 and 1.0 m 45 %, 120 and 0.6 m 38 %, 150 and
# 0.3 m 47 %.
LEAD_TURN = 90.0   # degrees
LEAD_SIDE = 0.6    # m


def rotations_from_vectors(forward: np.ndarray, up: np.ndarray) -> np.ndarray:
    """[..., 3] forward (R ez) and up (R ey) -> orthonormal [..., 3, 3] (Gram-Schmidt on forward)."""
    z = forward / np.maximum(np.linalg.norm(forward, axis=-1, keepdims=True), 1e-9)
    x = np.cross(up, z)
    x /= np.maximum(np.linalg.norm(x, axis=-1, keepdims=True), 1e-9)
    y = np.cross(z, x)
    return np.stack([x, y, z], -1)


@dataclass
class Dancer:
    offsets: np.ndarray                       # [17, 3]
    track: Track
    contacts: np.ndarray = field(default_factory=lambda: np.zeros(2))
    intention: np.ndarray | None = None       # [6, 5, 3] world: what this dancer expects of its partner
    resets: int = 0
    leashed: int = 0                          # frames the leash moved this dancer

    @property
    def root(self):
        return self.track.root[NOW]

    @property
    def heading(self):
        return float(self.track.heading[NOW])

    @property
    def positions(self):
        return self.track.positions[NOW]


def start_dancer(offsets, start_pose: dict, root, heading) -> Dancer:
    """A dancer standing still in the start pose, with a still history and a still plan."""
    h = np.float64(heading)
    rot_local = rotations_from_vectors(np.asarray(start_pose["forward"]), np.asarray(start_pose["up"]))
    rotations = np.einsum("ij,njk->nik", rotation_y(h), rot_local)
    hip = from_root_space_points(np.asarray(start_pose["hip"], float), np.asarray(root, float), h)
    positions = forward_kinematics_reduced(np.asarray(offsets), hip, rotations)
    track = Track(positions=np.repeat(positions[None], TRACK_FRAMES, 0),
                  rotations=np.repeat(rotations[None], TRACK_FRAMES, 0),
                  root=np.repeat(np.asarray(root, float)[None], TRACK_FRAMES, 0),
                  heading=np.full(TRACK_FRAMES, h))
    return Dancer(np.asarray(offsets, float), track)


def rotation_y(heading: float) -> np.ndarray:
    c, s = np.cos(heading), np.sin(heading)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def output_is_absurd(output: np.ndarray) -> bool:
    if not np.all(np.isfinite(output)):
        return True
    pose = output[OUT["pose"]].reshape(feat.N_JOINTS, 12)
    jump = np.linalg.norm(output[OUT["root_update"]][:2])
    return bool(np.linalg.norm(pose[:, :3], axis=-1).max() > MAX_JOINT_DISTANCE
                or jump > MAX_ROOT_JUMP)


def apply_output(d: Dancer, output: np.ndarray) -> None:
    """Move the dancer one frame on with a model output O (raw, 323)."""
    t = d.track
    dx, dz, dtheta = output[OUT["root_update"]]
    root = from_root_space_points(np.array([dx, 0.0, dz]), t.root[NOW], t.heading[NOW])[[0, 2]]
    heading = t.heading[NOW] + dtheta
    heading = float(np.angle(np.exp(1j * heading)))
    # Shift the past one frame back; the current slot gets the new frame.
    for a in (t.positions, t.rotations, t.root, t.heading):
        a[:NOW] = a[1:NOW + 1]
    t.root[NOW], t.heading[NOW] = root, heading
    pose = output[OUT["pose"]].reshape(feat.N_JOINTS, 12)
    forward = from_root_space_directions(pose[:, 6:9], heading)
    up = from_root_space_directions(pose[:, 9:12], heading)
    t.rotations[NOW] = rotations_from_vectors(forward, up)
    hip = from_root_space_points(pose[0, :3], root, heading)
    t.positions[NOW] = forward_kinematics_reduced(d.offsets, hip, t.rotations[NOW])
    # The predicted hip height can sag a few cm below what the legs need; lifting the whole body
    # keeps the ankles on or above the floor without bending a bone.
    lift = MIN_ANKLE_HEIGHT - t.positions[NOW][FEET, 1].min()
    if lift > 0:
        t.positions[NOW][:, 1] += lift
    # The predicted future root path becomes the plan (the leader's is bent by steering later).
    future = output[OUT["trajectory_future"]].reshape(KEYS, 4)
    keys = NOW + FUTURE_OFFSETS
    world = from_root_space_points(np.stack([future[:, 0], np.zeros(KEYS), future[:, 1]], -1), root, heading)
    t.root[keys] = world[:, [0, 2]]
    fwd = from_root_space_directions(np.stack([future[:, 2], np.zeros(KEYS), future[:, 3]], -1), heading)
    t.heading[keys] = np.arctan2(fwd[:, 0], fwd[:, 2])
    d.contacts = np.clip(output[OUT["contacts"]], 0, 1)


def reset_beside(d: Dancer, partner: Dancer, start_pose: dict) -> None:
    """Recover a dancer that produced absurd output: stand it in front of its partner, facing it."""
    p_heading = partner.heading
    root = partner.root + START_DISTANCE * np.array([np.sin(p_heading), np.cos(p_heading)])
    fresh = start_dancer(d.offsets, start_pose, root, p_heading + np.pi)
    d.track, d.contacts, d.resets = fresh.track, np.zeros(2), d.resets + 1


@dataclass
class Steering:
    """The user's stick (world x, z; length <= 1) turned into a smooth velocity, and the anchor
    that velocity carries: the spot the leader dances around. It moves only while steered."""
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(2))
    anchor: np.ndarray = field(default_factory=lambda: np.zeros(2))

    def update(self, stick: np.ndarray, dt: float = 1 / FPS) -> None:
        target = np.asarray(stick, float) * MAX_SPEED
        self.velocity = target + (self.velocity - target) * 0.5 ** (dt / STEER_HALFLIFE)
        self.anchor = self.anchor + self.velocity * dt


def steer_plan(leader: Dancer, steering: Steering, stick: np.ndarray) -> None:
    """Bend the leader's planned future root path toward the stick.

    With no stick, the plan is the leader's own last prediction (it dances on its own). With the
    stick held, each key moves toward where the smoothed steering velocity carries the anchor,
    in proportion to how far the stick is pushed.
    """
    steering.update(stick)
    weight = min(1.0, float(np.linalg.norm(stick)))
    if weight <= 0:
        return
    t = leader.track
    for k, off in enumerate(FUTURE_OFFSETS):
        target = steering.anchor + steering.velocity * off / FPS
        t.root[NOW + off] += weight * (target - t.root[NOW + off])


@dataclass
class Led:
    """One figure the leader leads: `name` her_turn or his_turn, to the dancer's left (way +1,
    counterclockwise seen from above) or right (-1), from duet frame `start` to `end` (both
    danced); `asked` when the visitor asked for it; `hands`: his hands (left, right) in his root
    space when his plan for it began."""
    name: str
    way: int
    start: int
    end: int
    asked: bool = False
    hands: np.ndarray | None = None


@dataclass
class Figures:
    """The figures of a duet: those danced and planned, in time order, and whether the leader
    leads his own (`own`; the page's ?figures=0 turns them off) with `rng` drawing when and which."""
    own: bool = True
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))
    led: list[Led] = field(default_factory=list)

    def at(self, frame: int) -> Led | None:
        """The figure danced at `frame`, or None."""
        return next((f for f in self.led if f.start <= frame <= f.end), None)

    def spans(self, frame: int) -> np.ndarray:
        """[M, 3] (kind, start, end) of every figure (features.figure_block), in the frames of a
        track whose NOW is `frame`."""
        return np.array([(feat.FIGURE_KINDS.index((f.name, f.way)), f.start - frame + NOW, f.end - frame + NOW)
                         for f in self.led], dtype=np.int64).reshape(-1, 3)


def frames_to_beat(duet: "Duet", at_frame: int, beat: float) -> int:
    """Frames from `at_frame` until the count reaches `beat` (the count runs on one step a frame)."""
    now = duet.beat + (at_frame - duet.frame) * music.beats_per_step(duet.tempo)
    return at_frame + max(0, int(np.ceil((beat - now) / music.beats_per_step(duet.tempo) - 1e-9)))


def figure_from(duet: "Duet", frame: int, name: str, way: int, asked: bool) -> Led:
    """A figure `name` of `way` starting at the first whole beat of the count at or after `frame`."""
    per = music.beats_per_step(duet.tempo)
    beat = duet.beat + (frame - duet.frame) * per
    start = frames_to_beat(duet, frame, np.ceil(beat - 1e-9))
    return Led(name, 1 if way >= 0 else -1, start, start + int(round(FIGURE_BEATS[name] / per)), asked)


def ask_turn(duet: "Duet", direction: int) -> None:
    """The visitor asks the leader to lead her turn (+1 to her left, -1 to her right): it starts on
    the next beat, or after the figure running ends; it takes the place of a figure not begun."""
    f = duet.figures
    f.led = [x for x in f.led if x.start <= duet.frame]
    after = max([duet.frame] + [x.end + 1 for x in f.led])
    f.led.append(figure_from(duet, after, "her_turn", direction, True))


def plan_figures(duet: "Duet") -> None:
    """Each step: forget figures out of the past second, and with `own`, plan his next figure
    OWN_GAP_BEATS after the last (or after the start) once none is running or planned."""
    f = duet.figures
    f.led = [x for x in f.led if x.end >= duet.frame - HISTORY]
    if not f.own or any(x.end >= duet.frame for x in f.led):
        return
    last = max([x.end + 1 for x in f.led], default=duet.frame)
    # Three uniform draws, in this order (the page's mirror draws the same): the wait, whose turn,
    # and its way.
    gap = OWN_GAP_BEATS[0] + (OWN_GAP_BEATS[1] - OWN_GAP_BEATS[0]) * f.rng.random()
    name = "his_turn" if f.rng.random() < HIS_SHARE else "her_turn"
    way = 1 if f.rng.random() < 0.5 else -1
    start = frames_to_beat(duet, last, duet.beat + (last - duet.frame) * music.beats_per_step(duet.tempo) + gap)
    f.led.append(figure_from(duet, max(start, duet.frame + 1), name, way, False))


# A figure is led from LEAD_IN frames before it starts (the figure block shows it a second ahead:
# his preparation) to its end.
LEAD_IN = FPS


def leading(duet: "Duet") -> bool:
    """Whether the leader leads a figure the visitor asked for this step: one runs, or starts
    within LEAD_IN frames. His own figures do not count: drawn more freely through them too, she
    turned more (0.90x the recording's turns a minute against 0.80x) but her steered steps landed
    on the beat at +0.34 against +0.40 (docs/results.md, "Leading a turn")."""
    return any(f.asked and f.start - LEAD_IN <= duet.frame <= f.end for f in duet.figures.led)


def leader_variety(duet: "Duet", temperature: float) -> float:
    """The leader's variety this step: the manifest's leadingTemperature while he leads a figure
    the visitor asked for (`leading`), else `temperature` (his own, options.py). Drawn at his
    everyday variety, his samples seldom raised the lead hand for the hands plan; drawn more freely,
    his guard's choice near the plan has more to choose from."""
    if duet.leading_temperature is not None and leading(duet):
        return duet.leading_temperature
    return temperature


def figure_share(led: Led, frame: float) -> float:
    """How much of the figure's turn is planned done at `frame`, 0 to 1 (smoothstep over it)."""
    u = min(1.0, max(0.0, (frame - led.start) / max(led.end - led.start, 1)))
    return u * u * (3 - 2 * u)


def raised(led: Led, frame: float) -> float:
    """How far his lead hand is raised for `led` at `frame`, 0 to 1 (smoothsteps up and down)."""
    up = min(1.0, max(0.0, (frame - led.start) / (RAISE[0] * FPS)))
    down = min(1.0, max(0.0, (frame - led.end) / (RAISE[1] * FPS)))
    return up * up * (3 - 2 * up) * (1 - down * down * (3 - 2 * down))


def planning(duet: "Duet") -> Led | None:
    """The figure his hands plan is for: the one danced now or beginning within the next second,
    else one whose raise is coming down. A figure that follows another at once takes the plan
    over as soon as the one before ends."""
    near = [x for x in duet.figures.led if x.name == "her_turn"
            and x.start - HISTORY <= duet.frame <= x.end + int(RAISE[1] * FPS)]
    return next((x for x in near if x.end >= duet.frame), near[0] if near else None)


def hands_input(duet: "Duet") -> np.ndarray | None:
    """The leader's hands plan [KEYS, 2, 3] for the figure he plans (None: none): from where his
    hands are now to where the raise puts them at each future key, in his root space."""
    led, leader = planning(duet), duet.leader
    if led is None:
        return None
    hands = feat.to_root_space_points(leader.positions[HANDS], leader.root, leader.heading)
    if led.hands is None:
        led.hands = hands
    lead = 0 if led.way > 0 else 1
    top = np.array(LEAD_HAND_RAISED) * np.array([1.0 if lead == 0 else -1.0, 1.0, 1.0])
    out = np.repeat(led.hands[None], KEYS, 0) - hands[None]
    for k, off in enumerate(FUTURE_OFFSETS):
        u = raised(led, duet.frame + off)
        out[k, lead] = led.hands[lead] + u * (top - led.hands[lead]) - hands[lead]
    return out


def lead_plan(duet: "Duet") -> None:
    """While a figure is danced or about to be, bend the leader's planned path (after steer_plan):
    for her turn it turns LEAD_TURN degrees her way and moves LEAD_SIDE metres to his other side,
    for his own turn it turns a full turn his way, from now to each future key times the share of
    the turn planned between them."""
    t = duet.leader.track
    h = t.heading[NOW]
    his_left = np.array([np.cos(h), -np.sin(h)])   # his root space's +x on the floor (x, z)
    for led in duet.figures.led:
        turn, side = (np.radians(LEAD_TURN), LEAD_SIDE) if led.name == "her_turn" else (2 * np.pi, 0.0)
        for off in FUTURE_OFFSETS:
            share = figure_share(led, duet.frame + off) - figure_share(led, duet.frame)
            if share:
                t.heading[NOW + off] += led.way * turn * share
                t.root[NOW + off] -= led.way * side * share * his_left


def shift_dancer(d: Dancer, shift: np.ndarray) -> None:
    """Slide a dancer on the floor: current root, current pose and planned path together."""
    t = d.track
    t.root[NOW] += shift
    t.root[NOW + FUTURE_OFFSETS] += shift
    t.positions[NOW][:, [0, 2]] += shift


def follow_anchor(leader: Dancer, steering: Steering) -> None:
    """Draw the leader a little toward its anchor in the frames where its feet are free.

    The leader model reads the steered plan as an intention, not an order: fed its own predicted
    path it wanders (about 1.7 m in 3 s here), and steered it answers only in part. Pulling the
    root toward the anchor lets it travel where the user steers and keeps it near the spot the
    user left it at. The pull moves the whole body, so it acts only as far as no foot is planted
    (1 - the larger contact): a planted foot is never slid by it. Measured with the shipped models
    (training.evaluation.soak.steering_trials: 8 turns of 90 degrees), seconds until the leader
    moves within 30 degrees of the new direction: gated rate 0.15 0.77 s, 0.3 0.58 s, 0.5 0.53 s.

    Nobody steering, the pull spares a circle of ANCHOR_FREE around the anchor (shrinking to
    nothing as the steered speed grows, so steering answers as before): pinned to one spot, the
    leader travelled 0.04 m/s where the recorded one travels 0.75 (training.evaluation.lead).
    """
    free = 1.0 - float(np.clip(leader.contacts, 0.0, 1.0).max())
    radius = ANCHOR_FREE * max(0.0, 1.0 - float(np.linalg.norm(steering.velocity)) / MAX_SPEED)
    d = steering.anchor - leader.root
    dist = float(np.linalg.norm(d))
    if dist <= radius:
        return
    shift_dancer(leader, d * (1.0 - radius / dist) * ANCHOR_RATE * free)


def keep_close(follower: Dancer, leader: Dancer) -> bool:
    """Draw a follower that fell behind toward its leader.

    A steered leader can travel faster and straighter than any recorded one; the follower model
    then lags. The leash only acts beyond LEASH_DISTANCE, where the recordings hardly go (99 % of
    recorded frames are within 2.74 m), and moves at most a tenth of the excess per frame.
    """
    d = leader.root - follower.root
    dist = float(np.linalg.norm(d))
    if dist <= LEASH_DISTANCE:
        return False
    shift_dancer(follower, d / dist * (dist - LEASH_DISTANCE) * LEASH_RATE)
    return True


@dataclass
class Duet:
    leader: Dancer
    follower: Dancer
    start_pose: dict
    steering: Steering = field(default_factory=Steering)
    frame: int = 0
    layer: ContactLayer = field(default_factory=ContactLayer)
    # What is shown after the contact layer: [leader, follower] world positions [17, 3].
    shown: np.ndarray = field(default_factory=lambda: np.zeros((2, feat.N_JOINTS, 3)))
    resets_seen: int = 0
    figures: Figures = field(default_factory=Figures)
    # The music both dancers hear (training/mirror/music.py): its tempo (beats a minute) and the
    # count now (beats since it started). Each step moves the count on by one step of the tempo;
    # the page reads it from the audio clock instead (what the listener hears now).
    tempo: float = music.DEFAULT_TEMPO
    beat: float = 0.0
    # The leader's variety while he leads a figure the visitor asked for (the manifest's
    # leadingTemperature; None: his own throughout). leader_variety reads it.
    leading_temperature: float | None = None


def show(duet: Duet) -> None:
    """The contact layer on copies of both current poses (the tracks stay the networks')."""
    resets = duet.leader.resets + duet.follower.resets
    if resets != duet.resets_seen:   # a dancer placed anew must not drag its old locks along
        duet.layer.clear()
        duet.resets_seen = resets
    duet.shown[0] = duet.leader.positions
    duet.shown[1] = duet.follower.positions
    duet.layer.apply(duet.shown[0], duet.shown[1], duet.leader.contacts, duet.follower.contacts,
                     duet.leader.heading, duet.follower.heading)


def manifest_tempo(manifest: dict) -> float:
    """The music's tempo a duet dances to when none is asked for: the manifest's (export writes
    `music.tempo`), else music.DEFAULT_TEMPO."""
    return float(manifest.get("music", {}).get("tempo", music.DEFAULT_TEMPO))


def start_duet(manifest: dict, tempo: float | None = None, figures: bool = True, seed: int = 0) -> Duet:
    """Both dancers in their start poses, the music at `tempo` beats a minute (None: the
    manifest's) and its count at 0; with `figures` the leader leads figures of his own, drawn
    from `seed` (the page's ?figures=1 and ?seed=)."""
    sk, sp = manifest["skeleton"], manifest["startPose"]
    leader = start_dancer(sk["offsets"]["leader"], sp["leader"], [0.0, 0.0], 0.0)
    follower = start_dancer(sk["offsets"]["follower"], sp["follower"], [0.0, START_DISTANCE], np.pi)
    bpm = manifest_tempo(manifest) if tempo is None else float(tempo)
    if not np.isfinite(bpm) or bpm <= 0:
        raise ValueError(f"tempo must be a positive number of beats a minute, got {tempo}")
    return Duet(leader, follower, sp, Steering(anchor=leader.root.copy()), tempo=bpm,
                figures=Figures(own=figures, rng=np.random.default_rng([seed, 1])),
                leading_temperature=manifest.get("leadingTemperature"))


def music_input(duet: Duet) -> np.ndarray:
    """The music block [53] both dancers hear this step: the count now and the tempo."""
    return music.music_block(np.array(duet.beat), np.array(duet.tempo / 60.0))


def step_inputs(duet: Duet) -> tuple[np.ndarray, np.ndarray]:
    """Both models' inputs at NOW. Both read the figure being led (what her hand feels); only his
    hands plan says where his hands go."""
    now = np.array([NOW])
    figure = feat.figure_block(duet.figures.spans(duet.frame), now)
    moves = hands_input(duet)
    plan = None if moves is None else feat.hands_plan_block(moves[None], 1)
    heard = music_input(duet)
    return (leader_input(duet.follower.track, duet.leader.track, now, figure, plan, heard)[0],
            follower_input(duet.leader.track, duet.follower.track, now, figure, heard)[0])


def finish_step(duet: Duet, leader_output: np.ndarray, follower_output: np.ndarray,
                follower_intention: np.ndarray | None = None) -> None:
    for d, partner, out, role in ((duet.leader, duet.follower, leader_output, "leader"),
                                  (duet.follower, duet.leader, follower_output, "follower")):
        if output_is_absurd(out):
            reset_beside(d, partner, duet.start_pose[role])
            if d is duet.leader:
                duet.steering.anchor = duet.leader.root.copy()
        else:
            apply_output(d, out)
            if d is duet.leader:
                follow_anchor(d, duet.steering)
    if keep_close(duet.follower, duet.leader):
        duet.follower.leashed += 1
    if follower_intention is not None:
        f = duet.follower
        keys = follower_intention.reshape(KEYS, len(KEY_JOINTS), 3)
        f.intention = from_root_space_points(keys, f.root, f.heading)
    show(duet)
    duet.frame += 1
    duet.beat += music.beats_per_step(duet.tempo)


class OnnxPolicy:
    """One exported step model in onnxruntime (what the page runs, minus the browser)."""

    def __init__(self, path, threads: int = 1):
        from .policy import open_session
        self.session = open_session(path, threads)
        self.outputs = [o.name for o in self.session.get_outputs()]
        self.latent = self.session.get_inputs()[2].shape[1]

    def __call__(self, x: np.ndarray, temperature: float, rng: np.random.Generator):
        x = np.atleast_2d(x).astype(np.float32)
        noise = rng.random((x.shape[0], self.latent), dtype=np.float32)
        res = self.session.run(None, {"input": x, "temperature": np.array([temperature], np.float32),
                                      "noise": noise})
        return dict(zip(self.outputs, res))


def step(duet: Duet, leader_policy, follower_policy, stick, temperature: float,
         rng: np.random.Generator) -> None:
    plan_figures(duet)
    steer_plan(duet.leader, duet.steering, np.asarray(stick, float))
    lead_plan(duet)
    xl, xf = step_inputs(duet)
    ol = leader_policy(xl, leader_variety(duet, temperature), rng)
    of = follower_policy(xf, temperature, rng)
    finish_step(duet, ol["output"][0], of["output"][0],
                of["intention"][0] if "intention" in of else None)
