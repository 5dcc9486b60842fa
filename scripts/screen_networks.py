"""Screen trained networks against known soak falls before soaking them.

    PYTHONPATH=. .venv/bin/python scripts/screen_networks.py runs/moments.json --setting guard=128 \
        --candidates "seed 4=follower=/tmp/F4/follower.onnx,seed 5=follower=/tmp/F5/follower.onnx"

A soak fall is a 1-in-100-rollouts event and one soak takes 40 minutes here, but how readily a
trained follower (or leader) falls is a property of its weights: the same recipe with another
--seed can stand or fall (docs/results.md, "Five seeds of one follower"). This script takes the
moments where soaks fell (MOMENTS, a JSON list of {"seed", "models", "fall", "rollout"?}: the soak
rollout, the pair that danced it, the first failing second, and the options it was danced with)
and, for each, dances on from --back seconds before the fall --n times per candidate
(scripts/fall_continuations.py: the same random streams for every candidate). It prints one row
per moment and the falls in all, per candidate.

A candidate is NAME=VARIANT, VARIANT as in fall_continuations (`follower=FILE.onnx`,
`leader=FILE.onnx`, guard options, joined by `+`); `--setting` is joined to every candidate and
to the reference (`base`: the pair that danced the moment). A candidate that falls far more than
the reference is not worth a soak; one that falls in none still has to stand the soak (seed 4
stood every moment here and fell in the soak once in 57 rollouts). One network costs about a
minute on this machine's one core beside the dancing to the moments, which every candidate shares.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import tempfile
from pathlib import Path

from tqdm import tqdm


def fall_continuations():
    """scripts/fall_continuations.py as a module (scripts/ is not a package)."""
    path = Path(__file__).resolve().parent / "fall_continuations.py"
    spec = importlib.util.spec_from_file_location("fall_continuations", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_moments(path: Path) -> list[dict]:
    """The moments file, checked: a list of objects with seed (int), models (a folder with a
    manifest) and fall (seconds); rollout optional."""
    moments = json.loads(path.read_text())
    if not isinstance(moments, list) or not moments:
        raise ValueError(f"{path}: a JSON list of moments, each {{seed, models, fall, rollout?}}")
    for i, m in enumerate(moments):
        missing = [k for k in ("seed", "models", "fall") if k not in m]
        if missing:
            raise ValueError(f"{path}: moment {i} lacks {', '.join(missing)}")
        if not (Path(m["models"]) / "manifest.json").exists():
            raise ValueError(f"{path}: moment {i}: {m['models']}/manifest.json not found")
    return moments


def parse_candidates(text: str, setting: str) -> dict[str, str]:
    """'NAME=VARIANT,...' -> {name: variant with the setting}, the reference 'base' first."""
    joined = lambda v: "+".join(p for p in (setting, v) if p and p != "base") or "base"
    out = {"base": joined("base")}
    for item in filter(None, text.split(",")):
        name, sep, variant = item.partition("=")
        if not sep or not variant:
            raise ValueError(f"candidate {item!r}: NAME=VARIANT (for example 'seed 4=follower=runs/s4/follower.onnx')")
        if name in out:
            raise ValueError(f"candidate {name!r} named twice")
        out[name] = joined(variant)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("moments", help="JSON list of soak falls: {seed, models, fall, rollout?}")
    ap.add_argument("--candidates", required=True, help="NAME=VARIANT,... (VARIANT as in fall_continuations)")
    ap.add_argument("--setting", default="", help="options joined to every candidate and the reference, e.g. guard=128")
    ap.add_argument("--back", default="0.4,0.25,0.1")
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--minutes", type=float, default=10.0, help="the soak's rollout length")
    ap.add_argument("--out", default=None, help="write the table as JSON here")
    a = ap.parse_args(argv)
    if a.n < 1:
        ap.error(f"--n {a.n}: at least one continuation per moment")
    try:
        moments = load_moments(Path(a.moments))
        candidates = parse_candidates(a.candidates, a.setting)
    except (ValueError, json.JSONDecodeError, FileNotFoundError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    fc = fall_continuations()
    names = list(candidates)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for m in tqdm(moments, desc="moments", unit="moment"):
            out = Path(tmp) / "moment.json"
            args = [str(m["seed"]), "--models", m["models"], "--fall", str(m["fall"]), "--back", a.back,
                    "--n", str(a.n), "--seconds", str(a.seconds), "--minutes", str(a.minutes),
                    "--rollout", m.get("rollout", "base"), "--variants", ",".join(candidates.values()),
                    "--out", str(out)]
            rc = fc.main(args)
            if rc != 0:
                print(f"error: fall_continuations {' '.join(args)} exited {rc}", file=sys.stderr)
                return rc
            got = json.loads(out.read_text())["variants"]
            rows.append({"seed": m["seed"], "fall": m["fall"],
                         "falls": {n: got[candidates[n]]["falls"] for n in names},
                         "continuations": got[candidates["base"]]["continuations"]})
    print(f"\n| soak seed (fall) | {' | '.join(names)} |\n|---|{'---|' * len(names)}")
    for r in rows:
        print(f"| {r['seed']} ({r['fall']:g} s) | {' | '.join(str(r['falls'][n]) for n in names)} |")
    total = sum(r["continuations"] for r in rows)
    print(f"| **in all, of {total}** | {' | '.join(str(sum(r['falls'][n] for r in rows)) for n in names)} |")
    if a.out:
        Path(a.out).write_text(json.dumps({"candidates": candidates, "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
