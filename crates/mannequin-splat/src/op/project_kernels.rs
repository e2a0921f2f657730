//! CubeCL kernels for the per-Gaussian work: the EWA projection (and SH colour) forward, and its
//! hand-written backward. They mirror `project.rs` line for line; one unit is one Gaussian.
//!
//! `cam` holds the camera as the kernels read it (see [`camera_words`]).

// `!(x > 0.0)` is how kernels reject NaN along with non-positive values (no `partial_cmp` there).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use burn_cubecl::cubecl;
use cubecl::prelude::*;

use crate::camera::CameraParams;
use crate::project::extent_sigma;
use crate::render::RenderOptions;

/// Camera words: fx, fy, cx, cy, R (9, row-major), t (3), centre (3), near, far, width,
/// height, x/z limits (−, +), y/z limits (−, +), extent in σ (0: unbounded), dilation.
pub(crate) fn camera_words(cam: &CameraParams<f32>, options: &RenderOptions) -> Vec<f32> {
    let mut w = vec![cam.fx, cam.fy, cam.cx, cam.cy];
    w.extend_from_slice(&cam.r);
    w.extend_from_slice(&cam.t);
    w.extend_from_slice(&cam.centre);
    w.extend([cam.near, cam.far, cam.width, cam.height, cam.lim_x.0, cam.lim_x.1, cam.lim_y.0, cam.lim_y.1]);
    w.push(extent_sigma(options.alpha_threshold).unwrap_or(0.0) as f32);
    w.push(options.dilation as f32);
    w
}

const FX: usize = 0;
const FY: usize = 1;
const CX: usize = 2;
const CY: usize = 3;
const R: usize = 4;
const T: usize = 13;
const CENTRE: usize = 16;
const NEAR: usize = 19;
const FAR: usize = 20;
const WIDTH: usize = 21;
const HEIGHT: usize = 22;
const LIM: usize = 23;
const EXTENT: usize = 27;
const DIL: usize = 28;

// Slots of the per-Gaussian intermediate state shared by both passes.
const PC: usize = 0;
const ROT: usize = 3;
const MC: usize = 12;
const UV: usize = 21;
const FREE: usize = 23;
const JAC: usize = 25;
const T2: usize = 29;
const COV: usize = 35;
const STATE: usize = 38;

/// Whether the `len` values from `start` are all finite (exponent bits not all set). This is
/// integer logic on purpose: shader compilers may assume floats are never NaN, so a float test
/// such as `v·0 != 0` can be folded away (on lavapipe it was).
#[cube]
fn all_finite(data: &[f32], start: usize, len: usize) -> bool {
    let mut finite = true;
    for k in 0..len {
        if u32::reinterpret(data[start + k]) & 0x7F80_0000u32 == 0x7F80_0000u32 {
            finite = false;
        }
    }
    finite
}

