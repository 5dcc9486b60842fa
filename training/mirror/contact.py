"""The run-time contact layer: what is shown of the duet (web/mirror/contact.ts mirrors it name for name).

The networks place each dancer on its own; three things they do not guarantee are fixed here, on
copies of the current poses, never on the Track the features read (so the networks' own motion
stays what they made, and every metric can be read with and without this layer):

1. bodies do not pass through each other: where the two spines come closer than 2 x TORSO_RADIUS
   (metrics.interaction's test), both bodies are moved apart horizontally, half the shortfall each;
2. hands meet when the model brings them within reach: the closest pair of hands of the two
   dancers, once closer than HAND_REACH, is drawn toward a grip around its midpoint by two-bone IK
   of both arms, fully at HAND_FULL and closer, with a weight that rises and falls smoothly;
3. planted feet stay planted: footik.FootLock on both dancers, last, so that a body moved by 1.
   keeps its feet where they were.

First of all, each body's path over the floor glides (HIP_GLIDE): the networks draw a new root
step each frame, and the follower's hips turned back 3.8x as often a second as the recorded
follower's (training.evaluation.jitter). The whole body is moved to where its hips' smoothed path
is, except the feet: a free foot stays where the network put it on the floor, a planted one at its
lock (footik.FootLock, last), and the legs take up the difference.
"""
from __future__ import annotations

import numpy as np

from .footik import CONTACT_THRESHOLD, FootLock, two_bone_ik
from ..evaluation.metrics import TORSO_RADIUS, closest_on_segments
from .skeleton import HANDS, PARENTS, SPINE

SEPARATION = 2 * TORSO_RADIUS + 0.01   # m between the spines after the push (1 cm to spare)
# The layer completes a hold the networks nearly make; it does not drag a hand across the gap.
# Reaching from 45 cm (fully from 25 cm), the hands met in 4-5x as many steered frames as the
# recorded couple's and the arm bent outside its recorded range; from 25 cm still 2x. From 20
# cm (the distance the hand-hold measure counts) it adds little to what the networks do
# (docs/plausibility.md).
HAND_REACH = 0.20      # m: a hand pair closer than this starts to meet
HAND_FULL = 0.10       # m: at or below this the hands meet fully
GRIP = 0.06            # m between the two hands' joints when they meet (palm to palm)
HOLD_RATE = 0.3        # share of the way the hold weight moves up to its target every step
# ... and down: the networks' hands part faster than the layer let go at HOLD_RATE (the shown hands
# stayed within 20 cm for 3-4 steps after the networks' left it, 1.57x the recording's hold share
# against the networks' own 1.40x), so a hold ends in about two steps.
RELEASE_RATE = 0.7
ELBOW_POLE = (0.0, -1.0, 0.0)   # a straight arm bends its elbow downward
MIN_ELBOW_BEND = 0.6   # radians: the recorded elbows bend at least 0.6-0.7 in 99.5 % of frames
# Each step the shown hips move by a running mean of the network's steps over the floor: they take
# HIP_GLIDE of the way from the step they last made to the network's new one (horizontal only;
# height and turning stay the network's). The glide smooths velocity, not place, so the shown hips
# turn back only when the network's keep going back, and stay within a few centimetres of them
# (the running mean lags the steps by (1 - HIP_GLIDE) / HIP_GLIDE frames, 2.3 at 0.3). Her drawn
# hips against the recorded follower's (training.evaluation.jitter, 20 seeds x 30 s, steered /
# nobody steering): reversals a second 1.20x / 1.00x, speed change 1.14x / 1.12x (his 1.24x /
# 1.27x and 0.98x / 0.93x). The glide before kept a share of the distance to where the network
# put the hips, and only while no foot was planted: the share it passed on changed with her
# contacts every frame, and her drawn hips turned back 1.55x / 1.38x as often. Holding this one
# while a foot is planted gave 1.35x; 0.2 trails a steered walk by 4 frames, 0.5 gave 1.21x
# (6 seeds each). The glide moves the body, not the feet: a free foot stays where the network put
# it on the floor and a planted one at its lock (footik.FootLock.apply), so the drawn steps land
# when the network's do.
HIP_GLIDE = 0.3


def spine_gap(a: np.ndarray, b: np.ndarray) -> tuple[float, np.ndarray]:
    """Closest distance between the two spines (positions [17, 3]) and the horizontal unit
    direction from b's closest point to a's (the way to push a; b goes the other way)."""
    pa0, pa1 = a[SPINE[:-1]][:, None], a[SPINE[1:]][:, None]          # [3, 1, 3]: a's segments
    pb0, pb1 = b[SPINE[:-1]][None], b[SPINE[1:]][None]                # [1, 3, 3]: b's
    s, t = closest_on_segments(pa0, pa1, pb0, pb1)                    # [3, 3] pairs
    diff = (pa0 + (pa1 - pa0) * s[..., None]) - (pb0 + (pb1 - pb0) * t[..., None])
    dist = np.linalg.norm(diff, axis=-1)
    i, j = np.unravel_index(np.argmin(dist), dist.shape)   # the first of equal pairs, as web/mirror/contact.ts
    best, away = float(dist[i, j]), diff[i, j]
    away = np.array([away[0], 0.0, away[2]])
    n = float(np.linalg.norm(away))
    if n < 1e-6:   # one spine right above the other: push along the line between the hips
        away = np.array([a[0, 0] - b[0, 0], 0.0, a[0, 2] - b[0, 2]])
        n = float(np.linalg.norm(away))
        if n < 1e-6:
            away, n = np.array([1.0, 0.0, 0.0]), 1.0
    return best, away / n


