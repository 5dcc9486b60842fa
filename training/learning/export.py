"""python -m training.learning.export: trained runs -> dynamic-int8 ONNX step models + manifest.

    python -m training.learning.export                    # runs/models/{follower,follower_ccm,leader} -> public/models
    python -m training.learning.export --runs R --models M --model follower

One ONNX file per model holds the whole step (normalization, intention, input encoder, Gumbel-max
sampling with temperature and noise as inputs, gather decoder, de-normalization), so the page
only builds features and reads results. Dynamic int8 (per channel) because static QDQ int8 runs
6-8x slower in the browser's WASM backend; the int8 weights are then snapped to a coarser grid
(--weight-step, coarsen) so that the compressed files a phone downloads are smaller.

Each follower also gets MODELS/eval/NAME.output_encoder.onnx (fp32, evaluation only; for the
page's public/models it goes to models/eval/, outside what the site publishes: stamp.eval_folder):
what training.evaluation.evaluate needs for the codebook error. Every file carries the
run's fingerprint (training/learning/stamp.py), repeated in manifest.json.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import zlib
from pathlib import Path

import numpy as np
import torch

from ..mirror import features as feat
from ..mirror import music, on_count
from ..data.dataset import DataError, discover_takes, load_pair
from ..data.folders import add_folder
from .models import OutputEncoderStep, StepModel
from ..data.prepared import TrainError
from .runs import fingerprint, load_run
from .stamp import PAGE_MODELS, eval_file, write_stamp
from ..mirror.skeleton import FPS, JOINT_NAMES, KEY_JOINTS, PARENTS
from ..mirror.guard import FOLLOWER_HIP_MARGIN, LEADER_HEAD_MARGIN, LEADER_HIP_MARGIN, LEADER_KEEP_PLAN, LEADER_MARGIN, LEADER_SAMPLES, MARGIN as GUARD_MARGIN, SAMPLES as GUARD_SAMPLES
from .train import SHIPPED

MANIFEST_VERSION = 1
OPSET = 18
# Each dancer's variety (Gumbel temperature). The follower's is the page's slider. At 1 the 24
# code channels are drawn each on its own, and a mix of "turn" and "step" channels decodes to a
# step: beside the recorded leader a follower trained without own rollouts turned 1.9 times a minute at 1 against
# 11.5 at 0.5 (the recording: 25.9). Lower varieties then let a follower sink beside our steered
# leader, so the page kept 1; the followers trained on their own rollouts (train.py) sink in none
# of 20 steered seeds down to 0.35, and turn 25.9 times a minute at 0.5 beside the recorded leader
# (5.9 at 1): the page runs them at 0.5 (docs/results.md, "Salsa turns"). The wide leader ran at 0.7:
# with his hips guarded, nobody steering, his body motion, travel and own turns reach 0.77x, 0.87x
# and 0.72x the recorded leader's (0.55x, 0.83x, 0.78x at 0.5), steered 0.80x body motion with no
# bad second in 100 seeds and no failure in the full soak (docs/results.md, "His variety"). The
# distilled leader the page ships (train.distilled) runs at 0.6: its code distribution is a little flatter than its
# teacher's (1.68 against 1.60 nats a channel on the validation take), and at 0.7 he turned 4.0
# times a minute nobody steering against his teacher's 7.0 at 0.7; at 0.6, 7.6 (docs/measurements.md).
DEFAULT_TEMPERATURE = 0.5
LEADER_TEMPERATURE = 0.6
# While he leads a figure the visitor asked for (rollout.leading: from a second before it starts to
# its end) the leader draws at 0.8: at his own 0.6 his 8 samples seldom held his lead hand up for the hands plan, and
# his guard's choice near the plan had little to choose from. Over 160 requests (`lead --seeds 40`
# and `--first-seed 40`, his own figures off) his hand went above 1.6 m after 59 % of them against
# 39 %, she turned the asked way after 71 % against 72 %, the other way after 3 % against 7 %;
# at 1.0 his hand 69 %, but she turned the asked way after 66 % (docs/results.md, "Leading a turn").
LEADING_TEMPERATURE = 0.8
# int8 weights snapped to every 4th level (coarsen): 1.0 MB less for a first visit to download,
# and the steered tables and the FID stay those of the 8-bit models (docs/measurements.md).
WEIGHT_STEP = 4
CREDIT = ("The data used in this project was obtained from mocap.cs.cmu.edu. "
          "The database was created with funding from NSF EIA-0196217.")


def export_onnx(model: StepModel, path: Path) -> None:
    cfg = model.cfg
    x = torch.zeros(2, cfg.input_size)
    t = torch.ones(1)
    u = torch.full((2, cfg.latent), 0.5)
    names = ["output", "intention", "code"] if cfg.intention else ["output", "code"]
    torch.onnx.export(model, (x, t, u), str(path), opset_version=OPSET, dynamo=False,
                      input_names=["input", "temperature", "noise"], output_names=names,
                      dynamic_axes={"input": {0: "batch"}, "noise": {0: "samples"},
                                    **{n: {0: "batch" if n == "intention" else "samples"} for n in names}})


def export_output_encoder(model: StepModel, path: Path) -> None:
    """fp32 ONNX of OutputEncoderStep: (input [B, 660], output [B, 323]) -> target_logits [B, C*D].
    fp32, not int8: it is the reference every follower's codes are scored against."""
    cfg = model.cfg
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.onnx.export(OutputEncoderStep(model).eval(), (torch.zeros(2, cfg.input_size), torch.zeros(2, cfg.output_size)),
                      str(path), opset_version=OPSET, dynamo=False, input_names=["input", "output"],
                      output_names=["target_logits"],
                      dynamic_axes={"input": {0: "batch"}, "output": {0: "batch"}, "target_logits": {0: "batch"}})