/// Fills `s` with the camera-space mean, rotation, `Mc = W R diag(s)`, the clamped `x/z, y/z`
/// (and whether they were free), the Jacobian's four entries, `T2 = J Mc` and the dilated screen
/// covariance `(p, q, r)`. Returns false when the Gaussian is culled (depth, zero quaternion).
#[cube]
fn ewa(
    i: usize,
    means: &[f32],
    rots: &[f32],
    scales: &[f32],
    cam: &[f32],
    s: &mut Array<f32>,
    #[comptime] matrices: bool,
) -> bool {
    let mut ok = true;
    #[unroll]
    for k in 0..3usize {
        s[PC + k] = cam[R + 3 * k] * means[3 * i]
            + cam[R + 3 * k + 1] * means[3 * i + 1]
            + cam[R + 3 * k + 2] * means[3 * i + 2]
            + cam[T + k];
    }
    let z = s[PC + 2];
    if !(z > cam[NEAR] && z < cam[FAR]) {
        ok = false;
    }
    if matrices {
        #[unroll]
        for k in 0..9usize {
            s[ROT + k] = rots[9 * i + k];
        }
    } else {
        let (q0, q1, q2, q3) = (rots[4 * i], rots[4 * i + 1], rots[4 * i + 2], rots[4 * i + 3]);
        let norm = f32::sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
        if !(norm > 0.0f32) {
            ok = false;
        }
        let (w, x, y, zz) = (q0 / norm, q1 / norm, q2 / norm, q3 / norm);
        s[ROT] = 1.0f32 - 2.0f32 * (y * y + zz * zz);
        s[ROT + 1] = 2.0f32 * (x * y - w * zz);
        s[ROT + 2] = 2.0f32 * (x * zz + w * y);
        s[ROT + 3] = 2.0f32 * (x * y + w * zz);
        s[ROT + 4] = 1.0f32 - 2.0f32 * (x * x + zz * zz);
        s[ROT + 5] = 2.0f32 * (y * zz - w * x);
        s[ROT + 6] = 2.0f32 * (x * zz - w * y);
        s[ROT + 7] = 2.0f32 * (y * zz + w * x);
        s[ROT + 8] = 1.0f32 - 2.0f32 * (x * x + y * y);
    }
    // Mc = W (R diag(s)).
    #[unroll]
    for row in 0..3usize {
        #[unroll]
        for col in 0..3usize {
            let sc = scales[3 * i + col];
            s[MC + 3 * row + col] = (cam[R + 3 * row] * s[ROT + col]
                + cam[R + 3 * row + 1] * s[ROT + 3 + col]
                + cam[R + 3 * row + 2] * s[ROT + 6 + col])
                * sc;
        }
    }
    let ux = s[PC] / z;
    let uy = s[PC + 1] / z;
    let u = f32::min(f32::max(ux, -cam[LIM]), cam[LIM + 1]);
    let v = f32::min(f32::max(uy, -cam[LIM + 2]), cam[LIM + 3]);
    s[UV] = u;
    s[UV + 1] = v;
    s[FREE] = select(ux == u, 1.0f32, 0.0f32);
    s[FREE + 1] = select(uy == v, 1.0f32, 0.0f32);
    s[JAC] = cam[FX] / z;
    s[JAC + 1] = -cam[FX] * u / z;
    s[JAC + 2] = cam[FY] / z;
    s[JAC + 3] = -cam[FY] * v / z;
    #[unroll]
    for col in 0..3usize {
        s[T2 + col] = s[JAC] * s[MC + col] + s[JAC + 1] * s[MC + 6 + col];
        s[T2 + 3 + col] = s[JAC + 2] * s[MC + 3 + col] + s[JAC + 3] * s[MC + 6 + col];
    }
    s[COV] = s[T2] * s[T2] + s[T2 + 1] * s[T2 + 1] + s[T2 + 2] * s[T2 + 2] + cam[DIL];
    s[COV + 1] = s[T2] * s[T2 + 3] + s[T2 + 1] * s[T2 + 4] + s[T2 + 2] * s[T2 + 5];
    s[COV + 2] = s[T2 + 3] * s[T2 + 3] + s[T2 + 4] * s[T2 + 4] + s[T2 + 5] * s[T2 + 5] + cam[DIL];
    ok
}

/// The SH basis (gsplat's order and signs) at unit direction `(x, y, z)`, as in `sh.rs`.
#[cube]
pub fn sh_basis(x: f32, y: f32, z: f32, out: &mut Array<f32>, #[comptime] degree: u32) {
    out[0] = 0.282_094_8f32;
    if degree >= 1 {
        out[1] = -0.488_602_5f32 * y;
        out[2] = 0.488_602_5f32 * z;
        out[3] = -0.488_602_5f32 * x;
    }
    if degree >= 2 {
        out[4] = 0.546_274_2f32 * 2.0f32 * x * y;
        out[5] = -1.092_548_4f32 * z * y;
        out[6] = 0.946_174_7f32 * z * z - 0.315_391_57f32;
        out[7] = -1.092_548_4f32 * z * x;
        out[8] = 0.546_274_2f32 * (x * x - y * y);
    }
    if degree >= 3 {
        let fc1 = x * x - y * y;
        let fs1 = 2.0f32 * x * y;
        let tmp_c = -2.285_229f32 * z * z + 0.457_045_8f32;
        out[9] = -0.590_043_6f32 * (x * fs1 + y * fc1);
        out[10] = 1.445_305_7f32 * z * fs1;
        out[11] = tmp_c * y;
        out[12] = z * (1.865_881_7f32 * z * z - 1.119_529f32);
        out[13] = tmp_c * x;
        out[14] = 1.445_305_7f32 * z * fc1;
        out[15] = -0.590_043_6f32 * (x * fc1 - y * fs1);
    }
}

