"""onnxruntime sessions that compute what the page computes (web/engine/policy.ts, SESSION_OPTIONS).

The shipped models are dynamic-int8: each MatMul multiplies u8 activations by s8 weights. On x86
CPUs without VNNI (AVX2 only: many AMD EPYC and older Intel machines) onnxruntime's default u8 x s8
kernel adds pairs of products in 16 bits, which saturate, so the same model gives other poses and
codes there than on a VNNI CPU. The page's onnxruntime-web (WebAssembly) sums exactly, like VNNI.
`session.x64quantprecision` makes onnxruntime convert the weights to u8 at load and use its exact
u8 x u8 kernel on the CPUs that need it (no effect elsewhere; the files stay as they are), so every
Python figure of the int8 models is the page's on any CPU. Measured on the fixture inputs
(tests/fixtures/runtime.json, written on a VNNI CPU), on an AVX2-only AMD EPYC: up to 5.7e-2
relative difference without it, 4e-7 (the fixture's rounding) with it (docs/testing.md).
"""
from __future__ import annotations

from pathlib import Path


def session_options(threads: int = 1):
    import onnxruntime as ort
    so = ort.SessionOptions()
    so.intra_op_num_threads = threads
    so.inter_op_num_threads = 1
    so.add_session_config_entry("session.x64quantprecision", "1")
    return so


def open_session(path: Path | str, threads: int = 1):
    """An onnxruntime CPU session of one ONNX file, computing as the page does."""
    import onnxruntime as ort
    return ort.InferenceSession(str(path), session_options(threads), providers=["CPUExecutionProvider"])
