"""python -m training.evaluation.crossval: ours against CCM, cross-validated by take, with paired intervals.

    python -m training.evaluation.crossval                       # 6 folds x seeds 1,2, ours and CCM
    python -m training.evaluation.crossval --folds 6 --seeds 1,2 --jobs 2
    python -m training.evaluation.crossval --report-only         # the table from what is on disk

The takes are split into --folds groups (in name order); in fold k the k-th group is the test set,
the first take of the next group validates (per-epoch numbers only) and the rest train. Every
method is trained in every fold with every seed, by the same recipe as the shipped model but
with --epochs / --intention-epochs (shorter, to fit this CPU), exported to int8 ONNX like the
page's models and measured by training.evaluation.evaluate on the fold's test takes: teacher-forced MPJPE
and codebook error, free-running FID (temperature 0.5 or --temperature, evaluation seeds 0-2; the evaluation
encoder is trained on the fold's training takes). Each take is tested exactly once and never
trained on in its fold.

Paired comparison: for two methods A and B, the difference A - B of each metric is taken per fold
and seed (same data, same seed), averaged over the seeds of a fold, and the mean over folds gets
a 95 % t-interval with folds - 1 degrees of freedom (folds are the independent units: seeds of
one fold share its test takes). An interval that excludes 0 is a difference this data can show.

Resumable: finished trainings (history.json) and evaluations (metrics.json) are kept; an
interrupted training continues from its checkpoint, and a later call with more seeds or methods
adds only what is missing. Writes OUT/REPORT.json and OUT/REPORT.md (also printed; --report,
default crossval), over the methods and seeds of this call.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import multiprocessing
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..data.dataset import DataError, discover_takes
from ..data.folders import add_folder
from ..data.prepare import TEMPOS

# Method name -> (run name = ONNX stem, recipe in train.MODELS, trained on the tempo copies): the
# shipped pair's recipes, intention or not, all else alike, at the width of their teachers: the
# shipped networks are distilled from teachers that saw every take, a fold's test takes too.
METHODS = {
    "ours": ("follower", "follower_wide", True),
    "ccm": ("follower_ccm", "follower_ccm_wide", True),
}
# implausible / worst second: the free-running follower's frames with its body low, folded or split,
# against the fold's own training range (evaluate's plausibility; n/a for evaluations without it).
# The figures (evaluation.figures): the follower's turns per minute and spin frames as a ratio to
# the recorded follower's on the same test takes, and the recall and precision of her turns; her
# rhythm (evaluation.rhythm) beside the played-back leader, at the count she hears.
METRICS = {"mpjpe_cm": "MPJPE cm", "fid": "FID", "codebook_error": "codebook error",
           "implausible": "implausible frames", "worst_second": "worst second",
           "turns_ratio": "turns/min ratio", "spin_ratio": "spin frames ratio", "recall": "turn recall",
           "precision": "turn precision", "pulse_ratio": "pulse ratio", "on_beat": "on the beat",
           "together_ratio": "together ratio"}
# Over the recording's on the same test takes. Her rhythm (evaluate's RHYTHM_KEYS, at the count
# she hears): her footwork's pulse and together as ratios; on the beat, which can be negative, as is.
RATIOS = {"turns_ratio": "turns_per_min", "spin_ratio": "spin_frames", "pulse_ratio": "pulse",
          "together_ratio": "together"}
CONFIDENCE = 0.95


class CrossvalError(RuntimeError):
    """Bad arguments or data; the message is one line for a user."""


def make_folds(takes: list[str], k: int) -> list[dict]:
    """k groups of consecutive takes; each fold: test = its group, validation = the first take of
    the next group, train = the rest."""
    if not 2 <= k <= len(takes) // 2:
        raise CrossvalError(f"--folds {k}: need 2 to {len(takes) // 2} folds for {len(takes)} takes "
                            f"(each fold tests at least one take and keeps a validation take)")
    groups = [list(g) for g in np.array_split(np.array(takes), k)]
    folds = []
    for i, test in enumerate(groups):
        validation = [groups[(i + 1) % k][0]]
        train = [t for t in takes if t not in test and t not in validation]
        folds.append({"fold": i, "test": test, "validation": validation, "train": train})
    return folds


def paired(a: dict, b: dict, folds: list[int], seeds: list[int], metric: str) -> dict | None:
    """Mean over folds of (A - B averaged over seeds) with a t-interval; None if a value is missing."""
    from scipy import stats
    per_fold = []
    for f in folds:
        d = [a[(f, s)][metric] - b[(f, s)][metric] for s in seeds
             if (f, s) in a and (f, s) in b and a[(f, s)][metric] is not None and b[(f, s)][metric] is not None]
        if len(d) != len(seeds):
            return None
        per_fold.append(float(np.mean(d)))
    if not per_fold:
        return None
    d = np.asarray(per_fold)
    mean = float(d.mean())
    if len(d) < 2:
        return {"mean": mean, "low": None, "high": None, "per_fold": per_fold}
    half = float(stats.t.ppf(0.5 + CONFIDENCE / 2, len(d) - 1) * d.std(ddof=1) / np.sqrt(len(d)))
    base = np.mean([b[(f, s)][metric] for f in folds for s in seeds])
    return {"mean": mean, "low": mean - half, "high": mean + half, "relative": mean / base if base else None,
            "per_fold": per_fold}


# ---------------------------------------------------------------- jobs (run in worker processes)

def _quietly(log: Path, fn, *args):
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "a") as f, contextlib.redirect_stdout(f), contextlib.redirect_stderr(f):
        return fn(*args)


def prepare_job(data: str, out: str, fold: dict) -> str:
    from ..data.prepare import prepare
    if not all((Path(out) / f).exists() for f in ("stats.npz", "train_tempo.npz")):
        _quietly(Path(out).parent / "prepare.log", prepare, data, out, fold["validation"], fold["test"],
                 None, True, True, TEMPOS)
    return out


def train_job(recipe: str, run: str, tempo: bool, prepared: str, runs: str, seed: int, epochs: int,
              intention_epochs: int, smoke: bool = False) -> str:
    import torch
    from ..learning.train import MODELS, smoke as tiny, train_model
    torch.set_num_threads(1)
    if (Path(runs) / run / "history.json").exists():
        return run
    cfg = replace(MODELS[recipe], seed=seed, epochs=epochs, intention_epochs=intention_epochs, tempo_copies=tempo)
    if smoke:
        cfg = tiny(cfg)
    resume = (Path(runs) / run / "checkpoint.pt").exists()
    _quietly(Path(runs) / f"{run}.log", train_model, run, cfg, prepared, runs, "cpu", resume, True)
    return run


def evaluate_job(data: str, where: str, fold: dict, runs: list[str], eval_seeds: str, smoke: bool = False,
                 temperature: float = 0.5) -> str:
    """Export each run of one fold and seed (WHERE/models_RUN) and evaluate it on the fold's test
    takes (WHERE/eval_RUN/metrics.json); what exists is kept. Methods are evaluated one by one:
    a method's numbers do not depend on the others (same seeds, same reference)."""
    import torch
    from ..learning import export
    from . import evaluate
    from .evaluate_inputs import NAMES
    torch.set_num_threads(1)
    where = Path(where)
    for run in runs:
        if (where / f"eval_{run}" / "metrics.json").exists():
            continue
        models = where / f"models_{run}"
        if not (models / "manifest.json").exists():
            _quietly(where / "export.log", export.export_all, [run], str(where / "runs"), str(models), data,
                     str(where.parent / "data"), str(where / "fp32"))
        code = _quietly(where / "evaluate.log", evaluate.main, [
            "--data", data, "--takes", ",".join(fold["test"]), "--models", str(models),
            "--train-takes", ",".join(fold["train"]), "--conditions", "", "--seeds", eval_seeds,
            "--temperatures", f"{temperature:g}", "--encoder-cache", str(where.parent / "eval_encoder"),
            "--out", str(where / f"eval_{run}"), "--quiet", "--methods", NAMES.get(run, run)]
            + (["--encoder-epochs", "2"] if smoke else []))
        if code:
            raise CrossvalError(f"evaluation of {run} failed in {where} (see {where / 'evaluate.log'})")
    return str(where)


