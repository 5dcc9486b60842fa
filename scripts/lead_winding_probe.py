"""A probe of the request's lead (results.md's tried table, "A winding lead"): the hands plan's lead
hand circles her way once while she is to turn (RADIUS metres, in the horizontal plane of his root
space; the sign the recorded leads wind: lead.winding), and with "3d" his guard keeps the hand
nearest the plan's place instead of its height. Runs `lead` on seeds 20-49 of the shipped models.

    PYTHONPATH=. .venv/bin/python scripts/lead_winding_probe.py OUT RADIUS 3d|height
"""
import sys
import numpy as np
from training.mirror import rollout as R, guard as G, features as feat
from training.mirror.skeleton import HANDS
RADIUS = float(sys.argv[2]); MODE3D = sys.argv[3] == "3d"
def hands_input(request, leader):
    if request is None:
        return None
    now = request.frame / R.FPS
    lead = 0 if request.direction > 0 else 1
    top = np.array(R.LEAD_HAND_RAISED) * np.array([1.0 if lead == 0 else -1.0, 1.0, 1.0])
    hands = feat.to_root_space_points(leader.positions[HANDS], leader.root, leader.heading)
    out = np.repeat(request.hands[None], R.KEYS, 0) - hands[None]
    for k, off in enumerate(R.FUTURE_OFFSETS):
        t = now + off / R.FPS
        u = R.raised(t)
        s = min(1.0, max(0.0, (t - R.TURN_START) / R.TURN_SECONDS))
        phi = -request.direction * 2 * np.pi * s
        circle = RADIUS * np.array([np.cos(phi) - 1.0, 0.0, np.sin(phi)]) * u
        out[k, lead] = request.hands[lead] + u * (top - request.hands[lead]) + circle - hands[lead]
    return out
R.hands_input = hands_input
if MODE3D:
    POSE0 = feat.block_slices(feat.LEADER_INPUT_LAYOUT)["self_pose"].start
    def drawn_miss(joints, x):
        first = np.atleast_2d(x)[0]
        now, move = first[G.HAND_HEIGHTS], first[G.HAND_PLAN_FIRST]
        lead = int(np.argmax(now + move))
        p0 = first[POSE0 + 12 * HANDS[lead]: POSE0 + 12 * HANDS[lead] + 3]
        m0 = first[G.HANDS_PLAN_SHOWN + 1 + 3 * lead: G.HANDS_PLAN_SHOWN + 4 + 3 * lead]
        target = p0 + m0 / feat.KEY_STEP
        return np.linalg.norm(joints[:, HANDS[lead]] - target, axis=-1)
    G.drawn_miss = drawn_miss
from training.evaluation import lead
sys.exit(lead.main(["--models", "public/models", "--seeds", "30", "--seconds", "30", "--first-seed", "20", "--no-legibility", "--quiet", "--out", sys.argv[1]]))
