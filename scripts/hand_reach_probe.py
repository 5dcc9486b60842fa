"""A probe of her reading of his hand (docs/developing.md, "Her turn after every request"): what
would she do if his lead hand reached the plan on every request? While a request runs, after each
step his lead hand is put where the hands plan has it now (rollout.hands_input's raise, up to
rollout.LEAD_HAND_RAISED: 1.90 m), his other joints left where his network put them (the forearm
stretches: a probe, not a drawing). She, and he on his next step, read the hand there. Runs
`python -m training.evaluation.lead` with the remaining arguments.

    PYTHONPATH=. .venv/bin/python scripts/hand_reach_probe.py --seeds 20 --seconds 30 --out runs/lead_reach
    PYTHONPATH=. .venv/bin/python scripts/hand_reach_probe.py --models DIR --method NAME --seeds 20 --out runs/lead_reach16
"""
from __future__ import annotations

import sys

import numpy as np

from training.evaluation import lead
from training.mirror import features as feat
from training.mirror import rollout
from training.mirror.skeleton import FPS, HANDS

_finish_step = rollout.finish_step


def hand_reached(duet: rollout.Duet) -> None:
    """His lead hand where the plan has it at this step of the running request (if any)."""
    request, d = duet.request, duet.leader
    if request is None:
        return
    lead_hand = 0 if request.direction > 0 else 1
    top = np.array(rollout.LEAD_HAND_RAISED) * np.array([1.0 if lead_hand == 0 else -1.0, 1.0, 1.0])
    u = rollout.raised(request.frame / FPS)
    target = request.hands[lead_hand] + u * (top - request.hands[lead_hand])
    d.track.positions[rollout.NOW][HANDS[lead_hand]] = feat.from_root_space_points(target, d.root, d.heading)


def finish_step(duet, *args, **kwargs):
    _finish_step(duet, *args, **kwargs)
    hand_reached(duet)


def main(argv: list[str]) -> int:
    rollout.finish_step = finish_step
    return lead.main(argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