# ---------------------------------------------------------------- driver

def run_crossval(args) -> dict:
    out = Path(args.out)
    methods = [m for m in args.methods.split(",") if m]
    unknown = [m for m in methods if m not in METHODS]
    if len(methods) < 2 or unknown:
        raise CrossvalError(f"--methods: need two or more of {', '.join(METHODS)}"
                            + (f"; unknown {', '.join(unknown)}" if unknown else ""))
    seeds = [int(s) for s in args.seeds.split(",") if s]
    takes = [t.name for t in discover_takes(args.data)]
    folds = make_folds(takes, args.folds)
    only = [int(f) for f in args.only_folds.split(",")] if args.only_folds else list(range(args.folds))
    folds = [f for f in folds if f["fold"] in only]
    (out).mkdir(parents=True, exist_ok=True)
    if args.smoke:
        args.epochs, args.intention_epochs = 2, 1
    plan = {"folds": folds, "methods": methods, "seeds": seeds, "epochs": args.epochs,
            "intention_epochs": args.intention_epochs, "smoke": args.smoke, "temperature": args.temperature,
            "tempos": TEMPOS if any(METHODS[m][2] for m in methods) else []}
    t0 = time.time()
    if not args.report_only:
        ctx = multiprocessing.get_context("spawn")   # torch and fork do not mix
        with ctx.Pool(args.jobs) as pool:
            for p in [pool.apply_async(prepare_job, (args.data, str(out / f"fold{f['fold']}" / "data"), f))
                      for f in folds]:
                p.get()
            # Fold by fold, one fold queued ahead so no process waits; each fold's evaluations are
            # queued as soon as its trainings finish, so finished folds have their numbers early
            # (--report-only reads them mid-run).
            bar = tqdm(total=len(folds) * len(seeds) * (len(methods) + 1), desc="crossval", unit="job",
                       disable=args.quiet)

            def queue_trainings(f):
                fdir = out / f"fold{f['fold']}"
                return [((s, m), pool.apply_async(train_job, (
                    METHODS[m][1], METHODS[m][0], METHODS[m][2], str(fdir / "data"),
                    str(fdir / f"seed{s}" / "runs"), s, args.epochs, args.intention_epochs, args.smoke)))
                    for s in seeds for m in methods]

            evals, queued = [], queue_trainings(folds[0]) if folds else []
            for i, f in enumerate(folds):
                jobs, queued = queued, queue_trainings(folds[i + 1]) if i + 1 < len(folds) else []
                for (s, m), j in jobs:
                    j.get()
                    bar.update(1)
                    bar.set_postfix_str(f"trained fold {f['fold']} seed {s} {m}")
                fdir = out / f"fold{f['fold']}"
                evals += [pool.apply_async(evaluate_job, (args.data, str(fdir / f"seed{s}"), f,
                                                          [METHODS[m][0] for m in methods],
                                                          args.eval_seeds, args.smoke, args.temperature)) for s in seeds]
            for e in evals:
                e.get()
                bar.update(1)
            bar.close()
    return report(out, plan, time.time() - t0, args.report)


