"""Where MediaPipe's 468 face-mesh landmarks sit on the default body's head (issue 22): its
canonical face mesh registered to the head once.

`canonical_face_model.obj` (beside this script; Apache-2.0, from MediaPipe's repository, see
`NOTICE.canonical_face_model`) is the face mesh's 468 points on a neutral face, in centimetres,
Y up, facing +Z, the subject's left at +X (the default body's axes), in landmark order. It is
scaled to metres, moved onto the head by the similarity that best aligns five points named on
both (the nose tip, both upper lids' centres, both mouth corners; the default body's vertices as
`crates/mannequin-fit/src/blazepose.rs` names them), and each point then goes to the nearest
point of the head's surface (the triangles of the face model's head vertices).

Writes `crates/mannequin-fit/data/face_landmarks.npz`: `triangles` [468] (indices into the
default body's `f`), `barycentrics` [468, 3], `canonical_distance_mm` [468] (how far each
aligned canonical point is from its surface point), `similarity` [4, 4] (the canonical
points in metres -> the default body), and prints the distances.

Run: python3 tools/default_body/face_landmarks.py
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from convert import write_npz  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
# MediaPipe landmark -> default body vertex (blazepose.rs: nose, left_eye, right_eye,
# mouth_left, mouth_right).
ANCHORS = [(4, 5054), (386, 6786), (159, 2), (291, 7301), (61, 560)]


def read_canonical():
    lines = open(os.path.join(HERE, "canonical_face_model.obj")).read().splitlines()
    v = np.array([[float(x) for x in ln.split()[1:4]] for ln in lines if ln.startswith("v ")])
    if v.shape != (468, 3):
        raise SystemExit(f"canonical_face_model.obj: {v.shape[0]} vertices, expected 468")
    return v / 100.0


def similarity(a, b):
    """s, R, t minimising |s R a + t - b|² (Umeyama)."""
    ma, mb = a.mean(0), b.mean(0)
    u, d, vt = np.linalg.svd((b - mb).T @ (a - ma))
    e = np.diag([1, 1, np.sign(np.linalg.det(u @ vt))])
    r = u @ e @ vt
    s = np.trace(np.diag(d) @ e) / ((a - ma) ** 2).sum()
    return s, r, mb - s * r @ ma


def closest_on_triangles(p, a, b, c):
    """For point p, the nearest point on each triangle (a, b, c rows) as barycentrics (Ericson)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
    bp = p - b
    d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
    cp = p - c
    d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        den = va + vb + vc
        v, w = vb / den, vc / den
        bary = np.stack([1 - v - w, v, w], 1)
        regions = [
            ((d1 <= 0) & (d2 <= 0), lambda: np.stack([np.ones_like(d1), 0 * d1, 0 * d1], 1)),
            ((d3 >= 0) & (d4 <= d3), lambda: np.stack([0 * d1, np.ones_like(d1), 0 * d1], 1)),
            ((d6 >= 0) & (d5 <= d6), lambda: np.stack([0 * d1, 0 * d1, np.ones_like(d1)], 1)),
            ((vc <= 0) & (d1 >= 0) & (d3 <= 0),
             lambda: (lambda t: np.stack([1 - t, t, 0 * t], 1))(d1 / (d1 - d3))),
            ((vb <= 0) & (d2 >= 0) & (d6 <= 0),
             lambda: (lambda t: np.stack([1 - t, 0 * t, t], 1))(d2 / (d2 - d6))),
            ((va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0),
             lambda: (lambda t: np.stack([0 * t, 1 - t, t], 1))((d4 - d3) / ((d4 - d3) + (d5 - d6)))),
        ]
        for mask, value in reversed(regions):
            bary = np.where(mask[:, None], value(), bary)
    return bary


def main():
    body = np.load(os.path.join(ROOT, "crates/mannequin-body/assets/default_body.npz"))
    face = np.load(os.path.join(ROOT, "crates/mannequin-body/assets/default_face.npz"))
    verts, faces = body["v_template"].astype(np.float64), body["f"].astype(np.int64)
    head = np.zeros(len(verts), bool)
    head[face["vertices"]] = True
    tris = np.flatnonzero(head[faces].all(1))
    canonical = read_canonical()
    s, r, t = similarity(canonical[[i for i, _ in ANCHORS]], verts[[v for _, v in ANCHORS]])
    aligned = s * canonical @ r.T + t
    a, b, c = (verts[faces[tris, k]] for k in range(3))
    triangles, barys, dist = [], [], []
    for p in aligned:
        bc = closest_on_triangles(p, a, b, c)
        q = bc[:, :1] * a + bc[:, 1:2] * b + bc[:, 2:] * c
        d = np.linalg.norm(q - p, axis=1)
        k = int(np.argmin(d))
        triangles.append(tris[k])
        barys.append(bc[k])
        dist.append(d[k])
    dist = np.array(dist) * 1000
    anchors_mm = [float(np.linalg.norm(aligned[i] - verts[v]) * 1000) for i, v in ANCHORS]
    print(f"scale {s:.4f}; anchors off by " + ", ".join(f"{d:.1f}" for d in anchors_mm) + " mm")
    print(f"canonical point -> head surface: median {np.median(dist):.1f} mm, 90 % {np.percentile(dist, 90):.1f}, "
          f"max {dist.max():.1f} (landmark {int(dist.argmax())})")
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = s * r, t
    write_npz(os.path.join(ROOT, "crates/mannequin-fit/data/face_landmarks.npz"), {
        "triangles": np.array(triangles, np.int64),
        "barycentrics": np.array(barys, np.float32),
        "canonical_distance_mm": dist.astype(np.float32),
        "similarity": m,
    })


if __name__ == "__main__":
    main()
