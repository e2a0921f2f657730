"""PSNR and SSIM oracle fixture from scikit-image.

Writes crates/mannequin-data/tests/fixtures/image_metrics.npz: image pairs as uint8 (N, H, W, 3)
and scikit-image's PSNR and SSIM of each pair, on the images as float64 in [0, 1], with the
settings the papers use (data range 1, Gaussian window sigma 1.5, population covariance).

Run: $HOME/.cache/mannequin-oracles/bin/python tools/oracles/data_image_metrics.py
"""

from pathlib import Path

import numpy as np
from skimage.metrics import peak_signal_noise_ratio, structural_similarity

OUT = Path(__file__).resolve().parents[2] / "crates/mannequin-data/tests/fixtures/image_metrics.npz"


def pair(rng, h, w, noise, shift):
    y, x = np.mgrid[0:h, 0:w] / max(h, w)
    base = np.stack([0.5 + 0.4 * np.sin(9 * x + 3 * y), 0.5 + 0.4 * np.cos(7 * y), (x + y) / 2], -1)
    base += 0.15 * rng.standard_normal((h, w, 3))
    gt = np.clip(base, 0, 1)
    pred = np.roll(gt, shift, axis=1) + noise * rng.standard_normal((h, w, 3))
    return (np.clip(gt, 0, 1) * 255).round().astype(np.uint8), (np.clip(pred, 0, 1) * 255).round().astype(np.uint8)


def main():
    rng = np.random.default_rng(20240601)
    shapes = [(40, 48, 0.05, 0), (33, 29, 0.2, 1), (40, 48, 0.01, 2)]
    gts, preds, psnr, ssim = [], [], [], []
    for h, w, noise, shift in shapes:
        g, p = pair(rng, h, w, noise, shift)
        # Pad to one array shape; the true size is stored alongside.
        G = np.zeros((40, 48, 3), np.uint8)
        P = np.zeros((40, 48, 3), np.uint8)
        G[:h, :w], P[:h, :w] = g, p
        gts.append(G)
        preds.append(P)
        gf, pf = g.astype(np.float64) / 255, p.astype(np.float64) / 255
        psnr.append(peak_signal_noise_ratio(gf, pf, data_range=1.0))
        ssim.append(
            structural_similarity(
                gf, pf, channel_axis=2, data_range=1.0, gaussian_weights=True, sigma=1.5, use_sample_covariance=False
            )
        )
    np.savez_compressed(
        OUT,
        gt=np.stack(gts),
        pred=np.stack(preds),
        sizes=np.array([[h, w] for h, w, _, _ in shapes], np.int64),
        psnr=np.array(psnr),
        ssim=np.array(ssim),
    )
    print(OUT, psnr, ssim)


if __name__ == "__main__":
    main()
