//! CubeCL kernels of linear blend skinning with pose correctives (thesis §SMPL, Eq. 1): the
//! kinematic chain runs in one unit (24 joints in sequence are nothing to a GPU, hundreds of tiny
//! launches are), the vertices one unit each. The chain's record is `[J, CHAIN]` per joint: the
//! local rotation R (9, row-major), the world rotation G (9), the world translation Gt (3) and
//! the skinning transform's translation At = Gt − G·J_rest (3); the skinning transform's
//! rotation is G.

// Kernels index their buffers: iterator forms do not exist in CubeCL.
#![allow(clippy::needless_range_loop)]

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// Floats per joint in the chain's record.
pub(crate) const CHAIN: usize = 24;
const R: usize = 0;
const G: usize = 9;
const GT: usize = 18;
const AT: usize = 21;

/// Keeps θ = ‖r‖ differentiable at the zero rotation, as `rodrigues_tensor` does.
const ANGLE_EPS2: f32 = 1e-16;

/// `parents[k]` as an index; the root has −1 and is never asked.
#[cube]
fn parent_of(parents: &[i32], k: usize) -> usize {
    usize::cast_from(parents[k])
}

/// One unit: R_k = Rodrigues(r_k), G_k = G_p·R_k, Gt_k = G_p·(J_k − J_p) + Gt_p,
/// At_k = Gt_k − G_k·J_k.
#[cube(launch)]
pub(crate) fn chain_forward(pose: &[f32], joints: &[f32], parents: &[i32], chain: &mut [f32], count: u32) {
    if ABSOLUTE_POS > 0 {
        terminate!();
    }
    for k in 0..count as usize {
        let c = k * CHAIN;
        let (rx, ry, rz) = (pose[3 * k], pose[3 * k + 1], pose[3 * k + 2]);
        let theta = f32::sqrt(rx * rx + ry * ry + rz * rz + ANGLE_EPS2);
        let (kx, ky, kz) = (rx / theta, ry / theta, rz / theta);
        let (co, si) = (f32::cos(theta), f32::sin(theta));
        let one_c = 1.0 - co;
        chain[c + R] = co + one_c * kx * kx;
        chain[c + R + 1] = one_c * kx * ky - si * kz;
        chain[c + R + 2] = one_c * kx * kz + si * ky;
        chain[c + R + 3] = one_c * ky * kx + si * kz;
        chain[c + R + 4] = co + one_c * ky * ky;
        chain[c + R + 5] = one_c * ky * kz - si * kx;
        chain[c + R + 6] = one_c * kz * kx - si * ky;
        chain[c + R + 7] = one_c * kz * ky + si * kx;
        chain[c + R + 8] = co + one_c * kz * kz;
        if parents[k] < 0 {
            for e in 0..9usize {
                chain[c + G + e] = chain[c + R + e];
            }
            for a in 0..3usize {
                chain[c + GT + a] = joints[3 * k + a];
            }
        } else {
            let p = parent_of(parents, k) * CHAIN;
            let j = 3 * parent_of(parents, k);
            for a in 0..3usize {
                let mut t = chain[p + GT + a];
                for b in 0..3usize {
                    let mut g = 0.0;
                    for m in 0..3usize {
                        g += chain[p + G + 3 * a + m] * chain[c + R + 3 * m + b];
                    }
                    chain[c + G + 3 * a + b] = g;
                    t += chain[p + G + 3 * a + b] * (joints[3 * k + b] - joints[j + b]);
                }
                chain[c + GT + a] = t;
            }
        }
        for a in 0..3usize {
            let mut t = chain[c + GT + a];
            for b in 0..3usize {
                t -= chain[c + G + 3 * a + b] * joints[3 * k + b];
            }
            chain[c + AT + a] = t;
        }
    }
}

/// The blended transform T_v = Σ_j w_vj A_j of vertex `v` (rotation 9, then translation 3):
/// `blend` is `[J + 1, V]`, joints' weights by row (the last row, of ones, is the backward's).
#[cube]
fn blended(chain: &[f32], blend: &[f32], v: usize, num_vertices: usize, count: usize, t: &mut Array<f32>) {
    for e in 0..12usize {
        t[e] = 0.0;
    }
    for j in 0..count {
        let w = blend[j * num_vertices + v];
        if w != 0.0 {
            let c = j * CHAIN;
            for e in 0..9usize {
                t[e] += w * chain[c + G + e];
            }
            for a in 0..3usize {
                t[9 + a] += w * chain[c + AT + a];
            }
        }
    }
}

