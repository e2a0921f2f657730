"""Checks printed for each level of the converted body; a failed hard check stops the converter."""

from dataclasses import dataclass

import numpy as np

import skeleton
from decimate import euler_characteristic


@dataclass
class RigTruth:
    """The rig's own joints (cube means, T-posed): on the mean body, per macro target offset,
    and per shape component."""

    mean: np.ndarray  # (24, 3)
    per_target: np.ndarray  # (K, 24, 3)
    populations: dict  # name -> (N, K) centred target coefficients of sampled bodies
    per_component: np.ndarray  # (24, 3, B)


def require(ok, what):
    print(f"    [{'ok' if ok else 'FAILED'}] {what}")
    if not ok:
        raise SystemExit(f"check failed: {what}")


def signed_volume(v, f):
    return float(np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6.0)


def consistently_oriented(f):
    """Every directed edge appears once: neighbouring triangles agree on orientation."""
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    return len(np.unique(directed, axis=0)) == len(directed)


def height(v):
    return float(v[:, 1].max() - v[:, 1].min())


def report(label, level, surface_deltas, truth, euler_full):
    v, f, s = level["v_template"], level["faces"], level["shapedirs"]
    w, reg = level["weights"], level["j_regressor"]
    print(f"== {label}: {len(v)} vertices, {len(f)} triangles, {len(level['uvs'])} UVs, {s.shape[2]} shape components")
    euler = euler_characteristic(f)
    require(euler == euler_full, f"Euler characteristic {euler} equals the full mesh's {euler_full}")
    require(len(np.unique(f)) == len(v), "every vertex is used by a face")
    vol = signed_volume(v, f)
    require(vol > 0, f"signed volume {vol * 1000:.1f} litres > 0 (normals point outwards)")
    require(consistently_oriented(f), "neighbouring triangles are consistently oriented")
    require(np.all(level["uv_faces"] < len(level["uvs"])), "UV corners index the UV table")

    sums = w.sum(1)
    print(f"    skinning weight row sums in [{sums.min():.7f}, {sums.max():.7f}], min weight {w.min():.3g}")
    require(np.allclose(sums, 1, atol=1e-6) and w.min() >= 0, "skinning weights are non-negative and sum to 1")
    rsum = reg.sum(1)
    nnz = (reg > 0).sum(1)
    print(f"    J_regressor: row sums in [{rsum.min():.7f}, {rsum.max():.7f}], {nnz.min()}-{nnz.max()} vertices per joint")
    require(np.allclose(rsum, 1, atol=1e-6) and reg.min() >= 0, "J_regressor rows are convex combinations")

    joints = reg @ v
    print(f"    mean body height {height(v):.3f} m (y from {v[:, 1].min():.3f} to {v[:, 1].max():.3f})")
    require(1.60 <= height(v) <= 1.80, "mean body height within 1.60-1.80 m")
    print("    joints of the mean body (regressed; error vs the rig's cube means):")
    for j, name in enumerate(skeleton.JOINT_NAMES):
        err = 1000 * np.linalg.norm(joints[j] - truth.mean[j])
        print(f"      {j:2d} {name:15s} ({joints[j, 0]:+.3f}, {joints[j, 1]:+.3f}, {joints[j, 2]:+.3f})  {err:5.2f} mm")
    check_skeleton(joints)

    # Fit error over sampled bodies and over beta = +-3 on every component.
    mean_err = np.linalg.norm(joints - truth.mean, axis=1).max()
    print(f"    regressor error on the mean body: max {1000 * mean_err:.2f} mm")
    reg_targets = np.einsum("jv,kvc->kjc", reg, surface_deltas) - truth.per_target
    worst = {}
    for name, coefs in truth.populations.items():
        err = np.linalg.norm(joints - truth.mean + np.einsum("nk,kjc->njc", coefs, reg_targets), axis=2)
        worst[name] = err
        print(f"    regressor error over {len(coefs)} {name}: mean {1000 * err.mean():.2f} mm, "
              f"99th percentile {1000 * np.percentile(err, 99):.2f} mm, max {1000 * err.max():.2f} mm "
              f"(at {skeleton.JOINT_NAMES[int(np.argmax(err.max(0)))]})")  # fmt: skip
    comp = (reg @ s.reshape(len(v), -1)).reshape(24, 3, -1) - truth.per_component
    beta_err = 3 * np.linalg.norm(comp, axis=1)
    print(f"    regressor error at beta = +-3 on one component: max {1000 * beta_err.max():.2f} mm "
          f"(pc{int(np.argmax(beta_err.max(0)))}, at {skeleton.JOINT_NAMES[int(np.argmax(beta_err.max(1)))]})")  # fmt: skip
    require(mean_err < 0.002, "regressor reproduces the mean body's joints within 2 mm")
    all_err = worst["sampled bodies"]
    require(all_err.mean() < 0.01 and beta_err.max() < 0.025, "mean error < 10 mm over sampled bodies, < 25 mm at beta = +-3")

    heights = []
    for j in range(s.shape[2]):
        for b in (-3.0, 3.0):
            heights.append(height(v + b * s[:, :, j]))
    print(f"    heights at beta = +-3 on one component: {min(heights):.3f} to {max(heights):.3f} m")
    print("      pc0..: " + ", ".join(f"{heights[2 * j]:.2f}/{heights[2 * j + 1]:.2f}" for j in range(s.shape[2])))
    require(1.35 <= min(heights) and max(heights) <= 2.05, "beta = +-3 bodies are 1.35-2.05 m tall")


def check_skeleton(j):
    y, x, z = j[:, 1], j[:, 0], j[:, 2]
    require(x[16] > 0 and x[17] < 0, "left shoulder at +x, right at -x")
    require(0.6 <= x[20] <= 0.85 and -0.85 <= x[21] <= -0.6, f"wrists at |x| {x[20]:.3f}, {-x[21]:.3f}")
    require(abs(y[20] - y[16]) < 0.05 and abs(y[21] - y[17]) < 0.05, "wrists at shoulder height (5 cm)")
    for a, b in ((16, 18), (18, 20), (20, 22), (17, 19), (19, 21), (21, 23)):
        d = (j[b] - j[a]) / np.linalg.norm(j[b] - j[a])
        require(abs(d[0]) > 0.99, f"{skeleton.JOINT_NAMES[a]}->{skeleton.JOINT_NAMES[b]} along x ({d.round(3)})")
    require(y[15] > y[12] > y[9] > y[6] > y[3] > y[0], "head above neck above spine3/2/1 above pelvis")
    require(y[4] < y[1] and y[5] < y[2], "knees below hips")
    require(y[7] < y[4] and y[8] < y[5], "ankles below knees")
    require(z[10] > z[7] + 0.05 and z[11] > z[8] + 0.05, "balls of the feet in front of the ankles (+z)")
