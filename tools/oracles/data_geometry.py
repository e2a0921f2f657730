"""Chamfer, point-to-surface and normal-consistency oracle fixture from trimesh, libigl and SciPy.

Writes, under crates/mannequin-data/tests/fixtures/:
- geometry_gt.ply, geometry_pred.ply: two meshes exported by trimesh (binary PLY), vertices
  rounded to float32 so that both sides see the same numbers;
- geometry.npz: surface samples of each (trimesh.sample.sample_surface: points and face ids) and
  the expected metrics on exactly those samples:
  chamfer_cm = 100 * (mean_p dist(p, gt surface) + mean_q dist(q, pred surface)) / 2
                                                   (igl.point_mesh_squared_distance both ways)
  p2s_cm     = 100 * mean_p dist(p, gt surface)    (the first half of the Chamfer sum)
  nc         = (mean_p |n_p . n_nn(p)| + mean_q |n_q . n_nn(q)|) / 2      (trimesh face normals)
  plus the per-point P2S distances and nearest GT faces for diagnosis.
This is the Chamfer of PIFu, ICON and ECON (point-to-surface in both directions), which the
clothed-human papers report; unlike point-to-point, it does not grow with the sample spacing.

Run: $HOME/.cache/mannequin-oracles/bin/python tools/oracles/data_geometry.py
"""

from pathlib import Path

import igl
import numpy as np
import trimesh
from scipy.spatial import cKDTree

FIX = Path(__file__).resolve().parents[2] / "crates/mannequin-data/tests/fixtures"


def f32(mesh):
    return trimesh.Trimesh(mesh.vertices.astype(np.float32).astype(np.float64), mesh.faces, process=False)


def main():
    rng = np.random.default_rng(42)
    gt = trimesh.creation.icosphere(subdivisions=3, radius=0.3)
    v = gt.vertices.copy()
    v[:, 1] *= 1.6  # an ellipsoid, like a torso
    v += 0.02 * np.sin(12 * v[:, [1]]) * gt.vertex_normals  # ripples, like folds
    gt = f32(trimesh.Trimesh(v, gt.faces, process=False))
    # A different topology for the prediction: a capsule-ish UV sphere, noisy and shifted.
    pred = trimesh.creation.uv_sphere(radius=0.31, count=[24, 32])
    pv = pred.vertices.copy()
    pv[:, 1] *= 1.55
    pv += 0.004 * rng.standard_normal(pv.shape) + np.array([0.01, -0.005, 0.0])
    pred = f32(trimesh.Trimesh(pv, pred.faces, process=False))

    gt.export(FIX / "geometry_gt.ply", encoding="binary")
    pred.export(FIX / "geometry_pred.ply", encoding="binary")

    n = 2000
    ps, pf = trimesh.sample.sample_surface(pred, n, seed=1)
    gs, gf = trimesh.sample.sample_surface(gt, n, seed=2)
    pn, gn = pred.face_normals[pf], gt.face_normals[gf]

    _, i_pg = cKDTree(gs).query(ps)
    _, i_gp = cKDTree(ps).query(gs)
    nc = 0.5 * (np.abs((pn * gn[i_pg]).sum(1)).mean() + np.abs((gn * pn[i_gp]).sum(1)).mean())
    sq, face, _ = igl.point_mesh_squared_distance(ps, gt.vertices, gt.faces.astype(np.int64))
    sq_back, _, _ = igl.point_mesh_squared_distance(gs, pred.vertices, pred.faces.astype(np.int64))
    p2s = 100 * np.sqrt(sq).mean()
    chamfer = 0.5 * (p2s + 100 * np.sqrt(sq_back).mean())

    np.savez_compressed(
        FIX / "geometry.npz",
        pred_points=ps,
        pred_faces=pf.astype(np.int64),
        gt_points=gs,
        gt_faces=gf.astype(np.int64),
        chamfer_cm=np.array(chamfer),
        p2s_cm=np.array(p2s),
        normal_consistency=np.array(nc),
        p2s_point_m=np.sqrt(sq),
        p2s_face=face.astype(np.int64),
    )
    print(chamfer, p2s, nc)


if __name__ == "__main__":
    main()