/// The posed-space rest vertex v_P = v + Σ_p (R − I)_p·P[p, 3v + a] (pose correctives over joints
/// 1..J, row-major 3×3 blocks), component `a`.
#[cube]
fn corrected(
    vertices: &[f32],
    posedirs: &[f32],
    chain: &[f32],
    v: usize,
    a: usize,
    num_vertices: usize,
    features: usize,
) -> f32 {
    let stride = 3 * num_vertices;
    let mut x = vertices[3 * v + a];
    for p in 0..features {
        let k = p / 9 + 1;
        let e = p % 9;
        let mut f = chain[k * CHAIN + R + e];
        if e % 4 == 0 {
            f -= 1.0;
        }
        x += f * posedirs[p * stride + 3 * v + a];
    }
    x
}

/// One unit per vertex: posed = T_v·v_P + transl.
#[cube(launch)]
pub(crate) fn skin_vertices(
    vertices: &[f32],
    chain: &[f32],
    blend: &[f32],
    posedirs: &[f32],
    transl: &[f32],
    posed: &mut [f32],
    num_vertices: u32,
    count: u32,
    features: u32,
) {
    let v = ABSOLUTE_POS;
    let n = num_vertices as usize;
    if v >= n {
        terminate!();
    }
    let mut t = Array::<f32>::new(12usize);
    blended(chain, blend, v, n, count as usize, &mut t);
    let x = corrected(vertices, posedirs, chain, v, 0, n, features as usize);
    let y = corrected(vertices, posedirs, chain, v, 1, n, features as usize);
    let z = corrected(vertices, posedirs, chain, v, 2, n, features as usize);
    for a in 0..3usize {
        posed[3 * v + a] = t[3 * a] * x + t[3 * a + 1] * y + t[3 * a + 2] * z + t[9 + a] + transl[a];
    }
}

/// One unit per vertex, given the output's gradient g: the rest vertex's gradient T_vᵀ·g (the
/// correctives add to v, so it is also v_P's), and the vertex's share of every transform's
/// gradient before weighting, `outer[v] = [g ⊗ v_P (9, row-major), g (3)]`.
#[cube(launch)]
pub(crate) fn skin_vertices_backward(
    vertices: &[f32],
    chain: &[f32],
    blend: &[f32],
    posedirs: &[f32],
    grad: &[f32],
    d_vertices: &mut [f32],
    outer: &mut [f32],
    num_vertices: u32,
    count: u32,
    features: u32,
) {
    let v = ABSOLUTE_POS;
    let n = num_vertices as usize;
    if v >= n {
        terminate!();
    }
    let mut t = Array::<f32>::new(12usize);
    blended(chain, blend, v, n, count as usize, &mut t);
    let (gx, gy, gz) = (grad[3 * v], grad[3 * v + 1], grad[3 * v + 2]);
    for b in 0..3usize {
        d_vertices[3 * v + b] = t[b] * gx + t[3 + b] * gy + t[6 + b] * gz;
        let x = corrected(vertices, posedirs, chain, v, b, n, features as usize);
        outer[12 * v + b] = gx * x;
        outer[12 * v + 3 + b] = gy * x;
        outer[12 * v + 6 + b] = gz * x;
    }
    outer[12 * v + 9] = gx;
    outer[12 * v + 10] = gy;
    outer[12 * v + 11] = gz;
}

