"""Golden fixture for the mesh operators, made with libigl (an implementation nobody here wrote).

Three small meshes exercise different cases:
- `ico`: a twice-subdivided icosphere with radially jittered vertices (closed, nearly regular);
- `hull`: the convex hull of random points on a sphere, radially jittered (closed, irregular, with
  obtuse triangles, so the Voronoi mass matrix takes its mixed-area branch);
- `grid`: a jittered grid with random diagonals (open: boundary edges and boundary vertices).

Vertices are rounded to float32 before anything is computed, because Mannequin stores positions
as f32; the operators are then evaluated in float64 by libigl.

For each mesh `<m>` the fixture holds `<m>_v` (V×3), `<m>_f` (F×3), and:
- `<m>_cot_{i,j,x}`: igl.cotmatrix as COO triplets;
- `<m>_mass_bary`, `<m>_mass_voronoi`: the diagonals of igl.massmatrix;
- `<m>_grad_{i,j,x}`: igl.grad as COO triplets (libigl row order: row d*F + f);
- `<m>_dblarea`: igl.doublearea;
- `<m>_vnormals`: igl.per_vertex_normals with area weighting; `<m>_fnormals`: igl.per_face_normals;
- `<m>_edges`: igl.edges; `<m>_tt`: igl.triangle_triangle_adjacency (face across edge
  (f[k], f[k+1]), -1 on the boundary).

Run: $ORACLE_VENV/bin/python tools/oracles/mesh_igl.py crates/mannequin-mesh/tests/fixtures
"""
import os
import sys

import igl
import numpy as np
import scipy.sparse
import scipy.spatial
import trimesh


def jitter_radially(v, rng, amount):
    return v * (1.0 + amount * rng.uniform(-1.0, 1.0, size=(len(v), 1)))


def outward(v, f):
    """Orients every face of a star-shaped closed mesh away from the origin."""
    f = f.copy()
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    inward = np.einsum("ij,ij->i", n, v[f].mean(axis=1)) < 0
    f[inward] = f[inward][:, ::-1]
    return f


def ico(rng):
    m = trimesh.creation.icosphere(subdivisions=2)
    return jitter_radially(np.asarray(m.vertices), rng, 0.15), np.asarray(m.faces)


def hull(rng):
    p = rng.normal(size=(100, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    f = scipy.spatial.ConvexHull(p).simplices
    v = jitter_radially(p, rng, 0.25)
    return v, outward(p, f)


def grid(rng):
    n = 8
    x, y = np.meshgrid(np.arange(n, dtype=np.float64), np.arange(n, dtype=np.float64), indexing="ij")
    v = np.stack([x, y, np.zeros_like(x)], axis=-1).reshape(-1, 3)
    v[:, :2] += rng.uniform(-0.3, 0.3, size=(len(v), 2))
    v[:, 2] = 0.4 * rng.normal(size=len(v))
    faces = []
    for i in range(n - 1):
        for j in range(n - 1):
            a, b, c, d = i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1
            faces += [[a, b, c], [a, c, d]] if rng.uniform() < 0.5 else [[a, b, d], [b, c, d]]
    return 0.1 * v, np.array(faces)


def coo(prefix, m, out):
    m = scipy.sparse.coo_matrix(m)
    out[prefix + "_i"] = m.row.astype(np.int64)
    out[prefix + "_j"] = m.col.astype(np.int64)
    out[prefix + "_x"] = m.data.astype(np.float64)


def main(folder):
    rng = np.random.default_rng(20240602)
    out = {}
    for name, make in [("ico", ico), ("hull", hull), ("grid", grid)]:
        v, f = make(rng)
        v = v.astype(np.float32).astype(np.float64)
        f = f.astype(np.int64)
        out[name + "_v"] = v
        out[name + "_f"] = f
        coo(name + "_cot", igl.cotmatrix(v, f), out)
        out[name + "_mass_bary"] = igl.massmatrix(v, f, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
        out[name + "_mass_voronoi"] = igl.massmatrix(v, f, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
        coo(name + "_grad", igl.grad(v, f), out)
        out[name + "_dblarea"] = igl.doublearea(v, f)
        out[name + "_vnormals"] = igl.per_vertex_normals(v, f, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
        out[name + "_fnormals"] = igl.per_face_normals(v, f, np.zeros(3))
        out[name + "_edges"] = igl.edges(f).astype(np.int64)
        out[name + "_tt"] = igl.triangle_triangle_adjacency(f)[0].astype(np.int64)
        cos = []
        for t in f:
            p = v[t]
            for k in range(3):
                a, b = p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]
                cos.append(a @ b / np.linalg.norm(a) / np.linalg.norm(b))
        print(f"{name}: {len(v)} vertices, {len(f)} faces, {np.sum(np.array(cos) < 0)} obtuse corners")
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, "mesh_igl.npz")
    np.savez_compressed(path, **out)
    print(f"wrote {path} ({os.path.getsize(path)} bytes)")


if __name__ == "__main__":
    main(sys.argv[1])
