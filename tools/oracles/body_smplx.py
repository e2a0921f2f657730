"""Golden fixtures for the body model, made with the `smplx` package (an implementation nobody
here wrote).

The model files are random but full size (6,890 vertices, or 10,475 for SMPL-X, on a grid topology) for SMPL (24
joints), SMPL-H (52) and SMPL-X (55, with 400 shape+expression components). Their arrays come from
a counter-based generator (splitmix64) that the Rust test reimplements, so the fixture stores only
inputs and outputs, not 20 MB of random bases. The generator is test scaffolding; the quantities
under test (blend shapes, pose correctives, joints, LBS) come from smplx.

Run: $ORACLE_VENV/bin/python tools/oracles/body_smplx.py crates/mannequin-body/tests/fixtures
"""
import os
import pickle
import sys
import tempfile

import numpy as np
import torch
import smplx

M = np.uint64(0xFFFFFFFFFFFFFFFF)
GRIDS = {"smpl": (65, 106), "smplh": (65, 106), "smplx": (25, 419)}  # 6,890 and 10,475 vertices
SMPL_PARENTS = [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21]


def splitmix64(x):
    with np.errstate(over="ignore"):
        z = x + np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        return z ^ (z >> np.uint64(31))


def uniform(stream, n):
    """n values in [0, 1): element i is splitmix64(stream << 32 | i) >> 11, times 2^-53."""
    idx = (np.uint64(stream) << np.uint64(32)) | np.arange(n, dtype=np.uint64)
    return (splitmix64(idx) >> np.uint64(11)).astype(np.float64) * 2.0 ** -53


def grid_mesh(V_RINGS, V_SEGMENTS):
    rings = (np.arange(V_RINGS) + 0.5) / V_RINGS * np.pi
    segs = np.arange(V_SEGMENTS) / V_SEGMENTS * 2 * np.pi
    phi, lam = np.meshgrid(rings, segs, indexing="ij")
    v = np.stack([0.3 * np.sin(phi) * np.cos(lam), 0.9 * np.cos(phi), 0.2 * np.sin(phi) * np.sin(lam)], -1)
    faces = []
    for r in range(V_RINGS - 1):
        for s in range(V_SEGMENTS):
            a, b = r * V_SEGMENTS + s, r * V_SEGMENTS + (s + 1) % V_SEGMENTS
            c, d = a + V_SEGMENTS, b + V_SEGMENTS
            faces += [[a, c, b], [b, c, d]]
    return v.reshape(-1, 3).astype(np.float32), np.array(faces, dtype=np.int64)