/// One unit: the chain's reverse pass. `d_transforms` is `[J + 1, 12]`: each transform's gradient
/// (rotation 9, translation 3), and in its last row the sum of the output's gradient over all
/// vertices (columns 9..12), which is the translation's gradient. `d_features` is the gradient of
/// the correctives' features (R − I). `work` holds `[J, 12]` world rotations' and translations'
/// gradients as they gather from the children.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn chain_backward(
    pose: &[f32],
    joints: &[f32],
    parents: &[i32],
    chain: &[f32],
    d_transforms: &[f32],
    d_features: &[f32],
    work: &mut [f32],
    d_pose: &mut [f32],
    d_joints: &mut [f32],
    d_transl: &mut [f32],
    count: u32,
    features: u32,
) {
    if ABSOLUTE_POS > 0 {
        terminate!();
    }
    let n = count as usize;
    // A_k = [G_k | Gt_k − G_k·J_k]: dG_k = dA_rot − dAt·J_kᵀ, dGt_k = dAt, dJ_k = −G_kᵀ·dAt.
    for k in 0..n {
        let (c, d) = (k * CHAIN, k * 12);
        for a in 0..3usize {
            let dat = d_transforms[d + 9 + a];
            work[d + 9 + a] = dat;
            for b in 0..3usize {
                work[d + 3 * a + b] = d_transforms[d + 3 * a + b] - dat * joints[3 * k + b];
            }
        }
        for b in 0..3usize {
            let mut s = 0.0;
            for a in 0..3usize {
                s -= chain[c + G + 3 * a + b] * d_transforms[d + 9 + a];
            }
            d_joints[3 * k + b] = s;
        }
    }
    for a in 0..3usize {
        d_transl[a] = d_transforms[n * 12 + 9 + a];
    }
    // Children before parents: parents[k] < k.
    for step in 0..n {
        let k = n - 1 - step;
        let (c, d) = (k * CHAIN, k * 12);
        // dR_k, from G_k = G_p·R_k (the root: G_0 = R_0) and from the correctives' features.
        let mut dr = Array::<f32>::new(9usize);
        for e in 0..9usize {
            dr[e] = 0.0;
            if k > 0 {
                let p = (k - 1) * 9 + e;
                if p < features as usize {
                    dr[e] = d_features[p];
                }
            }
        }
        if parents[k] < 0 {
            for e in 0..9usize {
                dr[e] += work[d + e];
            }
            for a in 0..3usize {
                d_joints[3 * k + a] += work[d + 9 + a];
            }
        } else {
            let pk = parent_of(parents, k);
            let (p, q) = (pk * CHAIN, pk * 12);
            for m in 0..3usize {
                for b in 0..3usize {
                    // dR_k[m, b] = Σ_a G_p[a, m]·dG_k[a, b]
                    let mut s = 0.0;
                    for a in 0..3usize {
                        s += chain[p + G + 3 * a + m] * work[d + 3 * a + b];
                    }
                    dr[3 * m + b] += s;
                }
            }
            for a in 0..3usize {
                for m in 0..3usize {
                    // dG_p[a, m] += Σ_b dG_k[a, b]·R_k[m, b] + dGt_k[a]·(J_k − J_p)[m]
                    let mut s = work[d + 9 + a] * (joints[3 * k + m] - joints[3 * pk + m]);
                    for b in 0..3usize {
                        s += work[d + 3 * a + b] * chain[c + R + 3 * m + b];
                    }
                    work[q + 3 * a + m] += s;
                }
            }
            for m in 0..3usize {
                // The offset's gradient G_pᵀ·dGt_k goes to J_k, and against J_p.
                let mut s = 0.0;
                for a in 0..3usize {
                    s += chain[p + G + 3 * a + m] * work[d + 9 + a];
                }
                d_joints[3 * k + m] += s;
                d_joints[3 * pk + m] -= s;
                work[q + 9 + m] += work[d + 9 + m];
            }
        }
        rodrigues_backward(pose, &dr, d_pose, k);
    }
}

/// The axis-angle gradient of R = cos θ I + sin θ [k]× + (1 − cos θ) k kᵀ with
/// θ = √(‖r‖² + ε²), k = r/θ, given R's gradient `dr` (row-major).
#[cube]
fn rodrigues_backward(pose: &[f32], dr: &Array<f32>, d_pose: &mut [f32], k: usize) {
    let (rx, ry, rz) = (pose[3 * k], pose[3 * k + 1], pose[3 * k + 2]);
    let theta = f32::sqrt(rx * rx + ry * ry + rz * rz + ANGLE_EPS2);
    let (kx, ky, kz) = (rx / theta, ry / theta, rz / theta);
    let (co, si) = (f32::cos(theta), f32::sin(theta));
    let one_c = 1.0 - co;
    // ∂R/∂θ = −sin θ I + cos θ [k]× + sin θ k kᵀ.
    let trace = dr[0] + dr[4] + dr[8];
    let cross_x = dr[7] - dr[5];
    let cross_y = dr[2] - dr[6];
    let cross_z = dr[3] - dr[1];
    let kk = kx * (dr[0] * kx + dr[1] * ky + dr[2] * kz)
        + ky * (dr[3] * kx + dr[4] * ky + dr[5] * kz)
        + kz * (dr[6] * kx + dr[7] * ky + dr[8] * kz);
    let d_theta = -si * trace + co * (kx * cross_x + ky * cross_y + kz * cross_z) + si * kk;
    // ∂/∂k: sin θ from [k]×, (1 − cos θ)(dR + dRᵀ)k from k kᵀ.
    let gx = si * cross_x + one_c * (2.0 * dr[0] * kx + (dr[1] + dr[3]) * ky + (dr[2] + dr[6]) * kz);
    let gy = si * cross_y + one_c * ((dr[1] + dr[3]) * kx + 2.0 * dr[4] * ky + (dr[5] + dr[7]) * kz);
    let gz = si * cross_z + one_c * ((dr[2] + dr[6]) * kx + (dr[5] + dr[7]) * ky + 2.0 * dr[8] * kz);
    // k = r/θ and ∂θ/∂r = k: dr = g/θ + (dθ − g·k/θ)·k.
    let gk = gx * kx + gy * ky + gz * kz;
    let radial = d_theta - gk / theta;
    d_pose[3 * k] = gx / theta + radial * kx;
    d_pose[3 * k + 1] = gy / theta + radial * ky;
    d_pose[3 * k + 2] = gz / theta + radial * kz;
}
