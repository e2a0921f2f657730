#!/usr/bin/env python3
"""A 3DGS .ply written the way the INRIA reference code writes it (`GaussianModel.save_ply`),
and the same Gaussians as plain arrays, to check that mannequin-splat reads such files.

INRIA stores `features_rest` as [N, K-1, 3] and writes it `transpose(1, 2).flatten(1)`, that is
channel-major; opacity is a logit, scales are logs, rotations (w, x, y, z) are stored as is.
The file is written with numpy's structured arrays, as `plyfile.PlyElement.describe` lays it out.

Usage: $HOME/.cache/mannequin-oracles/bin/python tools/oracles/splat_ply.py OUT_DIR
"""
import sys
from pathlib import Path

import numpy as np


def main():
    out = Path(sys.argv[1])
    rng = np.random.default_rng(7)
    n, degree = 20, 3
    k = (degree + 1) ** 2
    xyz = rng.normal(size=(n, 3)).astype(np.float32)
    features_dc = rng.normal(size=(n, 1, 3)).astype(np.float32)
    features_rest = rng.normal(scale=0.2, size=(n, k - 1, 3)).astype(np.float32)
    opacity_logit = rng.normal(size=(n, 1)).astype(np.float32)
    log_scale = rng.uniform(-5, -2, size=(n, 3)).astype(np.float32)
    rotation = rng.normal(size=(n, 4)).astype(np.float32)

    f_dc = features_dc.transpose(0, 2, 1).reshape(n, -1)
    f_rest = features_rest.transpose(0, 2, 1).reshape(n, -1)
    names = ["x", "y", "z", "nx", "ny", "nz"]
    names += [f"f_dc_{i}" for i in range(f_dc.shape[1])]
    names += [f"f_rest_{i}" for i in range(f_rest.shape[1])]
    names += ["opacity"] + [f"scale_{i}" for i in range(3)] + [f"rot_{i}" for i in range(4)]
    values = np.concatenate(
        [xyz, np.zeros_like(xyz), f_dc, f_rest, opacity_logit, log_scale, rotation], axis=1
    )
    records = np.empty(n, dtype=[(name, "f4") for name in names])
    records[:] = list(map(tuple, values))
    header = "ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % n
    header += "".join(f"property float {name}\n" for name in names) + "end_header\n"
    with open(out / "splat_inria.ply", "wb") as f:
        f.write(header.encode("ascii"))
        f.write(records.tobytes())

    sh = np.concatenate([features_dc, features_rest], axis=1)  # [N, K, 3], gsplat's layout
    np.savez_compressed(
        out / "splat_inria.npz",
        means=xyz,
        quaternions=rotation,
        scales=np.exp(log_scale.astype(np.float64)),
        opacities=1.0 / (1.0 + np.exp(-opacity_logit[:, 0].astype(np.float64))),
        sh=sh,
        sh_degree=np.int32(degree),
    )
    print(out / "splat_inria.ply", n, "Gaussians, SH degree", degree)


if __name__ == "__main__":
    main()
