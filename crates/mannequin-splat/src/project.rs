//! EWA splatting of one Gaussian (Zwicker et al. 2002; 3DGS eq. 5): the camera-space covariance
//! `Σ' = J W Σ Wᵀ Jᵀ` with the Jacobian `J` of the perspective map at the mean, plus a low-pass
//! variance on the diagonal (0.3 px² by default, gsplat's `eps2d`), inverted to the conic that the compositor evaluates. Conventions follow gsplat 1.5
//! (`_fully_fused_projection`): the Jacobian uses `x/z`, `y/z` clamped to 1.3× the frustum, the
//! screen extent is a 3.33σ box per axis, and Gaussians outside `(near, far)` are culled.
//! The backward pass is the exact derivative of this forward map, written out by hand.

use rayon::prelude::*;

use crate::camera::CameraParams;
use crate::gaussians::{Colors, GaussianGrads, Gaussians, Rotations};
use crate::real::Real;
use crate::sh;

/// Default variance (px²) added to the screen-space covariance diagonal: the low-pass filter of
/// 3DGS and gsplat (`eps2d`). [`crate::RenderOptions::dilation`] overrides it.
pub const DILATION: f64 = 0.3;

/// gsplat's per-axis screen extent in standard deviations. It equals `sqrt(2 ln 255)` rounded up,
/// so no pixel outside it can reach alpha 1/255 at opacity 1.
pub const EXTENT_SIGMA: f64 = 3.33;

type M3<T> = [T; 9];

fn mat_mul<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    std::array::from_fn(|k| {
        let (i, j) = (k / 3, k % 3);
        a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j]
    })
}

/// `aᵀ b`.
fn mat_tmul<T: Real>(a: &M3<T>, b: &M3<T>) -> M3<T> {
    std::array::from_fn(|k| {
        let (i, j) = (k / 3, k % 3);
        a[i] * b[j] + a[3 + i] * b[3 + j] + a[6 + i] * b[6 + j]
    })
}

fn mat_vec<T: Real>(a: &M3<T>, v: [T; 3]) -> [T; 3] {
    std::array::from_fn(|i| a[3 * i] * v[0] + a[3 * i + 1] * v[1] + a[3 * i + 2] * v[2])
}

/// `aᵀ v`.
fn mat_tvec<T: Real>(a: &M3<T>, v: [T; 3]) -> [T; 3] {
    std::array::from_fn(|i| a[i] * v[0] + a[3 + i] * v[1] + a[6 + i] * v[2])
}

/// Rotation matrix of the normalised quaternion `(w, x, y, z)`, and the norm.
fn quat_to_matrix<T: Real>(q: &[T]) -> (M3<T>, T) {
    let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = [q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm];
    let (one, two) = (T::ONE, T::from_f64(2.0));
    let m = [
        one - two * (y * y + z * z),
        two * (x * y - w * z),
        two * (x * z + w * y),
        two * (x * y + w * z),
        one - two * (x * x + z * z),
        two * (y * z - w * x),
        two * (x * z - w * y),
        two * (y * z + w * x),
        one - two * (x * x + y * y),
    ];
    (m, norm)
}

/// Vector-Jacobian product of [`quat_to_matrix`]: `dL/dq` from `dL/dR`, through the normalisation.
fn quat_to_matrix_vjp<T: Real>(q: &[T], g: &M3<T>) -> [T; 4] {
    let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = [q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm];
    let two = T::from_f64(2.0);
    let gw = two * (-z * g[1] + y * g[2] + z * g[3] - x * g[5] - y * g[6] + x * g[7]);
    let gx = two
        * (y * g[1] + z * g[2] + y * g[3] - two * x * g[4] - w * g[5] + z * g[6] + w * g[7] - two * x * g[8]);
    let gy = two
        * (-two * y * g[0] + x * g[1] + w * g[2] + x * g[3] + z * g[5] - w * g[6] + z * g[7]
            - two * y * g[8]);
    let gz = two
        * (-two * z * g[0] - w * g[1] + x * g[2] + w * g[3] - two * z * g[4]
            + y * g[5]
            + x * g[6]
            + y * g[7]);
    let dot = w * gw + x * gx + y * gy + z * gz;
    [(gw - w * dot) / norm, (gx - x * dot) / norm, (gy - y * dot) / norm, (gz - z * dot) / norm]
}