def report(out: Path, plan: dict, seconds: float, name: str = "crossval") -> dict:
    from .evaluate_inputs import NAMES
    methods, seeds = plan["methods"], plan["seeds"]
    values: dict[str, dict] = {m: {} for m in methods}
    for f in plan["folds"]:
        for s in seeds:
            for m in methods:
                run = METHODS[m][0]
                path = out / f"fold{f['fold']}" / f"seed{s}" / f"eval_{run}" / "metrics.json"
                if path.exists():
                    res = json.loads(path.read_text())["methods"]
                    row, ref = res[NAMES.get(run, run)], res.get("ground_truth", {})
                    for k, base in RATIOS.items():
                        row[k] = row[base] / ref[base] if row.get(base) is not None and ref.get(base) else None
                    values[m][(f["fold"], s)] = {k: row.get(k) for k in METRICS}
    fold_ids = [f["fold"] for f in plan["folds"] if all((f["fold"], s) in values[m] for m in methods for s in seeds)]
    comparisons = {}
    pairs = [("ours", "ccm")] if "ours" in methods and "ccm" in methods else []
    for a, b in pairs:
        comparisons[f"{a} - {b}"] = {k: paired(values[a], values[b], fold_ids, seeds, k) for k in METRICS}
    res = {"plan": plan, "complete_folds": fold_ids, "seconds": seconds,
           "means": {m: {k: mean_or_none([values[m][(f, s)][k] for f in fold_ids for s in seeds])
                         for k in METRICS} for m in methods},
           "per_fold": {m: {f"{f}/{s}": v for (f, s), v in values[m].items()} for m in methods},
           "comparisons": comparisons}
    (out / f"{name}.json").write_text(json.dumps(res, indent=1))
    (out / f"{name}.md").write_text(markdown(res))
    return res