def stamp_of(name: str, model: StepModel) -> dict:
    return {"fingerprint": fingerprint(model), "name": name, "role": model.cfg.role,
            "channels": model.cfg.channels, "classes": model.cfg.classes}


def quantize(src: Path, dst: Path) -> None:
    from onnxruntime.quantization import QuantType, quantize_dynamic
    quantize_dynamic(str(src), str(dst), per_channel=True, weight_type=QuantType.QInt8)


def coarsen(path: Path, step: int) -> None:
    """Snap every int8 weight of a dynamically quantized model to a grid `step` levels apart
    (step 4: 64 levels, 6-bit weights stored as int8). The graph, its operators and its speed stay
    the same; what changes is the weights' entropy, so the brotli and gzip copies the page
    downloads shrink (measured in docs/measurements.md, and the quality tables checked with the
    snapped models, since those are the bytes the page runs). Zero points stay on the grid's
    origin, so a weight of zero stays exactly zero."""
    if step == 1:
        return
    import onnx
    from onnx import numpy_helper
    model = onnx.load(str(path))
    inits = {i.name: i for i in model.graph.initializer}
    for name, init in inits.items():
        if not name.endswith("_quantized"):
            continue
        q = numpy_helper.to_array(init)
        zero = inits.get(name[: -len("_quantized")] + "_zero_point")
        zp = numpy_helper.to_array(zero).astype(np.int32) if zero is not None else np.int32(0)
        if zp.ndim == 1 and q.ndim == 2 and zp.shape[0] == q.shape[1]:
            zp = zp[None, :]  # per output channel (MatMulInteger's B is [in, out])
        info = np.iinfo(q.dtype)
        snapped = np.round((q.astype(np.int32) - zp) / step) * step + zp
        init.CopyFrom(numpy_helper.from_array(np.clip(snapped, info.min, info.max).astype(q.dtype), name))
    onnx.save(model, str(path))


def short_names(path: Path) -> None:
    """Rename the graph's nodes and the values passed between them to short numbers: the exporter's
    and the quantizer's names ("/matching/encoder/layers.0/MatMul_output_0_quantized", ...) are
    about 9 KB of every file the page downloads and mean nothing to it. The inputs, outputs and
    initializers keep their names; what the graph computes is unchanged (the tests compare outputs)."""
    import onnx
    model = onnx.load(str(path))
    g = model.graph
    keep = {v.name for v in (*g.input, *g.output)} | {i.name for i in g.initializer} | {""}
    renamed: dict[str, str] = {}

    def short(name: str) -> str:
        if name in keep:
            return name
        return renamed.setdefault(name, f"v{len(renamed)}")

    for i, node in enumerate(g.node):
        node.name = f"n{i}"
        node.input[:] = [short(n) for n in node.input]
        node.output[:] = [short(n) for n in node.output]
    for info in g.value_info:
        info.name = short(info.name)
    onnx.save(model, str(path))