/// Screen-space Gaussians, one entry per input Gaussian. Culled or skipped Gaussians have
/// radius 0 and unspecified other values.
#[derive(Clone, Debug)]
pub struct Projection<T> {
    /// `[N, 2]` pixel coordinates of the means (pixel centres at +0.5).
    pub means2d: Vec<T>,
    /// `[N, 3]` inverse screen covariance `(a, b, c)`: `σ(d) = ½(a dx² + c dy²) + b dx dy`.
    pub conics: Vec<T>,
    /// `[N]` camera-space z of the means.
    pub depths: Vec<T>,
    /// `[N, 2]` half-extent in whole pixels along x and y; 0 marks a culled Gaussian.
    /// `u32::MAX` means unbounded (no alpha threshold).
    pub radii: Vec<u32>,
    /// `[N, C]` colours (SH evaluated, offset and clamped) or features.
    pub colors: Vec<T>,
    /// Gaussians skipped because a parameter was NaN or infinite (or a quaternion was zero).
    pub skipped: usize,
}

/// Per-Gaussian quantities shared by the forward and backward maps.
struct Ewa<T> {
    /// Camera-space mean.
    pc: [T; 3],
    /// Rotation (quaternion converted) and `Mc = W R diag(s)`.
    rot: M3<T>,
    mc: M3<T>,
    /// Clamped `x/z`, `y/z` used inside the Jacobian, and whether each was left unclamped.
    uv: [T; 2],
    uv_free: [bool; 2],
    /// Non-zero Jacobian entries `J00, J02, J11, J12`.
    j: [T; 4],
    /// `T2 = J Mc`, 2×3 row-major.
    t2: [T; 6],
    /// Dilated screen covariance `(p, q, r)` = `[[p, q], [q, r]]`.
    cov: [T; 3],
}

fn ewa<T: Real>(g: &Gaussians<T>, cam: &CameraParams<T>, dil: T, i: usize) -> Option<Ewa<T>> {
    let m = [g.means[3 * i], g.means[3 * i + 1], g.means[3 * i + 2]];
    let pcr = mat_vec(&cam.r, m);
    let pc = [pcr[0] + cam.t[0], pcr[1] + cam.t[1], pcr[2] + cam.t[2]];
    let z = pc[2];
    if !(z > cam.near && z < cam.far) {
        return None;
    }
    let rot = match g.rotations {
        Rotations::Quaternions(q) => {
            let (r, norm) = quat_to_matrix(&q[4 * i..4 * i + 4]);
            if !(norm > T::ZERO && norm.is_finite()) {
                return None;
            }
            r
        }
        Rotations::Matrices(r) => std::array::from_fn(|k| r[9 * i + k]),
    };
    let s = &g.scales[3 * i..3 * i + 3];
    let ms: M3<T> = std::array::from_fn(|k| rot[k] * s[k % 3]);
    let mc = mat_mul(&cam.r, &ms);
    let (ux, uy) = (pc[0] / z, pc[1] / z);
    let u = ux.max(-cam.lim_x.0).min(cam.lim_x.1);
    let v = uy.max(-cam.lim_y.0).min(cam.lim_y.1);
    let j = [cam.fx / z, -cam.fx * u / z, cam.fy / z, -cam.fy * v / z];
    let t2: [T; 6] = std::array::from_fn(|k| {
        let (row, col) = (k / 3, k % 3);
        if row == 0 { j[0] * mc[col] + j[1] * mc[6 + col] } else { j[2] * mc[3 + col] + j[3] * mc[6 + col] }
    });
    let p = t2[0] * t2[0] + t2[1] * t2[1] + t2[2] * t2[2] + dil;
    let q = t2[0] * t2[3] + t2[1] * t2[4] + t2[2] * t2[5];
    let r = t2[3] * t2[3] + t2[4] * t2[4] + t2[5] * t2[5] + dil;
    Some(Ewa { pc, rot, mc, uv: [u, v], uv_free: [ux == u, uy == v], j, t2, cov: [p, q, r] })
}