def mean_or_none(values: list) -> float | None:
    """The mean, or None when there is nothing or a value is missing (older evaluations)."""
    return None if not values or any(v is None for v in values) else float(np.mean(values))


def _num(v, digits):
    return "n/a" if v is None else f"{v:.{digits}f}"


def markdown(res: dict) -> str:
    plan = res["plan"]
    digits = {"mpjpe_cm": 2, "fid": 1, "codebook_error": 4, "implausible": 3, "worst_second": 2,
              "turns_ratio": 2, "spin_ratio": 2, "recall": 2, "precision": 2, "pulse_ratio": 2,
              "on_beat": 2, "together_ratio": 2}
    lines = [f"Folds {len(res['complete_folds'])} of {len(plan['folds'])} complete, seeds "
             f"{','.join(map(str, plan['seeds']))}, {plan['intention_epochs']} + {plan['epochs']} epochs, "
             f"free runs at variety {plan.get('temperature', 0.5):g}"
             + (f", tempo copies {plan['tempos']}" if plan["tempos"] else "") + ".", "",
             "| fold | test takes | " + " | ".join(f"{m} {METRICS[k]}" for k in METRICS for m in plan["methods"]) + " |",
             "|---|---|" + "---|" * (len(METRICS) * len(plan["methods"]))]
    for f in plan["folds"]:
        cells = []
        for k in METRICS:
            for m in plan["methods"]:
                vals = [res["per_fold"][m].get(f"{f['fold']}/{s}", {}).get(k) for s in plan["seeds"]]
                cells.append("n/a" if any(v is None for v in vals) else _num(float(np.mean(vals)), digits[k]))
        lines.append(f"| {f['fold']} | {','.join(f['test'])} | " + " | ".join(cells) + " |")
    lines.append("| mean | | " + " | ".join(_num(res["means"][m][k], digits[k]) for k in METRICS
                                             for m in plan["methods"]) + " |")
    lines += ["", f"| paired difference (mean over folds, {int(CONFIDENCE * 100)} % interval) | "
              + " | ".join(METRICS.values()) + " |", "|---|" + "---|" * len(METRICS)]
    for name, c in res["comparisons"].items():
        cells = []
        for k in METRICS:
            p = c[k]
            if p is None:
                cells.append("n/a")
            elif p["low"] is None:
                cells.append(_num(p["mean"], digits[k] + 1))
            else:
                rel = f", {100 * p['relative']:+.0f} %" if p.get("relative") is not None else ""
                cells.append(f"{p['mean']:+.{digits[k] + 1}f} [{p['low']:+.{digits[k] + 1}f}, "
                             f"{p['high']:+.{digits[k] + 1}f}]{rel}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.crossval", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "read")
    ap.add_argument("--out", default="runs/crossval", help="folds, runs, evaluations and the report")
    ap.add_argument("--methods", default="ours,ccm", help=f"two or more of {', '.join(METHODS)}")
    ap.add_argument("--folds", type=int, default=6)
    ap.add_argument("--only-folds", default=None, help="comma-separated fold numbers (a subset)")
    ap.add_argument("--seeds", default="1,2", help="training seeds, each paired across methods")
    ap.add_argument("--epochs", type=int, default=20, help="matching epochs (shipped recipe: 40)")
    ap.add_argument("--intention-epochs", type=int, default=10, help="(shipped recipe: 20)")
    ap.add_argument("--eval-seeds", default="0,1,2", help="free-running seeds per evaluation")
    ap.add_argument("--temperature", type=float, default=0.5,
                    help="the followers' variety in the free runs (the page runs the shipped followers at 1)")
    ap.add_argument("--jobs", type=int, default=2, help="processes side by side, one thread each")
    ap.add_argument("--report-only", action="store_true", help="only rebuild the table from OUT")
    ap.add_argument("--report", default="crossval", help="name of the report files in OUT")
    ap.add_argument("--smoke", action="store_true", help="tiny models, 1 + 2 epochs (tests, CI)")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    try:
        res = run_crossval(args)
    except (CrossvalError, DataError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(markdown(res))
    print(f"wrote {args.out}/{args.report}.json and {args.out}/{args.report}.md ({res['seconds']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
