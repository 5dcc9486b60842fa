"""Foot locking for what is shown (web/mirror/footik.ts mirrors it name for name).

While the model says a foot is planted (its contact above the lock's threshold), the foot stays
where the contact began, with a two-bone IK on thigh - shin - foot, and never below the floor.
This touches only the SHOWN positions (contact.py's layer); the Track the features read stays what
the model produced, so the page's features remain identical to Python's and the networks' own
metrics stay measurable.
"""
from __future__ import annotations

import numpy as np

from .skeleton import FEET, PARENTS

# Lowest height of the ankle joint: a flat foot's ankle sits 7-11 cm up in the data, so 6 cm
# keeps the sole above the floor without ever lifting a real flat foot.
ANKLE_FLOOR = 0.06
# A lock never trails the model's foot by more than this: when the model slides a planted foot on
# (a step it took without lifting it), the lock slides along behind it. Re-planting it at the
# model's foot instead was a jump of a quarter metre that counted as skate: the follower's skate in
# contact was 1.16x the recording's with the slide against 2.11x with the jump (4 steered seeds x
# 60 s, docs/plausibility.md). Holding to half a metre hid most of that skate but stretched the
# legs out of the recorded range: steered duets of the decoder-reads-pose models, 10 x 30 s,
# follower with the layer, knee/hip angles out of range and foot skate in contact (ratios to the
# recording): 0.5 m 4.7x / 1.85x, 0.25 m 1.3x / 2.5x, 0.15 m 0.8x / 3.1x (docs/plausibility.md).
# A quarter metre keeps the legs plausible.
MAX_LOCK_DISTANCE = 0.25
# A knee never straightens further than this (radians between thigh and shin) to reach a lock:
# the recorded dancers' knees bend at least 0.19-0.30 rad in 99.5 % of frames, and a leg pulled
# fully straight read as out of the recorded range in 2-6 % of the shown frames.
MIN_KNEE_BEND = 0.2
# The locks never hold the feet further apart than this (ankle to ankle): a lock trailing behind a
# dancer that travels on spread his stance past the recording's widest (1.07 m, plausibility's
# feet_wide) in 1-7 % of a dancing leader's steered frames, with his own feet never that wide.
MAX_STANCE = 0.9
# After a contact ends, the lock's pull decays by this factor per step (no pop on release).
RELEASE_DECAY = 0.5
# A foot locks while the model's contact for it is above this (both dancers; contact.py says why the
# follower's no longer locks from 0.3).
CONTACT_THRESHOLD = 0.5


def two_bone_ik(positions: np.ndarray, a: int, b: int, c: int, target, pole, min_bend: float = 0.0) -> None:
    """In place on positions [17, 3]: joints a -> b -> c keep their bone lengths, c goes to the
    target (or as near as the chain reaches while the middle joint bends at least `min_bend`
    radians between the two bones, or as much as it bends now if that is less), and the middle
    joint stays on the side it bends to now (the pole direction when the chain is straight)."""
    pa, pb, pc = positions[a].copy(), positions[b], positions[c]
    upper = float(np.linalg.norm(pb - pa))
    lower = float(np.linalg.norm(pc - pb))
    n = np.asarray(target, float) - pa
    reach = float(np.linalg.norm(n))
    if reach < 1e-9 or upper < 1e-9 or lower < 1e-9:
        return
    n /= reach
    # The chain straightens up to min_bend, or up to how straight the pose already is.
    longest = max(np.sqrt(upper * upper + lower * lower + 2 * upper * lower * np.cos(min_bend)),
                  float(np.linalg.norm(pc - pa)))
    d = min(max(reach, abs(upper - lower) + 1e-6), min(upper + lower - 1e-6, longest))
    # Bend direction: the middle joint's side of the a-c line as posed now (a knee bent forward
    # stays forward), made perpendicular to the new line; the pole for a straight chain.
    u = pc - pa
    m = np.asarray(pole, float).copy()
    un = float(np.linalg.norm(u))
    if un > 1e-9:
        u = u / un
        ab = pb - pa
        side = ab - float(ab @ u) * u
        if np.linalg.norm(side) > 1e-6:
            m = side
    m = m - float(m @ n) * n
    mn = float(np.linalg.norm(m))
    if mn < 1e-9:
        return
    m /= mn
    # Triangle with sides upper, lower, d: the middle joint sits x along the line and h off it.
    x = (upper * upper - lower * lower + d * d) / (2 * d)
    h = np.sqrt(max(0.0, upper * upper - x * x))
    positions[b] = pa + x * n + h * m
    positions[c] = pa + d * n


