"""Side-view stick frames every 0.5 s of one steered seed of the shipped models, the 6 s with most
follower frames out of the recorded joint-angle range (how the worst seed of training.evaluation.seeds
looks).   PYTHONPATH=. .venv/bin/python scripts/worst_seed.py SEED OUT.png"""
import json, sys
import numpy as np
import matplotlib; matplotlib.use("Agg")
import matplotlib.pyplot as plt
from training.evaluation.soak import soak_one
from training.evaluation.evaluate_inputs import find_models, load_onnx
from training.evaluation import plausibility as P
from training.mirror.skeleton import PARENTS, FPS
seed = int(sys.argv[1]); out = sys.argv[2]
manifest, onnx, leader = find_models('public/models')
rec = {}
soak_one(manifest, load_onnx(leader), load_onnx(onnx['ours']), seed, 60 * FPS, 0.5, rec)
L, F = rec['leader_shown'], rec['follower_shown']
flags = P.frame_flags(F, manifest['plausibility'])
bad = flags['angles_out'].astype(float)
start = int(np.argmax(np.convolve(bad, np.ones(6 * FPS), 'valid')))   # the 6 s with most flagged frames
fig, axes = plt.subplots(2, 6, figsize=(18, 6.5))
for k, ax in enumerate(axes.flat):
    t = start + k * FPS // 2
    c = (L[t, 0] + F[t, 0]) / 2
    for pos, col in ((L[t], 'tab:blue'), (F[t], 'tab:red')):
        for j, p in enumerate(PARENTS):
            if p >= 0:
                ax.plot([pos[j, 0] - c[0], pos[p, 0] - c[0]], [pos[j, 1], pos[p, 1]], color=col, lw=2)
    ax.set_xlim(-1.2, 1.2); ax.set_ylim(0, 1.9); ax.set_aspect('equal'); ax.set_xticks([]); ax.set_yticks([])
    ax.set_title(f"t={t / FPS:.1f} s{'  angle out' if flags['angles_out'][t] else ''}", fontsize=9)
fig.suptitle(f"steered seed {seed} (the worst of 100 by follower joint angles out of range, with the layer): "
             f"the 6 s with most flagged frames, side view (x, height), a frame every 0.5 s")
fig.tight_layout(); fig.savefig(out, dpi=80)
print(start / FPS, bad.mean())
