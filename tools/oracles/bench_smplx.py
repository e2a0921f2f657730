"""Times smplx posing a clip with the random 6,890-vertex SMPL model of body_smplx.py, on CPU.
Prints one line: `smplx_seconds <s>`. Used by `cargo bench -p mannequin-body --bench pose`.

Run: $ORACLE_VENV/bin/python tools/oracles/bench_smplx.py FRAMES THREADS
"""
import os
import pickle
import sys
import tempfile
import time

import numpy as np
import torch
import smplx

sys.path.insert(0, os.path.dirname(__file__))
from body_smplx import GRIDS, random_model  # noqa: E402

frames, threads = int(sys.argv[1]), int(sys.argv[2])
torch.set_num_threads(threads)
with tempfile.TemporaryDirectory() as d:
    path = os.path.join(d, "SMPL_NEUTRAL.pkl")
    pickle.dump(random_model(24, 10, GRIDS["smpl"]), open(path, "wb"))
    model = smplx.SMPL(model_path=path, batch_size=frames)
rng = np.random.default_rng(0)
t = lambda a: torch.tensor(a, dtype=torch.float32)
pose = rng.uniform(-0.6, 0.6, (frames, 72))
args = dict(betas=t(rng.uniform(-2, 2, (1, 10)).repeat(frames, 0)), global_orient=t(pose[:, :3]),
            body_pose=t(pose[:, 3:]), transl=t(np.zeros((frames, 3))))
with torch.no_grad():
    model(**args)  # warm-up
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        model(**args)
        best = min(best, time.perf_counter() - start)
print(f"smplx_seconds {best:.6f}")
