#!/usr/bin/env python3
"""gsplat's CUDA rasterizer timed on the scenes `cargo bench -p mannequin-splat --bench splat --
--device gpu --save-scenes DIR` writes, so the two speeds come from one job on one GPU.

Usage: python3 tools/bench/gsplat_speed.py DIR [--reps 21]
Needs torch with CUDA and gsplat 1.5.3 (its kernels compile on first use: set
TORCH_CUDA_ARCH_LIST to the card's, e.g. "9.0", and MAX_JOBS to the cores).
Times L = <image, d_image> forward and forward+backward with means, quats and scales as leaves,
as the Rust bench does; best of `reps` after a warm-up, synchronised, in ms.
"""
import argparse
import glob
import os
import time

import numpy as np
import torch
from gsplat import rasterization


def best_ms(reps, f):
    f()
    torch.cuda.synchronize()
    best = float("inf")
    for _ in range(reps):
        start = time.perf_counter()
        f()
        torch.cuda.synchronize()
        best = min(best, (time.perf_counter() - start) * 1e3)
    return best


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("dir")
    parser.add_argument("--reps", type=int, default=21)
    args = parser.parse_args()
    dev = torch.device("cuda")
    print(f"gsplat {__import__('gsplat').__version__} on {torch.cuda.get_device_name()}")
    print(f"{'N':>8} {'device':>12} {'forward ms':>12} {'fwd+bwd ms':>12}")
    paths = sorted(glob.glob(os.path.join(args.dir, "scene_*.npz")), key=lambda p: int(p.split("_")[-1][:-4]))
    for path in paths:
        z = np.load(path)
        t = {k: torch.from_numpy(z[k]).to(dev) for k in z.files}
        _, h, w = t["d_image"].shape
        d_image = t["d_image"].permute(1, 2, 0).unsqueeze(0)
        background = torch.ones(1, 3, device=dev)

        def render(backward):
            leaf = (lambda x: x.clone().requires_grad_(True)) if backward else (lambda x: x)
            means, quats, scales = leaf(t["means"]), leaf(t["quats"]), leaf(t["scales"])
            image, alpha, _ = rasterization(
                means, quats, scales, t["opacities"], t["sh"],
                t["viewmat"][None], t["K"][None], w, h,
                near_plane=0.01, far_plane=1e10, sh_degree=3, backgrounds=background,
                eps2d=0.3, rasterize_mode="classic", packed=False,
            )
            if backward:
                (image * d_image).sum().backward()
            return image, alpha

        with torch.no_grad():
            _, alpha = render(False)
        coverage = 100.0 * (alpha > 0.5).float().mean().item()
        fwd = best_ms(args.reps, lambda: torch.no_grad()(render)(False))
        both = best_ms(args.reps, lambda: render(True))
        n = t["means"].shape[0]
        print(f"{n:>8} {'gsplat CUDA':>12} {fwd:>12.2f} {both:>12.2f}   (alpha coverage {coverage:.1f}%)")


if __name__ == "__main__":
    main()