/// `Σ_k g_k ∇Y_k` at `(x, y, z)` into `out[0..3]`, as `sh::basis_vjp`.
#[cube]
pub fn sh_basis_vjp(x: f32, y: f32, z: f32, g: &Array<f32>, out: &mut Array<f32>, #[comptime] degree: u32) {
    let c1 = 0.488_602_5f32;
    let mut vx = -c1 * g[3];
    let mut vy = -c1 * g[1];
    let mut vz = c1 * g[2];
    if degree >= 2 {
        let cxy = 0.546_274_2f32;
        let cz = 1.092_548_4f32;
        vx += 2.0f32 * cxy * y * g[4] - cz * z * g[7] + 2.0f32 * cxy * x * g[8];
        vy += 2.0f32 * cxy * x * g[4] - cz * z * g[5] - 2.0f32 * cxy * y * g[8];
        vz += -cz * y * g[5] + 2.0f32 * 0.946_174_7f32 * z * g[6] - cz * x * g[7];
    }
    if degree >= 3 {
        let a = -0.590_043_6f32;
        let b = 1.445_305_7f32;
        let cz = -2.285_229f32;
        let tmp_c = cz * z * z + 0.457_045_8f32;
        let xx = x * x;
        let yy = y * y;
        vx += a * 6.0f32 * x * y * g[9]
            + 2.0f32 * b * z * y * g[10]
            + tmp_c * g[13]
            + 2.0f32 * b * z * x * g[14]
            + a * 3.0f32 * (xx - yy) * g[15];
        vy += a * 3.0f32 * (xx - yy) * g[9] + 2.0f32 * b * z * x * g[10] + tmp_c * g[11]
            - 2.0f32 * b * z * y * g[14]
            - a * 6.0f32 * x * y * g[15];
        vz += 2.0f32 * b * x * y * g[10]
            + 2.0f32 * cz * z * y * g[11]
            + (3.0f32 * 1.865_881_7f32 * z * z - 1.119_529f32) * g[12]
            + 2.0f32 * cz * z * x * g[13]
            + b * (xx - yy) * g[14];
    }
    out[0] = vx;
    out[1] = vy;
    out[2] = vz;
}

