#!/usr/bin/env python3
"""Golden fixtures for mannequin-splat, made with gsplat 1.5.x's pure-PyTorch functions.

Projection (`_quat_scale_to_covar_preci`, `_fully_fused_projection`) and spherical harmonics
(`_spherical_harmonics`) come from `gsplat/cuda/_torch_impl.py` and run on CPU in float64.
gsplat's rasterizer needs CUDA, so images come from the small dense compositor below, which
evaluates every Gaussian at every pixel with the 3DGS rules: alpha = min(0.99, o exp(-sigma)),
skipped where sigma < 0 or alpha < 1/255, and a pixel stops before the Gaussian that would bring
its transmittance to 1e-4 or below (gsplat's CUDA rule; gsplat caps alpha at 0.999, 3DGS and
Mannequin at 0.99). Colours are SH + 0.5 clamped at 0, as gsplat's `rasterization` does.

Usage: $HOME/.cache/mannequin-oracles/bin/python tools/oracles/splat_gsplat.py OUT_DIR
Writes OUT_DIR/splat_<scene>.npz. Inputs are rounded to float32 before the float64 oracle runs,
and every array is stored as float32 (radii and counts as int32).
"""
import math
import sys
from pathlib import Path

import numpy as np
import torch
from gsplat.cuda._torch_impl import (
    _fully_fused_projection,
    _quat_scale_to_covar_preci,
    _spherical_harmonics,
)

torch.set_default_dtype(torch.float64)
ALPHA_THRESHOLD = 1.0 / 255.0
MAX_ALPHA = 0.99
MIN_TRANSMITTANCE = 1e-4


def f32(a):
    """Round to float32 (what the fixture stores), back to float64 for the oracle."""
    return np.asarray(a, dtype=np.float32).astype(np.float64)


def look_at(eye, target, up):
    """World-to-camera 4x4 in the OpenCV convention (x right, y down, z forward)."""
    eye, target, up = map(np.asarray, (eye, target, up))
    z = target - eye
    z = z / np.linalg.norm(z)
    x = np.cross(z, -up)
    x = x / np.linalg.norm(x)
    y = np.cross(z, x)
    r = np.stack([x, y, z])
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = -r @ eye
    return m