def skeleton_offsets(data: str) -> dict:
    """Bone offsets (metres) of each role, from the first take: the page draws and exports BVH
    with them. Offsets are constant per dancer, so this is not frame-by-frame data."""
    take = discover_takes(data)[0]
    lead, follow = load_pair(take)
    return {"leader": np.round(lead.offsets, 5).tolist(), "follower": np.round(follow.offsets, 5).tolist()}


def start_pose(stats_mean: np.ndarray) -> dict:
    """A neutral standing pose per role from the mean output pose (an average over all frames):
    the page starts both dancers from it."""
    pose = stats_mean[feat.block_slices(feat.OUTPUT_LAYOUT)["pose"]].reshape(feat.N_JOINTS, 12)
    return {"hip": np.round(pose[0, :3], 4).tolist(),
            "forward": np.round(pose[:, 6:9], 4).tolist(), "up": np.round(pose[:, 9:12], 4).tolist()}


def plausibility_ranges(prepared: str) -> dict:
    path = Path(prepared) / "plausibility.json"
    if not path.exists():
        raise TrainError(f"{path} not found: re-run training.data.prepare (it writes the recording's range)")
    r = json.loads(path.read_text())
    return {k: (np.round(v, 4).tolist() if isinstance(v, list) else round(v, 4) if isinstance(v, float) else v)
            for k, v in r.items()}


def write_manifest(out: Path, models: dict[str, StepModel], data: str, prepared: str,
                   weight_step: int = WEIGHT_STEP) -> dict:
    stats = np.load(Path(prepared) / "stats.npz")
    manifest = {
        "version": MANIFEST_VERSION,
        "fps": FPS,
        "skeleton": {"names": JOINT_NAMES, "parents": PARENTS, "offsets": skeleton_offsets(data)},
        "keyJoints": KEY_JOINTS,
        "layout": {"input": feat.INPUT_SIZE, "output": feat.OUTPUT_SIZE, "intention": feat.INTENTION_SIZE,
                   "followerInput": feat.FOLLOWER_INPUT_LAYOUT, "leaderInput": feat.LEADER_INPUT_LAYOUT,
                   "outputBlocks": feat.OUTPUT_LAYOUT},
        "startPose": {role: start_pose(stats[f"{role}_output_mean"]) for role in ("leader", "follower")},
        "models": {},
        "defaultTemperature": DEFAULT_TEMPERATURE,
        "leaderTemperature": LEADER_TEMPERATURE,
        "leadingTemperature": LEADING_TEMPERATURE,
        # The follower's upright guard (training/mirror/guard.py, web/mirror/guard.ts).
        "guard": {"samples": GUARD_SAMPLES, "margin": GUARD_MARGIN,
                  **({} if FOLLOWER_HIP_MARGIN is None else {"hipMargin": FOLLOWER_HIP_MARGIN})},
        # ... and the leader's (the same guard with its own margin).
        "leaderGuard": {"samples": LEADER_SAMPLES, "margin": LEADER_MARGIN,
                        **({} if LEADER_HEAD_MARGIN is None else {"headMargin": LEADER_HEAD_MARGIN}),
                        **({} if LEADER_HIP_MARGIN is None else {"hipMargin": LEADER_HIP_MARGIN}),
                        **({"keepPlan": LEADER_KEEP_PLAN} if LEADER_KEEP_PLAN else {})},
        # Both guards choose, every step, the sample whose footwork follows the count
        # (training/mirror/on_count.py, web/mirror/on_count.ts).
        "onCount": {"samples": on_count.SAMPLES, "strength": on_count.STRENGTH, "hips": on_count.HIPS,
                    "figureTurn": on_count.FIGURE_TURN},
        # The training dancers' range (evaluation.plausibility): soak counts a collapse against it
        # and training.evaluation.seeds judges every steered frame against it.
        "plausibility": plausibility_ranges(prepared),
        # What the dancers hear (training/mirror/music.py): the page's tempo when the address names
        # none, and what its tempo control offers; the evaluation commands dance at this tempo too.
        "music": {"tempo": music.DEFAULT_TEMPO, "range": list(music.TEMPO_RANGE)},
        "credit": CREDIT,
    }
    for name, m in models.items():
        f = out / f"{name}.onnx"
        entry = manifest["models"][name] = {
            "file": f.name, "bytes": f.stat().st_size, "role": m.cfg.role, "channels": m.cfg.channels,
            "classes": m.cfg.classes, "intention": m.cfg.intention, "hidden": m.cfg.hidden,
            # The grid is part of the file's identity: a page's cache (offline.ts assetVersion)
            # must not keep serving the same training's weights on another grid.
            "weightStep": weight_step, "fingerprint": fingerprint(m)}
        e = eval_file(out, name)
        if m.cfg.role == "follower" and e.exists():
            entry["eval"] = {"outputEncoder": os.path.relpath(e, out), "bytes": e.stat().st_size}
    # Models exported before into the same folder and not this time stay in the manifest, in their
    # place, while their files are there: `--model follower` after retraining the follower leaves the
    # page its leader.
    before = out / "manifest.json"
    if before.exists():
        try:
            old = json.loads(before.read_text()).get("models", {})
            kept = {k for k, v in old.items() if k not in models and (out / v.get("file", "")).is_file()}
        except (ValueError, AttributeError):
            old, kept = {}, set()   # not a manifest this code wrote: written anew
        new = manifest["models"]
        manifest["models"] = {**{k: new.get(k, v) for k, v in old.items() if k in new or k in kept},
                              **{k: v for k, v in new.items() if k not in old}}
        if kept:
            print(f"kept from the manifest there: {', '.join(sorted(kept))}")
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1))
    return manifest


