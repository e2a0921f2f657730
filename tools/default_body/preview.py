#!/usr/bin/env python3
"""Render a converted body to PNG (front and side views, a few shapes, a few poses) and write
OBJ files, to look at the converter's output.

    python3 tools/default_body/preview.py crates/mannequin-body/assets/default_body.npz --out /tmp/preview

Needs numpy and matplotlib.
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402


def rodrigues(axis_angle):
    angle = np.linalg.norm(axis_angle)
    if angle < 1e-12:
        return np.eye(3)
    k = axis_angle / angle
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx


def pose(model, betas, thetas):
    """SMPL forward pass (no pose correctives): thetas (24, 3) axis-angle, local to parents."""
    v = model["v_template"] + model["shapedirs"][:, :, : len(betas)] @ betas
    j = model["J_regressor"] @ v
    parents = model["kintree_table"][0]
    rot, loc = [None] * 24, [None] * 24
    for k in range(24):
        r = rodrigues(thetas[k])
        p = parents[k]
        if k == 0 or p < 0 or p > 23:
            rot[k], loc[k] = r, j[k]
        else:
            rot[k] = rot[p] @ r
            loc[k] = loc[p] + rot[p] @ (j[k] - j[p])
    out = np.zeros_like(v)
    for k in range(24):
        out += model["weights"][:, k : k + 1] * ((v - j[k]) @ rot[k].T + loc[k])
    return out, np.array(loc)


def draw(ax, v, f, joints, parents, view):
    """Flat-shaded painter's-algorithm render; view 'front' looks along -Z, 'side' along -X."""
    if view == "front":
        xy, depth, light = v[:, [0, 1]], v[:, 2], np.array([0.3, 0.4, 1.0])
        jxy = joints[:, [0, 1]]
    else:
        xy, depth, light = v[:, [2, 1]] * np.array([-1, 1]), v[:, 0], np.array([1.0, 0.4, 0.3])
        jxy = joints[:, [2, 1]] * np.array([-1, 1])
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-12
    view_dir = np.array([0, 0, 1.0]) if view == "front" else np.array([1.0, 0, 0])
    visible = n @ view_dir > 0
    order = np.argsort(depth[f].mean(1)[visible])
    tris = xy[f[visible][order]]
    shade = np.clip(n[visible][order] @ (light / np.linalg.norm(light)), 0.1, 1.0)
    colours = np.stack([0.85 * shade, 0.75 * shade, 0.65 * shade], axis=1)
    ax.add_collection(PolyCollection(tris, facecolors=colours, edgecolors="none"))
    for k, p in enumerate(parents):
        if 0 <= p < 24:
            ax.plot(*jxy[[p, k]].T, color="tab:blue", lw=1)
    ax.scatter(*jxy.T, s=6, color="tab:red", zorder=3)
    ax.set_aspect("equal")
    ax.set_xlim(-1.0, 1.0)
    ax.set_ylim(-1.35, 0.75)
    ax.axis("off")


def write_obj(path, v, f, vt=None, ft=None):
    with open(path, "w") as out:
        for p in v:
            out.write(f"v {p[0]:.5f} {p[1]:.5f} {p[2]:.5f}\n")
        if vt is not None:
            for t in vt:
                out.write(f"vt {t[0]:.5f} {t[1]:.5f}\n")
        for i, tri in enumerate(f + 1):
            if ft is None:
                out.write(f"f {tri[0]} {tri[1]} {tri[2]}\n")
            else:
                t = ft[i] + 1
                out.write(f"f {tri[0]}/{t[0]} {tri[1]}/{t[1]} {tri[2]}/{t[2]}\n")


def named_poses():
    deg = np.pi / 180
    arms_down = np.zeros((24, 3))
    arms_down[16] = [0, 0, -75 * deg]
    arms_down[17] = [0, 0, 75 * deg]
    raised = np.zeros((24, 3))
    raised[16] = [0, 0, 80 * deg]
    raised[17] = [0, 0, -80 * deg]
    squat = np.zeros((24, 3))
    squat[1] = squat[2] = [-90 * deg, 0, 0]
    squat[4] = squat[5] = [110 * deg, 0, 0]
    squat[18] = [0, -90 * deg, 0]
    squat[19] = [0, 90 * deg, 0]
    return {"arms down": arms_down, "arms raised": raised, "squat, elbows bent": squat}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model")
    ap.add_argument("--out", default="/tmp/default_body_preview")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    m = dict(np.load(args.model))
    stem = os.path.splitext(os.path.basename(args.model))[0]
    f, parents = m["f"], m["kintree_table"][0].astype(np.int64)
    names = list(m["shape_names"])
    b = m["shapedirs"].shape[2]

    shapes = [("mean", np.zeros(b))]
    for j in (0, 1, 2, 5):
        for s in (-3.0, 3.0):
            beta = np.zeros(b)
            beta[j] = s
            shapes.append((f"{names[j].split(':')[0]} = {s:+.0f}", beta))
    fig, axes = plt.subplots(2, len(shapes), figsize=(2.2 * len(shapes), 6))
    for c, (title, beta) in enumerate(shapes):
        v, joints = pose(m, beta, np.zeros((24, 3)))
        h = v[:, 1].max() - v[:, 1].min()
        for r, view in enumerate(("front", "side")):
            draw(axes[r, c], v, f, joints, parents, view)
        axes[0, c].set_title(f"{title}\n{h:.2f} m", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, f"{stem}_shapes.png"), dpi=110)

    poses = named_poses()
    fig, axes = plt.subplots(2, len(poses), figsize=(3 * len(poses), 6))
    for c, (title, theta) in enumerate(poses.items()):
        v, joints = pose(m, np.zeros(b), theta)
        for r, view in enumerate(("front", "side")):
            draw(axes[r, c], v, f, joints, parents, view)
        axes[0, c].set_title(title, fontsize=9)
        write_obj(os.path.join(args.out, f"{stem}_{title.split(',')[0].replace(' ', '_')}.obj"), v, f)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, f"{stem}_poses.png"), dpi=110)

    fig, ax = plt.subplots(figsize=(8, 8))
    uv = m["vt"][m["ft"]]
    ax.add_collection(PolyCollection(uv, facecolors="none", edgecolors="k", linewidths=0.1))
    ax.set_aspect("equal")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    fig.savefig(os.path.join(args.out, f"{stem}_uv.png"), dpi=110)

    write_obj(os.path.join(args.out, f"{stem}_mean.obj"), m["v_template"], f, m["vt"], m["ft"])
    print(f"wrote {args.out}/{stem}_shapes.png, _poses.png, _uv.png and OBJ files")


if __name__ == "__main__":
    main()
