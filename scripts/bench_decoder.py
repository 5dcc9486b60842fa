"""Does the gather decoder pay? The shipped follower step with its first decoder layer as a gather
of C weight rows (StepModel.decode) vs the same network multiplying the full one-hot code, both
dynamic int8 in native onnxruntime, 1 thread, batch 1, timed in interleaved rounds.

    PYTHONPATH=. .venv/bin/python scripts/bench_decoder.py      (needs runs/models/follower)
"""
import time

import numpy as np
import onnxruntime as ort
import torch
from pathlib import Path

from training.learning.export import export_onnx, quantize
from training.learning.models import StepModel
from training.learning.runs import load_run
torch.set_num_threads(1)
m = load_run(Path('runs/models/follower'), 'runs/data').model
class FullDecode(StepModel):
    def decode(self, code, xn):   # one-hot [B, C*D] times the full first-layer matrix
        oh = torch.nn.functional.one_hot(code, self.cfg.classes).float().reshape(code.shape[0], -1)
        return self.matching.decode(oh, xn)
full = FullDecode(m.cfg, m.predictor, m.matching, {k: getattr(m, k) for k in ['input_mean','input_std','output_mean','output_std','intention_mean','intention_std']}).eval()
out = Path('runs/bench_decoder'); out.mkdir(parents=True, exist_ok=True)
for name, model in (('gather', m), ('full', full)):
    export_onnx(model, out / f'{name}32.onnx'); quantize(out / f'{name}32.onnx', out / f'{name}.onnx')
so = ort.SessionOptions(); so.intra_op_num_threads = 1
x = np.load('runs/data/test.npz')['follower_input'][:1].astype(np.float32)
feeds = {'input': x, 'temperature': np.array([0.5], np.float32), 'noise': np.random.default_rng(0).random((1, m.cfg.latent), dtype=np.float32)}
sess = {n: ort.InferenceSession(str(out / f'{n}.onnx'), so, providers=['CPUExecutionProvider']) for n in ('gather', 'full')}
a = sess['gather'].run(None, feeds)[0]; b = sess['full'].run(None, feeds)[0]
print('max |gather - full| int8 outputs:', float(np.abs(a - b).max()))
res = {n: [] for n in sess}
for rep in range(7):   # interleaved rounds so machine noise hits both alike
    for n, s in sess.items():
        t0 = time.perf_counter()
        for _ in range(300): s.run(None, feeds)
        res[n].append((time.perf_counter() - t0) / 300 * 1e3)
g, f = np.median(res['gather']), np.median(res['full'])
print(f'native ORT int8, 1 thread, batch 1: gather {g:.3f} ms, full one-hot matmul {f:.3f} ms, ratio full/gather {f/g:.2f}')
print('int8 bytes: gather', (out/'gather.onnx').stat().st_size, 'full', (out/'full.onnx').stat().st_size)
