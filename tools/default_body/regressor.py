"""A sparse, non-negative joint regressor over surface vertices.

The rig's joints are means of helper cubes that are not part of the rendered surface, so each
joint is re-expressed as a convex combination of body vertices around it: non-negative weights
that sum to one (as SMPL's regressor), fitted by least squares so that they reproduce the joint on
the mean body and on sampled body shapes, with a small ridge that spreads the weights. The
solution of such a fit is naturally sparse.

Convexity keeps the joints inside the body under any template edit, at a price: the MakeHuman
targets do not always move the joint cubes with the surface. 35 of the muscle/weight targets
move the surface by up to 9 cm but leave the cubes where they are, and the min-height targets
lower the surface around the knee by 12 cm but the knee cube by 6 cm. No surface regressor
follows the cube means exactly on bodies that use them; a convex one stays with the surface.
"""

import numpy as np


def convex_least_squares(q, tol=1e-13):
    """min r^T q r subject to r >= 0 and sum(r) = 1, by a primal active-set method.

    KKT: q r = nu 1 + mu with mu >= 0 and mu_i r_i = 0, where nu = r^T q r. On the free set F,
    r_F is proportional to q_FF^-1 1; a vertex joins F when (q r)_i < nu, and leaves it when a
    step towards the free optimum would make its weight negative.
    """
    n = len(q)
    scale = np.trace(q) / n
    free = np.zeros(n, dtype=bool)
    start = int(np.argmin(np.diag(q)))
    free[start] = True
    r = np.zeros(n)
    r[start] = 1.0
    for _ in range(4 * n):
        g = q @ r
        nu = r @ g
        violation = np.where(free, np.inf, g - nu)
        i = int(np.argmin(violation))
        if violation[i] >= -tol * scale:
            break
        free[i] = True
        while True:
            idx = np.nonzero(free)[0]
            x = np.linalg.solve(q[np.ix_(idx, idx)], np.ones(len(idx)))
            s = np.zeros(n)
            s[idx] = x / x.sum()
            if np.all(s[idx] > 0):
                r = s
                break
            bad = idx[s[idx] <= 0]
            alpha = np.min(r[bad] / (r[bad] - s[bad]))
            r = r + alpha * (s - r)
            free &= r > 1e-15
            r[~free] = 0.0
            r /= r.sum()
    return r


def fit_joint(positions, joint, ridge):
    """Convex weights over K candidate vertices for one joint.

    positions: (N, K, 3) candidate vertices on N bodies (or body offsets); joint: (N, 3) the
    joint on each (or its offset). Since the weights sum to one, the residual r.x - J equals
    sum_i r_i (x_i - J): the fit is a quadratic form in r over relative positions. The ridge
    (relative to their mean square) spreads the weights over more vertices.
    """
    rel = positions - joint[:, None, :]
    q = np.einsum("nkc,nlc->kl", rel, rel)
    q += ridge * np.trace(q) / len(q) * np.eye(len(q))
    return convex_least_squares(q)


def surrounding_candidates(points, centre, nearest, per_direction):
    """Vertex candidates that surround `centre`: its `nearest` closest vertices, plus the
    `per_direction` closest within 35 degrees of each of 26 directions, so that an interior
    joint (the pelvis, the spine) lies inside their convex hull."""
    rel = points - centre
    dist = np.linalg.norm(rel, axis=1)
    chosen = set(np.argsort(dist)[:nearest].tolist())
    unit = rel / np.maximum(dist, 1e-12)[:, None]
    grid = np.array([(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) != (0, 0, 0)], dtype=float)
    grid /= np.linalg.norm(grid, axis=1, keepdims=True)
    for d in grid:
        inside = np.nonzero(unit @ d > np.cos(np.radians(35)))[0]
        chosen.update(inside[np.argsort(dist[inside])[:per_direction]].tolist())
    return np.array(sorted(chosen))


def fit_regressor(family, joint_family, nearest=60, per_direction=8, ridge=1e-3):
    """(J, V) regressor. `family` gives the surface of every body the fit must hold for, and
    `joint_family` the rig's joints on the same bodies (see `ShapeFamily`)."""
    num_joints = joint_family.mean.shape[0]
    out = np.zeros((num_joints, family.mean.shape[0]))
    all_joints = joint_family.bodies(np.arange(num_joints))
    for j in range(num_joints):
        candidates = surrounding_candidates(family.mean, joint_family.mean[j], nearest, per_direction)
        out[j, candidates] = fit_joint(family.bodies(candidates), all_joints[:, j, :], ridge)
    return out


class ShapeFamily:
    """Bodies `mean + coefs[n] @ deltas` (the mean itself first), evaluated on a vertex subset."""

    def __init__(self, mean, deltas, coefs):
        self.mean, self.deltas, self.coefs = mean, deltas, coefs

    def bodies(self, idx):
        sub = self.mean[idx][None] + np.einsum("nk,kvc->nvc", self.coefs, self.deltas[:, idx])
        return np.concatenate([self.mean[idx][None], sub], axis=0)
