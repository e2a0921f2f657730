//! CubeCL kernels for the per-pixel parts of the fused SSIM, one unit per pixel. `moments` is
//! `[5, plane]`: E[x], E[y], E[x²], E[y²], E[xy]. The factors are grouped as on Flex, so that
//! identical images give exactly 1.

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// `S = a1·a2 / (b1·b2)` at pixel `i`, returned as `(a1, a2, b1, b2)`.
#[cube]
fn factors(moments: &[f32], plane: usize, i: usize, c1: f32, c2: f32) -> (f32, f32, f32, f32) {
    let mx = moments[i];
    let my = moments[plane + i];
    let exx = moments[2 * plane + i];
    let eyy = moments[3 * plane + i];
    let exy = moments[4 * plane + i];
    let mx2 = mx * mx;
    let my2 = my * my;
    let mxy = mx * my;
    (2.0 * mxy + c1, 2.0 * (exy - mxy) + c2, (mx2 + my2) + c1, (exx - mx2) + (eyy - my2) + c2)
}

/// `planes` `[5, size]`: x, y, x², y², xy, the images the moments are blurred from.
#[cube(launch)]
pub(crate) fn moment_planes(x: &[f32], y: &[f32], planes: &mut [f32], size: u32) {
    let i = ABSOLUTE_POS;
    let n = size as usize;
    if i >= n {
        terminate!();
    }
    let (a, b) = (x[i], y[i]);
    planes[i] = a;
    planes[n + i] = b;
    planes[2 * n + i] = a * a;
    planes[3 * n + i] = b * b;
    planes[4 * n + i] = a * b;
}

#[cube(launch)]
pub(crate) fn ssim_map(moments: &[f32], map: &mut [f32], plane: u32, c1: f32, c2: f32) {
    let i = ABSOLUTE_POS;
    if i >= plane as usize {
        terminate!();
    }
    let (a1, a2, b1, b2) = factors(moments, plane as usize, i, c1, c2);
    map[i] = a1 * a2 / (b1 * b2);
}

/// `coeff` `[4, plane]`: the map's gradient times ∂S/∂E[x²] (= ∂S/∂E[y²]), ∂S/∂E[xy], ∂S/∂μx
/// and ∂S/∂μy.
#[cube(launch)]
pub(crate) fn ssim_coefficients(
    moments: &[f32],
    grad: &[f32],
    coeff: &mut [f32],
    plane: u32,
    c1: f32,
    c2: f32,
) {
    let i = ABSOLUTE_POS;
    let p = plane as usize;
    if i >= p {
        terminate!();
    }
    let (a1, a2, b1, b2) = factors(moments, p, i, c1, c2);
    let (mx, my) = (moments[i], moments[p + i]);
    let g = grad[i];
    let d = b1 * b2;
    let s = a1 * a2 / d;
    let shared = (a2 - a1) / d;
    let spread = s / b2 - s / b1;
    coeff[i] = -g * s / b2;
    coeff[p + i] = g * 2.0 * a1 / d;
    coeff[2 * p + i] = g * 2.0 * (my * shared + mx * spread);
    coeff[3 * p + i] = g * 2.0 * (mx * shared + my * spread);
}

/// `dx = t_μx + 2x·t_xx + y·t_xy` and `dy` alike from the transposed blurs `t` `[4, size]`
/// (E[x²], E[xy], μx, μy).
#[cube(launch)]
pub(crate) fn ssim_combine(x: &[f32], y: &[f32], t: &[f32], dx: &mut [f32], dy: &mut [f32], size: u32) {
    let i = ABSOLUTE_POS;
    let n = size as usize;
    if i >= n {
        terminate!();
    }
    let (t_xx, t_xy) = (t[i], t[n + i]);
    dx[i] = t[2 * n + i] + 2.0 * x[i] * t_xx + y[i] * t_xy;
    dy[i] = t[3 * n + i] + 2.0 * y[i] * t_xx + x[i] * t_xy;
}
