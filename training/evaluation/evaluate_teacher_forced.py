"""Protocol (a) of training.evaluation.evaluate, teacher-forced: every input from the recording,
one step. The pose error of the t+1 pose, and the codebook error of each learned follower against
its output encoder (an evaluation file exported beside the step model, of the same training)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..learning.stamp import eval_file, read_stamp
from ..mirror import features as feat
from ..mirror.features import follower_input, output_features
from . import metrics as M
from .evaluate_inputs import EvalError
from .motion_matching import MotionMatching, own_future

OUT = feat.block_slices(feat.OUTPUT_LAYOUT)


def teacher_forced(takes, policies: dict, mm_oracle: MotionMatching | None, bar) -> dict:
    """Per method: predicted O [N, 323] for every evaluated frame (inputs from the recording)."""
    x = np.concatenate([follower_input(t.lead, t.follow, t.frames, t.figure(t.frames)) for t in takes])
    y = np.concatenate([output_features(t.follow, t.frames) for t in takes])
    outputs, codes = {}, {}
    for name, policy in policies.items():
        if name == "ground_truth":
            outputs[name] = y
        elif isinstance(policy, MotionMatching):
            policy.reset()          # no plan: the own future is extrapolated from the past
            outputs[name] = np.asarray(policy(x)["output"], np.float64)
        else:
            rng = np.random.default_rng(0)   # unused at temperature 0
            res = [policy(x[s:s + 512], 0.0, rng) for s in range(0, len(x), 512)]
            outputs[name] = np.concatenate([r["output"] for r in res]).astype(np.float64)
            codes[name] = np.concatenate([r["code"] for r in res])
        bar.update(len(x))
    if mm_oracle is not None:
        fut = np.concatenate([own_future(t.follow, t.frames) for t in takes])
        outputs["motion_matching_oracle"] = np.asarray(mm_oracle(x, self_future=fut)["output"], np.float64)
    return {"x": x, "y": y, "outputs": outputs, "codes": codes}


def pose_positions(o: np.ndarray) -> np.ndarray:
    return o[:, OUT["pose"]].reshape(len(o), feat.N_JOINTS, 12)[..., :3]


class OutputEncoder:
    """An evaluation file (MODELS/eval/NAME.output_encoder.onnx): the code the output encoder of
    one training gives a recorded or generated output, beside the input it answers."""

    def __init__(self, path: Path, stamp: dict):
        from ..mirror.policy import open_session
        try:
            self.session = open_session(path)
        except Exception as e:   # onnxruntime raises its own types for a damaged file
            raise EvalError(f"{path}: cannot be loaded by onnxruntime ({e.__class__.__name__})") from None
        self.channels, self.classes = stamp["channels"], stamp["classes"]

    def codes(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Code indices [N, C] of outputs y [N, 323] after inputs x [N, 660] (raw features)."""
        logits = np.concatenate([self.session.run(None, {"input": x[s:s + 512].astype(np.float32),
                                                         "output": y[s:s + 512].astype(np.float32)})[0]
                                 for s in range(0, len(x), 512)])
        return logits.reshape(len(x), self.channels, self.classes).argmax(-1)


def output_encoders(root: Path, manifest: dict, onnx: dict[str, Path], methods: list[str]) -> tuple[dict, list[str]]:
    """{method: OutputEncoder or None} for the learned followers whose codebook error is needed
    (ours too where Motion Matching is scored with it), and notes. Refuses (EvalError) a step model
    beside an evaluation file or manifest entry of another training."""
    wanted = [m for m in methods if m in onnx] + (["ours"] if "motion_matching" in methods and "ours" in onnx else [])
    encoders, notes = {}, []
    for method in dict.fromkeys(wanted):
        step = onnx[method]
        enc = eval_file(root, step.stem)
        stamps = {str(step): read_stamp(step), str(enc): read_stamp(enc) if enc.exists() else None}
        prints = {f: (st or {}).get("fingerprint") for f, st in stamps.items()}
        listed = manifest.get("models", {}).get(step.stem)
        if listed is not None:
            prints[f"{root / 'manifest.json'} ({step.stem})"] = listed.get("fingerprint")
        trainings = {fp: f for f, fp in prints.items() if fp}
        if len(trainings) > 1:
            (fa, a), (fb, b) = list(trainings.items())[:2]
            raise EvalError(f"{a} and {b} come from different trainings (fingerprints {fa} and {fb}); "
                            f"export them together: python -m training.learning.export --models {root}")
        if not enc.exists():
            notes.append(f"codebook error of {method}: {enc} not found (python -m training.learning.export writes it)")
            encoders[method] = None
            continue
        unstamped = [f for f, fp in prints.items() if not fp]
        if unstamped:
            raise EvalError(f"{unstamped[0]} carries no training fingerprint, so {enc} cannot be matched "
                            f"with it; export them together: python -m training.learning.export --models {root}")
        encoders[method] = OutputEncoder(enc, stamps[str(enc)])
    return encoders, notes


def codebook_errors(tf: dict, methods: list[str], encoders: dict) -> dict:
    """Codebook error per method from the exported files (None where an evaluation file is missing).

    A model's target code is its output encoder's argmax on the recorded output (the evaluation
    file), its estimate the code its step model picks at temperature 0 (the shipped file). Motion
    Matching has no encoder of its own: its estimate is our output encoder's code of the frame it
    picked, against the same target."""
    res = {}
    for method in methods:
        enc = encoders.get("ours" if method == "motion_matching" else method)
        if method == "ground_truth" or enc is None:
            res[method] = None
            continue
        target = enc.codes(tf["x"], tf["y"])
        estimate = (enc.codes(tf["x"], tf["outputs"][method]) if method == "motion_matching"
                    else tf["codes"][method])
        res[method] = M.codebook_error(M.one_hot(target, enc.classes), M.one_hot(estimate, enc.classes))
    return res