def separate(a: np.ndarray, b: np.ndarray) -> float:
    """Move both bodies apart (in place) until their spines are SEPARATION apart; returns the
    distance each moved (0 when they were apart already)."""
    gap, away = spine_gap(a, b)
    if gap >= SEPARATION:
        return 0.0
    push = (SEPARATION - gap) / 2
    a += away * push
    b -= away * push
    return push


def closest_hands(a: np.ndarray, b: np.ndarray) -> tuple[int, int, float]:
    """Indices into HANDS of the closest hand pair of the two dancers, and its distance."""
    best = (0, 0, np.inf)
    for i in range(len(HANDS)):
        for j in range(len(HANDS)):
            d = float(np.linalg.norm(a[HANDS[i]] - b[HANDS[j]]))
            if d < best[2]:
                best = (i, j, d)
    return best


def reach_weight(distance: float) -> float:
    """1 at HAND_FULL and closer, 0 at HAND_REACH and beyond, linear between."""
    return min(max((HAND_REACH - distance) / (HAND_REACH - HAND_FULL), 0.0), 1.0)


def move_hand(positions: np.ndarray, hand: int, target: np.ndarray) -> None:
    """Two-bone IK of the arm (shoulder - forearm - hand) that ends at `hand`."""
    elbow = PARENTS[hand]
    two_bone_ik(positions, PARENTS[elbow], elbow, hand, target, ELBOW_POLE, MIN_ELBOW_BEND)


class HipGlide:
    """One dancer's shown path over the floor (HIP_GLIDE): where its hips were shown, the step they
    made last, and where the network put them last."""

    def __init__(self):
        self.shown = None               # the shown hips (x, z), None: not yet shown
        self.step = np.zeros(2)         # the shown hips' last step (x, z)
        self.network = np.zeros(2)      # where the network put the hips last (x, z)

    def clear(self) -> None:
        self.shown = None

    def apply(self, positions: np.ndarray) -> None:
        """Move the body [17, 3] (world, in place) to its hips' smoothed path over the floor: the
        shown hips step by the running mean of the network's steps. Planted feet stay where they
        are by the foot locks, applied last."""
        hips = positions[0, [0, 2]].copy()
        if self.shown is None:
            self.shown, self.step, self.network = hips.copy(), np.zeros(2), hips.copy()
        self.step = self.step + HIP_GLIDE * ((hips - self.network) - self.step)
        self.network = hips
        self.shown = self.shown + self.step
        positions[:, [0, 2]] += self.shown - hips

    def glided(self) -> np.ndarray:
        """How far (x, z) the last apply moved the body from where the network put it."""
        return np.zeros(2) if self.shown is None else self.shown - self.network


class ContactLayer:
    """State kept between steps: both dancers' glides, foot locks and the hand hold."""

    def __init__(self):
        # Both dancers' feet lock from footik.CONTACT_THRESHOLD. The follower's locked from 0.3 once
        # (her skate while low 1.31x against 2.08x, on networks before the figure block); on the
        # shipped networks the early lock had slid its full quarter metre by the time her network
        # planted the foot: her skate in contact 2.54x the recording's against 1.31x from 0.5, her
        # drawn steps on the beat +0.25 against +0.37 (5 steered seeds x 40 s; docs/music.md).
        self.leader_feet = FootLock(CONTACT_THRESHOLD)
        self.follower_feet = FootLock(CONTACT_THRESHOLD)
        self.hold = 0.0                 # 0..1: how far the closest hands are drawn together
        self.hands = (0, 0)             # the pair held (indices into HANDS: leader's, follower's)
        self.pushed = 0.0               # m each body was moved apart this step
        self.leader_glide = HipGlide()
        self.follower_glide = HipGlide()

    def clear(self) -> None:
        """Forget every lock, the hold and the glides (after a reset or a jump of either dancer)."""
        self.leader_feet.clear()
        self.follower_feet.clear()
        self.hold = 0.0
        self.leader_glide.clear()
        self.follower_glide.clear()

    def apply(self, leader: np.ndarray, follower: np.ndarray, leader_contacts, follower_contacts,
              leader_heading: float, follower_heading: float) -> None:
        """Make the shown poses leader, follower [17, 3] (world, copies: changed in place) read
        as partner dancing."""
        self.leader_glide.apply(leader)
        self.follower_glide.apply(follower)
        self.pushed = separate(leader, follower)
        i, j, d = closest_hands(leader, follower)
        target = reach_weight(d)
        self.hold += (target - self.hold) * (HOLD_RATE if target > self.hold else RELEASE_RATE)
        self.hands = (i, j)
        if self.hold > 1e-3 and d > 1e-6:
            hl, hf = leader[HANDS[i]].copy(), follower[HANDS[j]].copy()
            mid, u = (hl + hf) / 2, (hl - hf) / d
            move_hand(leader, HANDS[i], hl + (mid + u * GRIP / 2 - hl) * self.hold)
            # The follower's hand goes to where the leader's hand got (an arm too short to reach the
            # midpoint leaves the rest of the way to the partner's arm).
            reached = leader[HANDS[i]]
            move_hand(follower, HANDS[j], hf + (reached - u * GRIP - hf) * self.hold)
        self.leader_feet.apply(leader, leader_contacts, leader_heading, self.leader_glide.glided())
        self.follower_feet.apply(follower, follower_contacts, follower_heading, self.follower_glide.glided())