/// Projects every Gaussian: a packed row (mean, conic, opacity, depth, …, colour; see
/// `composite::field`) and its radii in pixels (0: culled or skipped). Gaussians with a NaN or
/// infinite parameter are skipped and counted in `skipped[0]`.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_forward(
    means: &[f32],
    rots: &[f32],
    scales: &[f32],
    opacities: &[f32],
    colors: &[f32],
    cam: &[f32],
    rows: &mut [f32],
    radii: &mut [f32],
    skipped: &mut [Atomic<f32>],
    n: u32,
    #[comptime] matrices: bool,
    #[comptime] sh_degree: u32,
    #[comptime] sh: bool,
    #[comptime] color_len: usize,
    #[comptime] stride: usize,
) {
    let i = ABSOLUTE_POS;
    if i >= n as usize {
        terminate!();
    }
    radii[2 * i] = 0.0f32;
    radii[2 * i + 1] = 0.0f32;
    // The buffers come uninitialised (no fill launches): rows of Gaussians left out stay zero.
    let row = i * stride;
    #[unroll]
    for k in 0..stride {
        rows[row + k] = 0.0f32;
    }
    let rot_len = comptime!(if matrices { 9usize } else { 4usize });
    let finite = all_finite(means, 3 * i, 3)
        && all_finite(rots, rot_len * i, rot_len)
        && all_finite(scales, 3 * i, 3)
        && all_finite(opacities, i, 1)
        && all_finite(colors, color_len * i, color_len);
    if !finite {
        skipped[0].fetch_add(1.0f32);
        terminate!();
    }
    let mut s = Array::<f32>::new(STATE);
    if !ewa(i, means, rots, scales, cam, &mut s, matrices) {
        terminate!();
    }
    let (p, q, r) = (s[COV], s[COV + 1], s[COV + 2]);
    let det = p * r - q * q;
    if !(det > 0.0f32) {
        terminate!();
    }
    let z = s[PC + 2];
    let mx = cam[FX] * s[PC] / z + cam[CX];
    let my = cam[FY] * s[PC + 1] / z + cam[CY];
    let mut rx = 1.0e30f32;
    let mut ry = 1.0e30f32;
    if cam[EXTENT] > 0.0f32 {
        rx = f32::ceil(cam[EXTENT] * f32::sqrt(p));
        ry = f32::ceil(cam[EXTENT] * f32::sqrt(r));
    }
    if !(mx + rx > 0.0f32 && mx - rx < cam[WIDTH] && my + ry > 0.0f32 && my - ry < cam[HEIGHT]) {
        terminate!();
    }
    rows[row] = mx;
    rows[row + 1] = my;
    rows[row + 2] = r / det;
    rows[row + 3] = -q / det;
    rows[row + 4] = p / det;
    rows[row + 5] = opacities[i];
    rows[row + 6] = z;
    if sh {
        let k = comptime!(((sh_degree + 1) * (sh_degree + 1)) as usize);
        let dx = means[3 * i] - cam[CENTRE];
        let dy = means[3 * i + 1] - cam[CENTRE + 1];
        let dz = means[3 * i + 2] - cam[CENTRE + 2];
        let dn = f32::sqrt(dx * dx + dy * dy + dz * dz);
        let mut basis = Array::<f32>::new(16usize);
        sh_basis(dx / dn, dy / dn, dz / dn, &mut basis, sh_degree);
        #[unroll]
        for ch in 0..3usize {
            let mut v = 0.5f32;
            #[unroll]
            for b in 0..k {
                v += basis[b] * colors[color_len * i + 3 * b + ch];
            }
            rows[row + 12 + ch] = f32::max(v, 0.0f32);
        }
    } else {
        for ch in 0..color_len {
            rows[row + 12 + ch] = colors[color_len * i + ch];
        }
    }
    radii[2 * i] = rx;
    radii[2 * i + 1] = ry;
}