/// Unit view direction from the camera centre to the mean, and the distance.
fn view_dir<T: Real>(g: &Gaussians<T>, cam: &CameraParams<T>, i: usize) -> ([T; 3], T) {
    let d: [T; 3] = std::array::from_fn(|k| g.means[3 * i + k] - cam.centre[k]);
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    (d.map(|v| v / n), n)
}

/// Writes Gaussian `i`'s colour into `out` (length C).
fn color<T: Real>(g: &Gaussians<T>, cam: &CameraParams<T>, i: usize, basis: &mut [T], out: &mut [T]) {
    match g.colors {
        Colors::Features { channels, values } => {
            out.copy_from_slice(&values[channels * i..channels * (i + 1)])
        }
        Colors::Sh { degree, coeffs } => {
            let k = sh::basis_len(degree);
            let (d, _) = view_dir(g, cam, i);
            sh::basis(degree, d, &mut basis[..k]);
            let c = &coeffs[3 * k * i..3 * k * (i + 1)];
            for (ch, o) in out.iter_mut().enumerate() {
                let v: T = (0..k).map(|b| basis[b] * c[3 * b + ch]).sum();
                *o = (v + T::from_f64(0.5)).max(T::ZERO);
            }
        }
    }
}

/// The per-axis extent in σ for alpha threshold `threshold`: gsplat's 3.33σ box, widened when a
/// lower threshold makes farther pixels count; unbounded (`None`) without a threshold.
pub(crate) fn extent_sigma(threshold: f64) -> Option<f64> {
    (threshold > 0.0).then(|| EXTENT_SIGMA.max((2.0 * (1.0 / threshold).ln()).sqrt()))
}

/// Projects every Gaussian (in parallel). `alpha_threshold` sets the screen extent and `dilation` is the low-pass variance (px²).
pub fn project<T: Real>(
    g: &Gaussians<T>,
    cam: &CameraParams<T>,
    alpha_threshold: f64,
    dilation: f64,
) -> Projection<T> {
    let n = g.len();
    let dil = T::from_f64(dilation);
    let ch = g.channels();
    let extent = extent_sigma(alpha_threshold).map(T::from_f64);
    let mut means2d = vec![T::ZERO; 2 * n];
    let mut conics = vec![T::ZERO; 3 * n];
    let mut depths = vec![T::ZERO; n];
    let mut radii = vec![0u32; 2 * n];
    let mut colors = vec![T::ZERO; ch * n];
    let skipped = means2d
        .par_chunks_mut(2)
        .zip(conics.par_chunks_mut(3))
        .zip(depths.par_iter_mut())
        .zip(radii.par_chunks_mut(2))
        .zip(colors.par_chunks_mut(ch))
        .enumerate()
        .map_init(
            || vec![T::ZERO; sh::basis_len(sh::MAX_DEGREE)],
            |basis, (i, ((((m2, con), dep), rad), col))| {
                if !g.is_finite(i) {
                    return 1usize;
                }
                let Some(e) = ewa(g, cam, dil, i) else { return 0 };
                let [p, q, r] = e.cov;
                let det = p * r - q * q;
                if det.partial_cmp(&T::ZERO) != Some(std::cmp::Ordering::Greater) {
                    return 0;
                }
                let z = e.pc[2];
                let mx = cam.fx * e.pc[0] / z + cam.cx;
                let my = cam.fy * e.pc[1] / z + cam.cy;
                let (rx, ry) = match extent {
                    Some(k) => ((k * p.sqrt()).to_f64().ceil(), (k * r.sqrt()).to_f64().ceil()),
                    None => (f64::INFINITY, f64::INFINITY),
                };
                let (mxf, myf) = (mx.to_f64(), my.to_f64());
                let inside = mxf + rx > 0.0
                    && mxf - rx < cam.width.to_f64()
                    && myf + ry > 0.0
                    && myf - ry < cam.height.to_f64();
                if !inside {
                    return 0;
                }
                m2.copy_from_slice(&[mx, my]);
                con.copy_from_slice(&[r / det, -q / det, p / det]);
                *dep = z;
                rad.copy_from_slice(&[rx.min(u32::MAX as f64) as u32, ry.min(u32::MAX as f64) as u32]);
                color(g, cam, i, basis, col);
                0
            },
        )
        .sum();
    Projection { means2d, conics, depths, radii, colors, skipped }
}