def random_quats(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def sh_coeffs(rng, n, degree):
    k = (degree + 1) ** 2
    c = rng.uniform(-0.3, 0.3, size=(n, k, 3))
    c[:, 0, :] = rng.uniform(-0.5, 1.5, size=(n, 3))
    return c


def composite(means2d, conics, opacities, depths, colors, radii, width, height, background):
    """Dense front-to-back compositing of every valid Gaussian at every pixel centre."""
    ys, xs = torch.meshgrid(torch.arange(height) + 0.5, torch.arange(width) + 0.5, indexing="ij")
    px, py = xs.reshape(-1), ys.reshape(-1)
    npx, ch = px.shape[0], colors.shape[1]
    t = torch.ones(npx)
    color = torch.zeros(npx, ch)
    depth = torch.zeros(npx)
    count = torch.zeros(npx, dtype=torch.int64)
    done = torch.zeros(npx, dtype=torch.bool)
    valid = (radii > 0).all(dim=-1)
    order = [i for i in torch.argsort(depths, stable=True).tolist() if valid[i]]
    for i in order:
        dx, dy = px - means2d[i, 0], py - means2d[i, 1]
        a, b, c = conics[i]
        sigma = 0.5 * (a * dx * dx + c * dy * dy) + b * dx * dy
        alpha = torch.clamp(opacities[i] * torch.exp(-sigma), max=MAX_ALPHA)
        ok = (sigma >= 0) & (alpha >= ALPHA_THRESHOLD) & ~done
        nxt = t * (1 - alpha)
        stop = ok & (nxt <= MIN_TRANSMITTANCE)
        done |= stop
        take = ok & ~stop
        w = torch.where(take, alpha * t, torch.zeros_like(t))
        color += w[:, None] * colors[i][None, :]
        depth += w * depths[i]
        count += take.long()
        t = torch.where(take, nxt, t)
    alpha_img = 1 - t
    color = color + t[:, None] * torch.as_tensor(background)[None, :]
    exp_depth = depth / torch.clamp(alpha_img, min=1e-10)
    return (
        color.T.reshape(ch, height, width),
        alpha_img.reshape(height, width),
        exp_depth.reshape(height, width),
        count.reshape(height, width),
    )


def drop_depth_ties(scene):
    """Removes Gaussians whose camera depth is within 1e-5 of another's: their order is a tie
    that float32 and float64 may break differently, which is not what the fixtures test."""
    pc = scene["means"] @ scene["viewmat"][:3, :3].T + scene["viewmat"][:3, 3]
    order = np.argsort(pc[:, 2], kind="stable")
    gaps = np.diff(pc[order, 2])
    drop = set(order[1:][gaps < 1e-5].tolist())
    keep = np.array([i for i in range(len(pc)) if i not in drop])
    for key in ("means", "quats", "scales", "opacities", "sh", "features"):
        if key in scene:
            scene[key] = scene[key][keep]
    return scene


def oracle(scene):
    """Runs gsplat's projection and SH, then the dense compositor."""
    means = torch.as_tensor(scene["means"])
    quats = torch.as_tensor(scene["quats"])
    scales = torch.as_tensor(scene["scales"])
    viewmat = torch.as_tensor(scene["viewmat"])
    K = torch.as_tensor(scene["K"])
    w, h = int(scene["width"]), int(scene["height"])
    covars, _ = _quat_scale_to_covar_preci(quats, scales, compute_covar=True, compute_preci=False)
    radii, means2d, depths, conics, _ = _fully_fused_projection(
        means, covars, viewmat[None], K[None], w, h, eps2d=float(scene["eps2d"]),
        near_plane=float(scene["near"]), far_plane=float(scene["far"]),
    )
    radii, means2d, depths, conics = radii[0], means2d[0], depths[0], conics[0]
    if "sh" in scene:
        campos = torch.linalg.inv(viewmat)[:3, 3]
        colors = _spherical_harmonics(int(scene["sh_degree"]), means - campos, torch.as_tensor(scene["sh"]))
        colors = torch.clamp_min(colors + 0.5, 0.0)
    else:
        colors = torch.as_tensor(scene["features"])
    image, alpha, depth, count = composite(
        means2d, conics, torch.as_tensor(scene["opacities"]), depths, colors, radii, w, h, scene["background"]
    )
    return {
        "radii": radii.int().numpy(),
        "means2d": means2d.numpy(),
        "conics": conics.numpy(),
        "depths": depths.numpy(),
        "colors": colors.numpy(),
        "image": image.numpy(),
        "alpha": alpha.numpy(),
        "depth": depth.numpy(),
        "count": count.int().numpy(),
    }


def camera(width, height, eye, target, fx, fy, cx, cy, near=0.01, far=100.0):
    return {
        "width": width, "height": height,
        "K": np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1.0]]),
        "viewmat": look_at(eye, target, [0.0, 1.0, 0.0]),
        "near": near, "far": far,
    }


def random_cloud(rng):
    n = 200
    s = camera(64, 48, [0.4, 0.3, 3.0], [0.0, 0.0, 0.0], 70.0, 66.0, 31.0, 25.0)
    s.update(
        means=rng.uniform(-0.8, 0.8, size=(n, 3)),
        quats=random_quats(rng, n),
        scales=np.exp(rng.uniform(np.log(0.01), np.log(0.2), size=(n, 3))),
        opacities=rng.uniform(0.05, 1.0, size=n),
        sh_degree=3, sh=sh_coeffs(rng, n, 3),
        background=np.array([0.1, 0.2, 0.3]),
    )
    return s


