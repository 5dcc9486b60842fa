"""Which training an exported ONNX file comes from.

export writes a stamp into every file it writes (step models and their evaluation files) as ONNX
metadata: the run's fingerprint (runs.fingerprint: weights, configuration, normalization), the
model name, role and code size. The manifest repeats the fingerprint per model. Evaluation reads
the stamps back and refuses to score a step model with an evaluation file of another training.
"""
from __future__ import annotations

import json
from pathlib import Path

STAMP_KEY = "duet"
EVAL_FOLDER = "eval"                       # MODELS/eval/: evaluation only, the page never loads it
OUTPUT_ENCODER = "{name}.output_encoder.onnx"
REPO = Path(__file__).resolve().parents[2]
PAGE_MODELS = REPO / "public" / "models"   # what the static site publishes and the page's budget counts
SHIPPED_EVAL = REPO / "models" / "eval"    # the shipped models' evaluation files, outside public/


def eval_folder(models: str | Path) -> Path:
    """Where the evaluation files of the step models in `models` lie: MODELS/eval/, except for the
    page's own public/models, whose evaluation files (fp32, about 5 MB each) live in models/eval/
    at the top of the repository, so that nothing the page does not load is published with it."""
    models = Path(models)
    return SHIPPED_EVAL if models.resolve() == PAGE_MODELS.resolve() else models / EVAL_FOLDER


def eval_file(models: str | Path, name: str) -> Path:
    """Where the output encoder of model `name` lies (see eval_folder)."""
    return eval_folder(models) / OUTPUT_ENCODER.format(name=name)


def write_stamp(path: str | Path, stamp: dict) -> None:
    import onnx
    model = onnx.load(str(path))
    kept = [p for p in model.metadata_props if p.key != STAMP_KEY]
    del model.metadata_props[:]
    model.metadata_props.extend(kept)
    model.metadata_props.add(key=STAMP_KEY, value=json.dumps(stamp, sort_keys=True))
    onnx.save(model, str(path))


def read_stamp(path: str | Path) -> dict | None:
    """The stamp of an exported file; None for a file without one (exported before stamps, or
    not by training.learning.export)."""
    import onnx
    model = onnx.load(str(path), load_external_data=False)
    for p in model.metadata_props:
        if p.key == STAMP_KEY:
            return json.loads(p.value)
    return None