def export_all(names: list[str], runs: str, out: str, data: str, prepared: str, keep_fp32: str | None,
               weight_step: int = WEIGHT_STEP):
    out_dir = Path(out)
    out_dir.mkdir(parents=True, exist_ok=True)
    fp32_dir = Path(keep_fp32) if keep_fp32 else Path(runs) / "fp32"
    fp32_dir.mkdir(parents=True, exist_ok=True)
    models = {}
    for name in names:
        model = load_run(Path(runs) / name, prepared).model
        fp32 = fp32_dir / f"{name}.onnx"
        export_onnx(model, fp32)
        quantize(fp32, out_dir / f"{name}.onnx")
        coarsen(out_dir / f"{name}.onnx", weight_step)
        short_names(out_dir / f"{name}.onnx")
        stamp = stamp_of(name, model)
        write_stamp(out_dir / f"{name}.onnx", stamp)
        if model.cfg.role == "follower":
            export_output_encoder(model, eval_file(out_dir, name))
            write_stamp(eval_file(out_dir, name), stamp)
        models[name] = model
        int8 = (out_dir / f"{name}.onnx").read_bytes()
        print(f"{name}: fp32 {fp32.stat().st_size / 1e6:.2f} MB -> int8 {len(int8) / 1e6:.2f} MB "
              f"(gzip {len(zlib.compress(int8, 9)) / 1e6:.2f} MB, weight step {weight_step})")
    return write_manifest(out_dir, models, data, prepared, weight_step)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.learning.export", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--model", action="append", help=f"default: {', '.join(SHIPPED)}")
    add_folder(ap, "runs", "read")
    add_folder(ap, "prepared", "read for the normalization")
    add_folder(ap, "data", "read for the skeleton offsets")
    add_folder(ap, "models", "written", old=("--out",))
    ap.add_argument("--fp32", default=None, help="where to keep the fp32 ONNX (default RUNS/fp32)")
    ap.add_argument("--weight-step", type=int, default=WEIGHT_STEP,
                    help=f"snap the int8 weights to every Nth level, so they compress better (1: keep all 256; default {WEIGHT_STEP})")
    args = ap.parse_args(argv)
    if not 1 <= args.weight_step <= 64:
        ap.error(f"--weight-step {args.weight_step}: between 1 (all 256 levels) and 64")
    try:
        m = export_all(args.model or SHIPPED, args.runs, args.models, args.data, args.prepared, args.fp32,
                       args.weight_step)
    except (TrainError, DataError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    total = sum(v["bytes"] for v in m["models"].values())
    print(f"wrote {args.models}/manifest.json; models total {total / 1e6:.2f} MB")
    if Path(args.models).resolve() == PAGE_MODELS.resolve():
        # tests/fixtures/runtime.json pins the page's models (tests/e2e/runtime.test.mjs).
        print("the page's models changed: rewrite the test fixtures with .venv/bin/python tests/python/fixtures_writer.py")
    return 0


if __name__ == "__main__":
    sys.exit(main())