def cap_stance(target: np.ndarray, foot: np.ndarray, other: np.ndarray) -> None:
    """Move a lock `target` (in place) along the line to the model's `foot` until it is within
    MAX_STANCE of the `other` foot (as shown now); at the foot itself if even that is further.
    The distance to a point is convex along a line, so the linear share below never overshoots."""
    near = float(np.linalg.norm(foot - other))
    far = float(np.linalg.norm(target - other))
    if far <= MAX_STANCE:
        return
    share = 0.0 if near >= MAX_STANCE else (MAX_STANCE - near) / (far - near)
    target[:] = foot + (target - foot) * share
    target[1] = max(target[1], ANKLE_FLOOR)


class FootLock:
    """The lock state of one dancer's two feet, kept between steps."""

    def __init__(self, threshold: float = CONTACT_THRESHOLD):
        self.threshold = threshold
        self.locked = [False, False]
        self.target = np.zeros((2, 3))
        self.weight = np.zeros(2)

    def clear(self) -> None:
        """Forget every lock (after a reset or a jump of the dancer)."""
        self.locked = [False, False]
        self.weight[:] = 0

    def apply(self, positions: np.ndarray, contacts, heading: float, glide=(0.0, 0.0)) -> None:
        """Lock or release each foot from contacts (left, right) and bend the legs of positions
        [17, 3] (world, in place). heading gives the knee's bend direction for a straight leg.

        glide (x, z) is how far the contact layer's hip glide moved the body from where the network
        put it (contact.HipGlide). The feet do not glide: a free foot goes where the network put it
        on the floor, a planted one stays at its lock, and the legs take up the glide. The glide
        lags the network's steps by about two frames; feet carried along with it landed their
        steps off the network's beat (her drawn steps on the beat +0.33 with the feet kept where
        the network put them against +0.25 carried; the network's own +0.46; 5 steered seeds x
        40 s, docs/music.md)."""
        glide = np.asarray(glide, float)
        for i, foot in enumerate(FEET):
            knee = PARENTS[foot]
            thigh = PARENTS[knee]
            own = positions[foot].copy()          # the network's own foot on the floor
            own[[0, 2]] -= glide
            t = self.target[i]
            if contacts[i] > self.threshold:
                if not self.locked[i]:
                    t[:] = (own[0], max(own[1], ANKLE_FLOOR), own[2])
                    self.locked[i] = True
                else:
                    behind = float(np.linalg.norm(t - own))
                    if behind > MAX_LOCK_DISTANCE:   # slide along, MAX_LOCK_DISTANCE behind the foot
                        t[:] = own + (t - own) * (MAX_LOCK_DISTANCE / behind)
                        t[1] = max(t[1], ANKLE_FLOOR)
                self.weight[i] = 1.0
            else:
                self.locked[i] = False
                w = self.weight[i] * RELEASE_DECAY
                self.weight[i] = 0.0 if w < 0.01 else w
            w = self.weight[i]
            if w > 0:
                cap_stance(t, own, positions[FEET[1 - i]])
            goal = own + (t - own) * w
            goal[1] = max(goal[1], ANKLE_FLOOR)
            if w > 0 or glide.any() or own[1] < ANKLE_FLOOR:
                two_bone_ik(positions, thigh, knee, foot, goal, (np.sin(heading), 0.0, np.cos(heading)),
                            MIN_KNEE_BEND)
