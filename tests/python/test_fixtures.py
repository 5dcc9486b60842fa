"""tests/fixtures/*.json still say what training/ computes (tests/python/fixtures_writer.py rewrites them).

The TypeScript tests compare web/mirror/*.ts against these files; this test compares the files against
the Python reference, so a change on either side shows up as a failing test.
"""
from __future__ import annotations

import json
import math

import pytest

import fixtures_writer as fixtures


@pytest.fixture(scope="module")
def built():
    # Through JSON, as written: tuples become lists, NaN-free.
    return json.loads(json.dumps(fixtures.build(), allow_nan=False))


def same(a, b, path="") -> None:
    if isinstance(b, dict):
        assert isinstance(a, dict) and a.keys() == b.keys(), f"{path}: keys differ"
        for k in b:
            same(a[k], b[k], f"{path}.{k}")
    elif isinstance(b, list):
        assert isinstance(a, list) and len(a) == len(b), f"{path}: length differs"
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{path}[{i}]")
    elif isinstance(b, float) and isinstance(a, (int, float)):
        assert math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-6), f"{path}: {a} != {b}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


@pytest.mark.parametrize("name", ["bvh", "features", "rollout", "runtime"])
def test_fixture_file_matches_python(built, name):
    path = fixtures.OUT_DIR / f"{name}.json"
    assert path.exists(), f"{path} missing: run .venv/bin/python tests/python/fixtures_writer.py"
    same(json.loads(path.read_text()), built[name], name)
