//! CubeCL kernels of the features, one unit per Gaussian: the colour's are the fused colour's
//! own (`crate::sh_colour`), the normal's a 3×3 product each way.

use burn_cubecl::cubecl;
use cubecl::prelude::*;

use crate::sh_colour::kernels::{colour_gradients, write_colour};

/// `out[6i..6i + 3]` the colour, `out[6i + 3..6i + 6] = R·n_i` (`rotation` row-major).
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn features_forward(
    means: &[f32],
    coeffs: &[f32],
    normals: &[f32],
    rotation: &[f32],
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
    write_colour(means, coeffs, out, i, 6 * i, ex, ey, ez, degree);
    #[unroll]
    for r in 0..3usize {
        let mut v = 0.0f32;
        #[unroll]
        for c in 0..3usize {
            v += rotation[3 * r + c] * normals[3 * i + c];
        }
        out[6 * i + 3 + r] = v;
    }
}

/// The colour's gradients from `grad[6i..6i + 3]`, and `d n_i = Rᵀ·grad[6i + 3..6i + 6]`.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn features_backward(
    means: &[f32],
    coeffs: &[f32],
    rotation: &[f32],
    grad: &[f32],
    d_means: &mut [f32],
    d_coeffs: &mut [f32],
    d_normals: &mut [f32],
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
    colour_gradients(means, coeffs, grad, d_means, d_coeffs, i, 6 * i, ex, ey, ez, degree);
    #[unroll]
    for c in 0..3usize {
        let mut v = 0.0f32;
        #[unroll]
        for r in 0..3usize {
            v += rotation[3 * r + c] * grad[6 * i + 3 + r];
        }
        d_normals[3 * i + c] = v;
    }
}
