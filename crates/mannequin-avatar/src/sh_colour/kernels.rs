//! CubeCL kernels of the colour, one unit per Gaussian; the basis and its gradient are the
//! rasterizer's (`mannequin_splat::sh`), so the two GPU colour paths cannot drift apart.
//! Coefficients are `[G, k, 3]` (basis-major, then channel).

use burn_cubecl::cubecl;
use cubecl::prelude::*;
use mannequin_splat::sh::{sh_basis, sh_basis_vjp};

/// The unit direction from the eye to Gaussian `i` into `d`, returning the distance.
#[cube]
fn direction(means: &[f32], i: usize, ex: f32, ey: f32, ez: f32, d: &mut Array<f32>) -> f32 {
    let vx = means[3 * i] - ex;
    let vy = means[3 * i + 1] - ey;
    let vz = means[3 * i + 2] - ez;
    let r = f32::sqrt(vx * vx + vy * vy + vz * vz);
    d[0] = vx / r;
    d[1] = vy / r;
    d[2] = vz / r;
    r
}

/// Channel `ch` of Gaussian `i` before the clamp: `½ + Σ_b Y_b · c_b`.
#[cube]
fn value(coeffs: &[f32], basis: &Array<f32>, i: usize, ch: usize, #[comptime] degree: u32) -> f32 {
    let k = comptime!(((degree + 1) * (degree + 1)) as usize);
    let mut v = 0.5f32;
    #[unroll]
    for b in 0..k {
        v += basis[b] * coeffs[3 * k * i + 3 * b + ch];
    }
    v
}

/// Gaussian `i`'s colours `[max(v, 0)]` into `out[at..at + 3]`, and its direction's basis.
#[cube]
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_colour(
    means: &[f32],
    coeffs: &[f32],
    out: &mut [f32],
    i: usize,
    at: usize,
    ex: f32,
    ey: f32,
    ez: f32,
    #[comptime] degree: u32,
) {
    let mut d = Array::<f32>::new(3usize);
    direction(means, i, ex, ey, ez, &mut d);
    let mut basis = Array::<f32>::new(16usize);
    sh_basis(d[0], d[1], d[2], &mut basis, degree);
    #[unroll]
    for ch in 0..3usize {
        out[at + ch] = f32::max(value(coeffs, &basis, i, ch, degree), 0.0f32);
    }
}

#[cube(launch)]
pub(crate) fn colour_forward(
    means: &[f32],
    coeffs: &[f32],
    out: &mut [f32],
    n: u32,
    ex: f32,
    ey: f32,
    ez: f32,
    #[comptime] degree: u32,
) {
    let i = ABSOLUTE_POS;
    if i >= n as usize {
        terminate!();
    }
    write_colour(means, coeffs, out, i, 3 * i, ex, ey, ez, degree);
}

/// Gaussian `i`'s gradients of its mean and coefficients given its colours' gradient
/// `grad[at..at + 3]`. The gradient passes the clamp where the colour is positive; the means get
/// it through the view direction, projected off the direction (normalisation):
/// `(g − d (d·g)) / |v|`.
#[cube]
#[allow(clippy::too_many_arguments)]
pub(crate) fn colour_gradients(
    means: &[f32],
    coeffs: &[f32],
    grad: &[f32],
    d_means: &mut [f32],
    d_coeffs: &mut [f32],
    i: usize,
    at: usize,
    ex: f32,
    ey: f32,
    ez: f32,
    #[comptime] degree: u32,
) {
    let k = comptime!(((degree + 1) * (degree + 1)) as usize);
    let mut d = Array::<f32>::new(3usize);
    let r = direction(means, i, ex, ey, ez, &mut d);
    let mut basis = Array::<f32>::new(16usize);
    sh_basis(d[0], d[1], d[2], &mut basis, degree);
    let mut g = Array::<f32>::new(3usize);
    #[unroll]
    for ch in 0..3usize {
        g[ch] = select(value(coeffs, &basis, i, ch, degree) > 0.0f32, grad[at + ch], 0.0f32);
    }
    let mut per_basis = Array::<f32>::new(16usize);
    #[unroll]
    for b in 0..k {
        let mut acc = 0.0f32;
        #[unroll]
        for ch in 0..3usize {
            let c = 3 * k * i + 3 * b + ch;
            d_coeffs[c] = basis[b] * g[ch];
            acc += coeffs[c] * g[ch];
        }
        per_basis[b] = acc;
    }
    if comptime!(degree == 0) {
        #[unroll]
        for a in 0..3usize {
            d_means[3 * i + a] = 0.0f32;
        }
    } else {
        let mut gd = Array::<f32>::new(3usize);
        sh_basis_vjp(d[0], d[1], d[2], &per_basis, &mut gd, degree);
        let along = gd[0] * d[0] + gd[1] * d[1] + gd[2] * d[2];
        #[unroll]
        for a in 0..3usize {
            d_means[3 * i + a] = (gd[a] - d[a] * along) / r;
        }
    }
}

#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn colour_backward(
    means: &[f32],
    coeffs: &[f32],
    grad: &[f32],
    d_means: &mut [f32],
    d_coeffs: &mut [f32],
    n: u32,
    ex: f32,
    ey: f32,
    ez: f32,
    #[comptime] degree: u32,
) {
    let i = ABSOLUTE_POS;
    if i >= n as usize {
        terminate!();
    }
    colour_gradients(means, coeffs, grad, d_means, d_coeffs, i, 3 * i, ex, ey, ez, degree);
}
