"""The folders the commands read and write, and the one flag name each has in every command.

    --data DIR       BVH couples, SUBJECT_TAKE.bvh (the CMU salsa takes)   prepare, export, evaluate, plots,
                     (default: default_data() below)                      motion_matching
    --prepared DIR   prepared arrays: {train,validation,test,stats}.npz    prepare writes; train, validation,
                     (default runs/data)                                  export, plots read
    --runs DIR       trained runs, one folder per model with checkpoint.pt train writes; export, plots read
                     (default runs/models)
    --models DIR     exported ONNX step models + manifest.json              export writes; evaluate, soak,
                     (default public/models)                              plots read

`--out` is left for what a command writes that is none of these (evaluate's report, plots' PNGs).

Older names are still accepted, hidden from --help, and print a note naming the new flag:
prepare --out, train --data / --out, validation --data, export --out, plots --bvh. (plots --data
used to mean the prepared arrays; it now means the BVH couples, like everywhere else.)
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
REPO_DATA = REPO / "data" / "cmu-salsa"                          # git-ignored: put the takes here
SHARED_DATA = REPO.parent / "shared" / "data" / "cmu-salsa"      # the project machines' copy
DATA_ENV = "DUET_DATA"
DEFAULT_PREPARED = "runs/data"
DEFAULT_RUNS = "runs/models"
DEFAULT_MODELS = "public/models"



def default_data() -> str:
    """The BVH couples folder when --data is not given: $DUET_DATA if set; else data/cmu-salsa in
    the repository if it exists; else ../shared/data/cmu-salsa beside the repository if that
    exists; else data/cmu-salsa (where README's "Data" says to put the takes)."""
    if os.environ.get(DATA_ENV):
        return os.environ[DATA_ENV]
    for folder in (REPO_DATA, SHARED_DATA):
        if folder.is_dir():
            return _short(folder)
    return _short(REPO_DATA)


def _short(path: Path) -> str:
    """Relative to the working directory when below it (commands run from the repository root)."""
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


DEFAULTS = {"prepared": DEFAULT_PREPARED, "runs": DEFAULT_RUNS, "models": DEFAULT_MODELS}
WHAT = {
    "data": f"BVH couples (folder of SUBJECT_TAKE.bvh pairs; default ${DATA_ENV}, else data/cmu-salsa, "
            f"else ../shared/data/cmu-salsa)",
    "prepared": "prepared arrays (training.data.prepare's output)",
    "runs": "trained runs, one folder per model (training.learning.train's output)",
    "models": "exported ONNX models + manifest.json (training.learning.export's output)",
}


class _OldName(argparse.Action):
    """A renamed flag: sets the new flag's value and says so on stderr."""

    def __init__(self, option_strings, dest, new: str, **kw):
        self.new = new
        super().__init__(option_strings, dest, **kw)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"note: {option_string} is now {self.new} (the old name still works)", file=sys.stderr)
        setattr(namespace, self.dest, values)


def add_folder(ap: argparse.ArgumentParser, name: str, use: str, default: str | None = None,
               old: tuple[str, ...] = ()) -> None:
    """Add --NAME (data, prepared, runs or models) with its one meaning; `use` says what this
    command does with it; `old` are former names of the same flag, kept as hidden aliases."""
    if default is None:
        default = default_data() if name == "data" else DEFAULTS[name]
    ap.add_argument(f"--{name}", default=default, metavar="DIR",
                    help=f"{WHAT[name]}: {use} (default {default})")
    for flag in old:
        ap.add_argument(flag, dest=name, action=_OldName, new=f"--{name}", help=argparse.SUPPRESS)


class _Retired(argparse.Action):
    def __init__(self, option_strings, dest, why: str, **kw):
        self.why = why
        super().__init__(option_strings, argparse.SUPPRESS, **kw)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"note: {option_string} is no longer read: {self.why}", file=sys.stderr)


def add_retired(ap: argparse.ArgumentParser, flag: str, why: str) -> None:
    """A flag this command no longer uses: still accepted (old scripts keep working), hidden,
    ignored with a note saying why."""
    ap.add_argument(flag, action=_Retired, why=why, default=argparse.SUPPRESS, help=argparse.SUPPRESS)