def human_shell(rng):
    """An ellipsoid-ish shell 1.7 m tall, 2.5 m from the camera, densely covered."""
    n = 1200
    u = rng.uniform(0, 2 * np.pi, n)
    v = np.arccos(rng.uniform(-1, 1, n))
    radius = np.stack([0.25 * np.ones(n), 0.85 * np.ones(n), 0.15 * np.ones(n)], axis=1)
    radius[:, 0] *= 1 + 0.3 * np.cos(3 * v)
    pts = radius * np.stack([np.sin(v) * np.cos(u), np.cos(v), np.sin(v) * np.sin(u)], axis=1)
    pts[:, 1] += 0.85
    s = camera(48, 64, [0.0, 0.9, 2.5], [0.0, 0.85, 0.0], 80.0, 80.0, 24.0, 32.0)
    s.update(
        means=pts,
        quats=random_quats(rng, n),
        scales=np.exp(rng.uniform(np.log(0.01), np.log(0.05), size=(n, 3))),
        opacities=rng.uniform(0.5, 1.0, size=n),
        sh_degree=0, sh=sh_coeffs(rng, n, 0),
        background=np.array([1.0, 1.0, 1.0]),
        # The screen filter avatars train with (mannequin_avatar::AVATAR_DILATION), not 3DGS's 0.3.
        eps2d=0.1,
    )
    return s


def behind_and_crossing(rng):
    """Gaussians behind the camera, straddling the near plane, very close, and off to the side
    (where the Jacobian's frustum clamp is active)."""
    cam = camera(40, 32, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 40.0, 40.0, 20.0, 16.0, near=0.05, far=6.0)
    n = 60
    z = np.concatenate([rng.uniform(-1.0, 0.0, 10), rng.uniform(0.0, 0.1, 10), rng.uniform(0.1, 0.5, 10),
                        rng.uniform(0.5, 7.0, 30)])
    xy = rng.uniform(-0.8, 0.8, size=(n, 2)) * np.maximum(z, 0.3)[:, None]
    means = np.concatenate([xy, z[:, None]], axis=1)
    cam.update(
        means=means,
        quats=random_quats(rng, n),
        scales=np.exp(rng.uniform(np.log(0.01), np.log(0.3), size=(n, 3))),
        opacities=rng.uniform(0.2, 1.0, size=n),
        sh_degree=2, sh=sh_coeffs(rng, n, 2),
        background=np.array([0.0, 0.0, 0.0]),
    )
    return cam


def tiny_and_huge(rng):
    """Sub-pixel splats (the 0.3 px dilation dominates) and splats larger than the image,
    with 2-channel features."""
    s = camera(48, 40, [0.0, 0.0, 2.0], [0.0, 0.0, 0.0], 60.0, 60.0, 24.0, 20.0)
    n = 80
    scales = np.concatenate([np.exp(rng.uniform(np.log(1e-5), np.log(1e-3), size=(60, 3))),
                             np.exp(rng.uniform(np.log(0.5), np.log(3.0), size=(20, 3)))])
    s.update(
        means=rng.uniform(-0.6, 0.6, size=(n, 3)),
        quats=random_quats(rng, n),
        scales=scales,
        opacities=np.concatenate([rng.uniform(0.5, 1.0, 60), rng.uniform(0.02, 0.3, 20)]),
        features=rng.uniform(-1.0, 1.0, size=(n, 2)),
        background=np.array([0.25, -0.5]),
    )
    return s


SCENES = {
    "random_cloud": random_cloud,
    "human_shell": human_shell,
    "behind_and_crossing": behind_and_crossing,
    "tiny_and_huge": tiny_and_huge,
}


def main():
    out_dir = Path(sys.argv[1])
    out_dir.mkdir(parents=True, exist_ok=True)
    for i, (name, make) in enumerate(SCENES.items()):
        rng = np.random.default_rng(1000 + i)
        scene = {"eps2d": 0.3, **make(rng)}
        for key in ("means", "quats", "scales", "opacities", "sh", "features", "K", "viewmat", "background"):
            if key in scene:
                scene[key] = f32(scene[key])
        scene = drop_depth_ties(scene)
        result = oracle(scene)
        arrays = {}
        for key, value in list(scene.items()) + list(result.items()):
            value = np.asarray(value)
            if value.dtype.kind == "f":
                value = value.astype(np.float32)
            elif value.dtype.kind in "iu":
                value = value.astype(np.int32)
            arrays[key] = value
        path = out_dir / f"splat_{name}.npz"
        np.savez_compressed(path, **arrays)
        visible = int((result["radii"] > 0).all(axis=-1).sum())
        print(f"{path}: {len(scene['opacities'])} Gaussians, {visible} visible, "
              f"alpha mean {result['alpha'].mean():.3f}, max count {result['count'].max()}")


if __name__ == "__main__":
    main()
