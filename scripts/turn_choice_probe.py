"""A probe of her choice among her samples taking the turn they offer (docs/developing.md, "Her turn
after every request"). Each step her guard already draws 8 samples and takes the standing one whose
footwork follows the count (on_count.nearest_count); here, while she is not spinning, it takes it
among the standing samples that start a turn (her planned path turning at least DEGREES over the
next second) whenever any does:

- `eager`: a start either way. Nothing is read but what her network offers: where his lead makes
  more of her samples turn, she turns more often.
- `reader P`: only a start the way a linear reader of his body reads a lead (lead_reader.py,
  fitted on the recorded training samples, about 20 s), and only where it gives that way a
  probability of at least P.

She still gets no command. Runs `python -m training.evaluation.lead` with the remaining arguments.

    PYTHONPATH=. .venv/bin/python scripts/turn_choice_probe.py eager 180 --seeds 20 --out runs/lead_eager
    PYTHONPATH=. .venv/bin/python scripts/turn_choice_probe.py reader 180 0.15 --seeds 20 --out runs/lead_reader
"""
from __future__ import annotations

import sys

import numpy as np

from training.evaluation import lead
from training.learning.train import key_heading_change
from training.mirror import features as feat
from training.mirror import on_count

FUTURE = feat.block_slices(feat.OUTPUT_LAYOUT)["trajectory_future"]
_target, _keeps = on_count.OnCount.target, on_count.OnCount.keeps
counts = {"steps": 0, "read": 0}


def patch(mode: str, degrees: float, reader=None, p_min: float = 0.0) -> None:
    def target(self, x):
        t = _target(self, x)
        self.lead = None
        if self.role == "follower" and self.spin is None:
            counts["steps"] += 1
            if mode == "eager":
                self.lead = 0
            else:
                xx = np.atleast_2d(x)[0]
                p = reader.model.predict_proba(((xx[:reader.mean.size] - reader.mean) / reader.std)[None])[0]
                if max(p[1], p[2]) >= p_min:
                    self.lead = 1 if p[1] > p[2] else -1
            counts["read"] += self.lead is not None
        return t

    def keeps(self, outputs):
        k = _keeps(self, outputs)
        if k is not None or getattr(self, "lead", None) is None:
            return k
        o = np.atleast_2d(outputs)
        turn = key_heading_change(o[:, FUTURE].reshape(len(o), feat.KEYS, 4), False)
        return np.abs(turn) >= degrees if self.lead == 0 else turn * self.lead >= degrees

    on_count.OnCount.target, on_count.OnCount.keeps = target, keeps


def main(argv: list[str]) -> int:
    if len(argv) < 2 or argv[0] not in ("eager", "reader"):
        print(__doc__, file=sys.stderr)
        return 2
    mode, degrees, rest = argv[0], float(argv[1]), argv[2:]
    reader, p_min = None, 0.0
    if mode == "reader":
        from training.data.prepared import load_split
        from training.learning.lead_reader import LeadReader
        p_min, rest = float(rest[0]), rest[1:]
        train = load_split("runs/data", "train", "follower")
        reader = LeadReader.fit(train["input"], train["output"])
    patch(mode, degrees, reader, p_min)
    rc = lead.main(rest)
    print(f"the choice looked for a turn start in {counts['read'] / max(1, counts['steps']):.0%} of her steps "
          f"outside a spin ({counts['steps']} steps)")
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