def random_model(joints, components, grid):
    v_template, faces = grid_mesh(*grid)
    nv = len(v_template)
    shapedirs = (0.02 * (uniform(1, nv * 3 * components) - 0.5)).astype(np.float32).reshape(nv, 3, components)
    posedirs = (0.02 * (uniform(2, nv * 3 * 9 * (joints - 1)) - 0.5)).astype(np.float32).reshape(nv, 3, -1)
    reg = np.zeros((joints, nv), np.float64)
    cols = np.floor(uniform(3, joints * 8) * nv).astype(np.int64)
    vals = uniform(4, joints * 8) + 0.1
    for i in range(joints * 8):
        reg[i // 8, cols[i]] += vals[i]
    reg = (reg / reg.sum(1, keepdims=True)).astype(np.float32)
    w = np.zeros((nv, joints), np.float64)
    js = np.floor(uniform(5, nv * 4) * joints).astype(np.int64)
    ws = uniform(6, nv * 4) + 0.1
    for i in range(nv * 4):
        w[i // 4, js[i]] += ws[i]
    w = (w / w.sum(1, keepdims=True)).astype(np.float32)
    if joints == 24:
        parents = np.array(SMPL_PARENTS, np.int64)
    else:
        parents = np.concatenate([[-1], np.floor(uniform(7, joints)[1:] * np.arange(1, joints)).astype(np.int64)])
    kintree = np.stack([parents, np.arange(joints)]).astype(np.int64)
    kintree[0, 0] = 4294967295  # as in the released SMPL files
    return dict(v_template=v_template, f=faces, shapedirs=shapedirs, posedirs=posedirs,
                J_regressor=reg, weights=w, kintree_table=kintree)


def run_family(name, joints, components, frames, out):
    model = random_model(joints, components, GRIDS[name])
    rng = np.random.default_rng(joints)
    nb = 10
    betas = rng.uniform(-2, 2, (frames, nb))
    pose = rng.uniform(-0.6, 0.6, (frames, joints * 3))
    pose[0] = 0.0  # the rest pose
    transl = rng.uniform(-1, 1, (frames, 3))
    expression = rng.uniform(-2, 2, (frames, 10)) if name == "smplx" else np.zeros((frames, 0))
    with tempfile.TemporaryDirectory() as d:
        t = lambda a: torch.tensor(a, dtype=torch.float64)
        common = dict(num_betas=nb, batch_size=frames, dtype=torch.float64)
        if name == "smpl":
            path = os.path.join(d, "SMPL_NEUTRAL.pkl")
            pickle.dump(model, open(path, "wb"))
            m = smplx.SMPL(model_path=path, **common)
            o = m(betas=t(betas), global_orient=t(pose[:, :3]), body_pose=t(pose[:, 3:]), transl=t(transl))
        elif name == "smplh":
            h = dict(model, hands_componentsl=np.eye(45, dtype=np.float32), hands_componentsr=np.eye(45, dtype=np.float32),
                     hands_meanl=np.zeros(45, np.float32), hands_meanr=np.zeros(45, np.float32))
            path = os.path.join(d, "SMPLH_NEUTRAL.pkl")
            pickle.dump(h, open(path, "wb"))
            m = smplx.SMPLH(model_path=path, use_pca=False, flat_hand_mean=True, **common)
            o = m(betas=t(betas), global_orient=t(pose[:, :3]), body_pose=t(pose[:, 3:66]),
                  left_hand_pose=t(pose[:, 66:111]), right_hand_pose=t(pose[:, 111:156]), transl=t(transl))
        else:
            x = dict(model, hands_componentsl=np.eye(45, dtype=np.float32), hands_componentsr=np.eye(45, dtype=np.float32),
                     hands_meanl=np.zeros(45, np.float32), hands_meanr=np.zeros(45, np.float32),
                     lmk_faces_idx=np.arange(51, dtype=np.int64), lmk_bary_coords=np.full((51, 3), 1 / 3, np.float32))
            path = os.path.join(d, "SMPLX_NEUTRAL.npz")
            np.savez(path, **x)
            m = smplx.SMPLX(model_path=path, use_pca=False, flat_hand_mean=True, num_expression_coeffs=10, **common)
            # smplx's SMPL-X order: global, body (21), jaw, left eye, right eye, left hand, right hand.
            o = m(betas=t(betas), expression=t(expression), global_orient=t(pose[:, :3]), body_pose=t(pose[:, 3:66]),
                  jaw_pose=t(pose[:, 66:69]), leye_pose=t(pose[:, 69:72]), reye_pose=t(pose[:, 72:75]),
                  left_hand_pose=t(pose[:, 75:120]), right_hand_pose=t(pose[:, 120:165]), transl=t(transl))
    verts = o.vertices.detach().numpy()
    subset = np.arange(0, verts.shape[1], 3)
    np.savez_compressed(os.path.join(out, f"smplx_{name}.npz"), betas=betas, expression=expression, pose=pose,
                        transl=transl, vertex_ids=subset, vertices=verts[:, subset], joints=o.joints.detach().numpy()[:, :joints],
                        joint_count=np.array(joints), components=np.array(components))
    print(name, "vertices", verts.shape, "range", verts.min(), verts.max())


if __name__ == "__main__":
    out = sys.argv[1]
    run_family("smpl", 24, 10, 4, out)
    run_family("smplh", 52, 16, 3, out)
    run_family("smplx", 55, 400, 3, out)