/// Chains each Gaussian's screen-space gradient sums (mean x, y; conic a, b, c; opacity; depth;
/// colours) back to its parameters, as `project::project_vjp`.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_backward(
    means: &[f32],
    rots: &[f32],
    scales: &[f32],
    colors: &[f32],
    cam: &[f32],
    sums: &[f32],
    d_means: &mut [f32],
    d_rots: &mut [f32],
    d_scales: &mut [f32],
    d_opacities: &mut [f32],
    d_colors: &mut [f32],
    n: u32,
    #[comptime] matrices: bool,
    #[comptime] sh_degree: u32,
    #[comptime] sh: bool,
    #[comptime] color_len: usize,
) {
    let i = ABSOLUTE_POS;
    if i >= n as usize {
        terminate!();
    }
    let slots = comptime!(7 + if sh { 3usize } else { color_len });
    let g = i * slots;
    // Every output word is written (the buffers come uninitialised: no fill launches); those of
    // a Gaussian that is not drawn, or that no pixel's gradient reaches, stay zero.
    let rot_len = comptime!(if matrices { 9usize } else { 4usize });
    #[unroll]
    for k in 0..3usize {
        d_means[3 * i + k] = 0.0f32;
        d_scales[3 * i + k] = 0.0f32;
    }
    #[unroll]
    for k in 0..rot_len {
        d_rots[rot_len * i + k] = 0.0f32;
    }
    for k in 0..color_len {
        d_colors[color_len * i + k] = 0.0f32;
    }
    d_opacities[i] = sums[g + 5];
    let mut nonzero = false;
    for k in 0..slots {
        if sums[g + k] != 0.0f32 {
            nonzero = true;
        }
    }
    let mut s = Array::<f32>::new(STATE);
    let visible = ewa(i, means, rots, scales, cam, &mut s, matrices);
    if !(nonzero && visible) {
        terminate!();
    }
    let (p, q, r) = (s[COV], s[COV + 1], s[COV + 2]);
    let det = p * r - q * q;
    let (a, b, c) = (r / det, -q / det, p / det);
    // dL/dΣ' = −Q G Q.
    let ga = sums[g + 2];
    let gb = 0.5f32 * sums[g + 3];
    let gc = sums[g + 4];
    let qg0 = a * ga + b * gb;
    let qg1 = a * gb + b * gc;
    let qg2 = b * ga + c * gb;
    let qg3 = b * gb + c * gc;
    let s00 = -(qg0 * a + qg1 * b);
    let s01 = -(qg0 * b + qg1 * c);
    let s11 = -(qg2 * b + qg3 * c);
    let mut dt2 = Array::<f32>::new(6usize);
    #[unroll]
    for col in 0..3usize {
        dt2[col] = 2.0f32 * (s00 * s[T2 + col] + s01 * s[T2 + 3 + col]);
        dt2[3 + col] = 2.0f32 * (s01 * s[T2 + col] + s11 * s[T2 + 3 + col]);
    }
    let dj00 = dt2[0] * s[MC] + dt2[1] * s[MC + 1] + dt2[2] * s[MC + 2];
    let dj02 = dt2[0] * s[MC + 6] + dt2[1] * s[MC + 7] + dt2[2] * s[MC + 8];
    let dj11 = dt2[3] * s[MC + 3] + dt2[4] * s[MC + 4] + dt2[5] * s[MC + 5];
    let dj12 = dt2[3] * s[MC + 6] + dt2[4] * s[MC + 7] + dt2[5] * s[MC + 8];
    let mut dmc = Array::<f32>::new(9usize);
    #[unroll]
    for col in 0..3usize {
        dmc[col] = s[JAC] * dt2[col];
        dmc[3 + col] = s[JAC + 2] * dt2[3 + col];
        dmc[6 + col] = s[JAC + 1] * dt2[col] + s[JAC + 3] * dt2[3 + col];
    }
    // Mc = W R diag(s): dms = Wᵀ dMc.
    let mut drot = Array::<f32>::new(9usize);
    #[unroll]
    for col in 0..3usize {
        let mut ds = 0.0f32;
        #[unroll]
        for row in 0..3usize {
            let dms =
                cam[R + row] * dmc[col] + cam[R + 3 + row] * dmc[3 + col] + cam[R + 6 + row] * dmc[6 + col];
            ds += dms * s[ROT + 3 * row + col];
            drot[3 * row + col] = dms * scales[3 * i + col];
        }
        d_scales[3 * i + col] = ds;
    }
    if matrices {
        #[unroll]
        for k in 0..9usize {
            d_rots[9 * i + k] = drot[k];
        }
    } else {
        let (q0, q1, q2, q3) = (rots[4 * i], rots[4 * i + 1], rots[4 * i + 2], rots[4 * i + 3]);
        let norm = f32::sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
        let (w, x, y, zz) = (q0 / norm, q1 / norm, q2 / norm, q3 / norm);
        let gw =
            2.0f32 * (-zz * drot[1] + y * drot[2] + zz * drot[3] - x * drot[5] - y * drot[6] + x * drot[7]);
        let gx = 2.0f32
            * (y * drot[1] + zz * drot[2] + y * drot[3] - 2.0f32 * x * drot[4] - w * drot[5]
                + zz * drot[6]
                + w * drot[7]
                - 2.0f32 * x * drot[8]);
        let gy = 2.0f32
            * (-2.0f32 * y * drot[0] + x * drot[1] + w * drot[2] + x * drot[3] + zz * drot[5] - w * drot[6]
                + zz * drot[7]
                - 2.0f32 * y * drot[8]);
        let gz = 2.0f32
            * (-2.0f32 * zz * drot[0] - w * drot[1] + x * drot[2] + w * drot[3] - 2.0f32 * zz * drot[4]
                + y * drot[5]
                + x * drot[6]
                + y * drot[7]);
        let dot = w * gw + x * gx + y * gy + zz * gz;
        d_rots[4 * i] = (gw - w * dot) / norm;
        d_rots[4 * i + 1] = (gx - x * dot) / norm;
        d_rots[4 * i + 2] = (gy - y * dot) / norm;
        d_rots[4 * i + 3] = (gz - zz * dot) / norm;
    }
    // Camera-space mean: through the projected mean, the depth and the Jacobian.
    let (px, py, z) = (s[PC], s[PC + 1], s[PC + 2]);
    let (fx, fy) = (cam[FX], cam[FY]);
    let (u, v) = (s[UV], s[UV + 1]);
    let (gmx, gmy) = (sums[g], sums[g + 1]);
    let z2 = z * z;
    let mut d0 = fx / z * gmx;
    let mut d1 = fy / z * gmy;
    let mut d2 = -(fx * px * gmx + fy * py * gmy) / z2 + sums[g + 6];
    d2 += (-fx * dj00 - fy * dj11 + fx * u * dj02 + fy * v * dj12) / z2;
    let du = -fx / z * dj02;
    let dv = -fy / z * dj12;
    if s[FREE] > 0.0f32 {
        d0 += du / z;
        d2 -= px / z2 * du;
    }
    if s[FREE + 1] > 0.0f32 {
        d1 += dv / z;
        d2 -= py / z2 * dv;
    }
    let mut dm = Array::<f32>::new(3usize);
    #[unroll]
    for k in 0..3usize {
        dm[k] = cam[R + k] * d0 + cam[R + 3 + k] * d1 + cam[R + 6 + k] * d2;
    }
    if sh {
        let k = comptime!(((sh_degree + 1) * (sh_degree + 1)) as usize);
        let dx = means[3 * i] - cam[CENTRE];
        let dy = means[3 * i + 1] - cam[CENTRE + 1];
        let dz = means[3 * i + 2] - cam[CENTRE + 2];
        let dist = f32::sqrt(dx * dx + dy * dy + dz * dz);
        let (ux, uy, uz) = (dx / dist, dy / dist, dz / dist);
        let mut basis = Array::<f32>::new(16usize);
        sh_basis(ux, uy, uz, &mut basis, sh_degree);
        let mut gcol = Array::<f32>::new(3usize);
        #[unroll]
        for ch in 0..3usize {
            let mut val = 0.5f32;
            #[unroll]
            for bi in 0..k {
                val += basis[bi] * colors[color_len * i + 3 * bi + ch];
            }
            gcol[ch] = select(val > 0.0f32, sums[g + 7 + ch], 0.0f32);
        }
        let mut gbasis = Array::<f32>::new(16usize);
        #[unroll]
        for bi in 0..k {
            let mut acc = 0.0f32;
            #[unroll]
            for ch in 0..3usize {
                d_colors[color_len * i + 3 * bi + ch] = basis[bi] * gcol[ch];
                acc += colors[color_len * i + 3 * bi + ch] * gcol[ch];
            }
            gbasis[bi] = acc;
        }
        if sh_degree > 0 {
            let mut vd = Array::<f32>::new(3usize);
            sh_basis_vjp(ux, uy, uz, &gbasis, &mut vd, sh_degree);
            let dot = vd[0] * ux + vd[1] * uy + vd[2] * uz;
            dm[0] += (vd[0] - ux * dot) / dist;
            dm[1] += (vd[1] - uy * dot) / dist;
            dm[2] += (vd[2] - uz * dot) / dist;
        }
    } else {
        for ch in 0..color_len {
            d_colors[color_len * i + ch] = sums[g + 7 + ch];
        }
    }
    #[unroll]
    for k in 0..3usize {
        d_means[3 * i + k] = dm[k];
    }
}