/// Gradients of the loss with respect to one Gaussian's screen-space quantities.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ScreenGrad<T> {
    pub mean2d: [T; 2],
    pub conic: [T; 3],
    pub depth: T,
}

/// Chains screen-space gradients back to Gaussian `i`'s parameters, writing row `i` of `out`.
/// `d_color` is `dL/dcolour` (length C) and `d_opacity` passes through unchanged.
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_vjp<T: Real>(
    g: &Gaussians<T>,
    cam: &CameraParams<T>,
    dil: T,
    i: usize,
    sg: &ScreenGrad<T>,
    d_color: &[T],
    d_opacity: T,
    basis: &mut [T],
    out: GradRow<'_, T>,
) {
    out.opacity[0] = d_opacity;
    let Some(e) = ewa(g, cam, dil, i) else { return };
    let [p, q, r] = e.cov;
    let det = p * r - q * q;
    let (a, b, c) = (r / det, -q / det, p / det);
    let half = T::from_f64(0.5);
    // dL/dΣ' = −Q G Q with Q = [[a, b], [b, c]] and G the (symmetric) gradient w.r.t. Q.
    let (ga, gb, gc) = (sg.conic[0], half * sg.conic[1], sg.conic[2]);
    let qg = [a * ga + b * gb, a * gb + b * gc, b * ga + c * gb, b * gb + c * gc];
    let s00 = -(qg[0] * a + qg[1] * b);
    let s01 = -(qg[0] * b + qg[1] * c);
    let s11 = -(qg[2] * b + qg[3] * c);
    // Σ' = T2 T2ᵀ + εI ⇒ dL/dT2 = 2 S T2 (S symmetric).
    let two = T::from_f64(2.0);
    let t2 = &e.t2;
    let dt2: [T; 6] = std::array::from_fn(|k| {
        let col = k % 3;
        if k < 3 {
            two * (s00 * t2[col] + s01 * t2[3 + col])
        } else {
            two * (s01 * t2[col] + s11 * t2[3 + col])
        }
    });
    // T2 = J Mc ⇒ dJ = dT2 Mcᵀ (only the four non-zero entries matter), dMc = Jᵀ dT2.
    let mc = &e.mc;
    let dj00 = dt2[0] * mc[0] + dt2[1] * mc[1] + dt2[2] * mc[2];
    let dj02 = dt2[0] * mc[6] + dt2[1] * mc[7] + dt2[2] * mc[8];
    let dj11 = dt2[3] * mc[3] + dt2[4] * mc[4] + dt2[5] * mc[5];
    let dj12 = dt2[3] * mc[6] + dt2[4] * mc[7] + dt2[5] * mc[8];
    let j = &e.j;
    let dmc: M3<T> = std::array::from_fn(|k| {
        let (row, col) = (k / 3, k % 3);
        match row {
            0 => j[0] * dt2[col],
            1 => j[2] * dt2[3 + col],
            _ => j[1] * dt2[col] + j[3] * dt2[3 + col],
        }
    });
    // Mc = W R diag(s).
    let dms = mat_tmul(&cam.r, &dmc);
    let s = &g.scales[3 * i..3 * i + 3];
    for k in 0..3 {
        out.scales[k] = (0..3).map(|row| dms[3 * row + k] * e.rot[3 * row + k]).sum();
    }
    let drot: M3<T> = std::array::from_fn(|k| dms[k] * s[k % 3]);
    match g.rotations {
        Rotations::Quaternions(qs) => {
            out.rotations.copy_from_slice(&quat_to_matrix_vjp(&qs[4 * i..4 * i + 4], &drot))
        }
        Rotations::Matrices(_) => out.rotations.copy_from_slice(&drot),
    }
    // Camera-space mean: through the projected mean, the depth and the Jacobian.
    let [x, y, z] = e.pc;
    let (fx, fy) = (cam.fx, cam.fy);
    let [u, v] = e.uv;
    let (gmx, gmy) = (sg.mean2d[0], sg.mean2d[1]);
    let mut dpc = [fx / z * gmx, fy / z * gmy, -(fx * x * gmx + fy * y * gmy) / (z * z) + sg.depth];
    let z2 = z * z;
    dpc[2] += (-fx * dj00 - fy * dj11 + fx * u * dj02 + fy * v * dj12) / z2;
    let (du, dv) = (-fx / z * dj02, -fy / z * dj12);
    if e.uv_free[0] {
        dpc[0] += du / z;
        dpc[2] -= x / z2 * du;
    }
    if e.uv_free[1] {
        dpc[1] += dv / z;
        dpc[2] -= y / z2 * dv;
    }
    let mut dm = mat_tvec(&cam.r, dpc);
    // Colour.
    match g.colors {
        Colors::Features { .. } => out.colors.copy_from_slice(d_color),
        Colors::Sh { degree, coeffs } => {
            let k = sh::basis_len(degree);
            let (d, dist) = view_dir(g, cam, i);
            sh::basis(degree, d, &mut basis[..k]);
            let cf = &coeffs[3 * k * i..3 * k * (i + 1)];
            // The clamp at 0 stops the gradient of a channel that was clamped.
            let mut gcol = [T::ZERO; 3];
            for (ch, gc) in gcol.iter_mut().enumerate() {
                let v: T = (0..k).map(|bi| basis[bi] * cf[3 * bi + ch]).sum();
                if v + half > T::ZERO {
                    *gc = d_color[ch];
                }
            }
            for (row, &y) in out.colors.chunks_exact_mut(3).zip(&basis[..k]) {
                for (o, &gc) in row.iter_mut().zip(&gcol) {
                    *o = y * gc;
                }
            }
            if degree > 0 {
                let mut gbasis = [T::ZERO; sh::basis_len(sh::MAX_DEGREE)];
                for (bi, gb) in gbasis[..k].iter_mut().enumerate() {
                    *gb = (0..3).map(|ch| cf[3 * bi + ch] * gcol[ch]).sum();
                }
                let vd = sh::basis_vjp(degree, d, &gbasis[..k]);
                let dot = vd[0] * d[0] + vd[1] * d[1] + vd[2] * d[2];
                for k in 0..3 {
                    dm[k] += (vd[k] - d[k] * dot) / dist;
                }
            }
        }
    }
    out.means.copy_from_slice(&dm);
}

/// Mutable views of one Gaussian's rows in a [`GaussianGrads`].
pub(crate) struct GradRow<'a, T> {
    pub means: &'a mut [T],
    pub rotations: &'a mut [T],
    pub scales: &'a mut [T],
    pub opacity: &'a mut [T],
    pub colors: &'a mut [T],
}

impl<T: Real> GaussianGrads<T> {
    /// Zeroed gradients shaped like `g`.
    pub(crate) fn zeros_like(g: &Gaussians<T>) -> Self {
        let n = g.len();
        let rot = match g.rotations {
            Rotations::Quaternions(_) => 4,
            Rotations::Matrices(_) => 9,
        };
        let col = match g.colors {
            Colors::Sh { degree, .. } => 3 * sh::basis_len(degree),
            Colors::Features { channels, .. } => channels,
        };
        GaussianGrads {
            means: vec![T::ZERO; 3 * n],
            rotations: vec![T::ZERO; rot * n],
            scales: vec![T::ZERO; 3 * n],
            opacities: vec![T::ZERO; n],
            colors: vec![T::ZERO; col * n],
        }
    }
}
