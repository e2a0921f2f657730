//! Real spherical harmonics up to degree 3, in the basis order and sign convention of 3DGS and
//! gsplat (`_eval_sh_bases_fast`, after Sloan, "Efficient Spherical Harmonic Evaluation", 2013).
//! The basis is evaluated as polynomials in the unit direction `(x, y, z)`; the gradient below is
//! of these same polynomials, and the caller projects it through the normalisation.

use crate::real::Real;

/// The same basis and gradient as CubeCL functions (f32), for other crates' kernels.
pub use crate::op::{sh_basis, sh_basis_vjp};

/// Number of basis functions for `degree` (1, 4, 9, 16).
pub const fn basis_len(degree: usize) -> usize {
    (degree + 1) * (degree + 1)
}

/// Highest supported degree.
pub const MAX_DEGREE: usize = 3;

const C0: f64 = 0.282_094_791_773_878_1;
const C1: f64 = 0.488_602_511_902_92;
const C2_XY: f64 = 0.546_274_215_296_039_5;
const C2_Z: f64 = 1.092_548_430_592_079;
const C2_ZZ: f64 = 0.946_174_695_757_560_1;
const C2_0: f64 = 0.315_391_565_252_520_1;
const C3_A: f64 = -0.590_043_589_926_643_5;
const C3_B: f64 = 1.445_305_721_320_277;
const C3_CZ: f64 = -2.285_228_997_322_329;
const C3_C0: f64 = 0.457_045_799_464_465_8;
const C3_DZ: f64 = 1.865_881_662_950_577;
const C3_D0: f64 = 1.119_528_997_770_346;

/// Writes the `basis_len(degree)` basis values at unit direction `d` into `out`.
pub fn basis<T: Real>(degree: usize, d: [T; 3], out: &mut [T]) {
    let c = T::from_f64;
    let [x, y, z] = d;
    out[0] = c(C0);
    if degree == 0 {
        return;
    }
    out[1] = -c(C1) * y;
    out[2] = c(C1) * z;
    out[3] = -c(C1) * x;
    if degree == 1 {
        return;
    }
    let (fc1, fs1) = (x * x - y * y, c(2.0) * x * y);
    out[4] = c(C2_XY) * fs1;
    out[5] = -c(C2_Z) * z * y;
    out[6] = c(C2_ZZ) * z * z - c(C2_0);
    out[7] = -c(C2_Z) * z * x;
    out[8] = c(C2_XY) * fc1;
    if degree == 2 {
        return;
    }
    let (fc2, fs2) = (x * fc1 - y * fs1, x * fs1 + y * fc1);
    let tmp_c = c(C3_CZ) * z * z + c(C3_C0);
    out[9] = c(C3_A) * fs2;
    out[10] = c(C3_B) * z * fs1;
    out[11] = tmp_c * y;
    out[12] = z * (c(C3_DZ) * z * z - c(C3_D0));
    out[13] = tmp_c * x;
    out[14] = c(C3_B) * z * fc1;
    out[15] = c(C3_A) * fc2;
}

/// The basis of degree ≤ 2 at unit directions `d` [N, 3], as a differentiable tensor [N, (d+1)²]:
/// callers that composite colours as features (several channels in one pass) evaluate the SH
/// themselves and still get gradients through the view direction.
pub fn basis_tensor(
    degree: usize,
    d: burn::tensor::Tensor<2>,
) -> Result<burn::tensor::Tensor<2>, crate::SplatError> {
    use burn::tensor::Tensor;
    if degree > 2 {
        return Err(crate::SplatError::Options(format!(
            "tensor SH basis supports degrees 0 to 2, not {degree}"
        )));
    }
    let col = |k: usize| d.clone().narrow(1, k, 1);
    let (x, y, z) = (col(0), col(1), col(2));
    let mut out = vec![x.ones_like() * C0];
    if degree >= 1 {
        out.extend([y.clone() * -C1, z.clone() * C1, x.clone() * -C1]);
    }
    if degree >= 2 {
        out.extend([
            x.clone() * y.clone() * (2.0 * C2_XY),
            z.clone() * y.clone() * -C2_Z,
            z.clone().square() * C2_ZZ - C2_0,
            z * x.clone() * -C2_Z,
            (x.square() - y.square()) * C2_XY,
        ]);
    }
    Ok(Tensor::cat(out, 1))
}

/// `Σ_k g_k ∇Y_k(d)`: the gradient with respect to `(x, y, z)` of the basis polynomials,
/// contracted with per-basis weights `g` (for colour, `g_k = Σ_c sh_kc · dL/dcolour_c`).
pub fn basis_vjp<T: Real>(degree: usize, d: [T; 3], g: &[T]) -> [T; 3] {
    let c = T::from_f64;
    let [x, y, z] = d;
    let mut v = [T::ZERO; 3];
    if degree == 0 {
        return v;
    }
    v[1] -= c(C1) * g[1];
    v[2] += c(C1) * g[2];
    v[0] -= c(C1) * g[3];
    if degree == 1 {
        return v;
    }
    // Y4 = C2_XY·2xy, Y5 = −C2_Z·zy, Y6 = C2_ZZ·z² − C2_0, Y7 = −C2_Z·zx, Y8 = C2_XY·(x² − y²)
    v[0] += c(2.0 * C2_XY) * y * g[4];
    v[1] += c(2.0 * C2_XY) * x * g[4];
    v[1] -= c(C2_Z) * z * g[5];
    v[2] -= c(C2_Z) * y * g[5];
    v[2] += c(2.0 * C2_ZZ) * z * g[6];
    v[0] -= c(C2_Z) * z * g[7];
    v[2] -= c(C2_Z) * x * g[7];
    v[0] += c(2.0 * C2_XY) * x * g[8];
    v[1] -= c(2.0 * C2_XY) * y * g[8];
    if degree == 2 {
        return v;
    }
    // Y9 = A(3x²y − y³), Y10 = 2B·zxy, Y11 = (Cz·z² + C0)·y, Y12 = Dz·z³ − D0·z,
    // Y13 = (Cz·z² + C0)·x, Y14 = B·z(x² − y²), Y15 = A(x³ − 3xy²)
    let tmp_c = c(C3_CZ) * z * z + c(C3_C0);
    let (xx, yy) = (x * x, y * y);
    v[0] += c(C3_A) * c(6.0) * x * y * g[9];
    v[1] += c(C3_A) * c(3.0) * (xx - yy) * g[9];
    v[0] += c(2.0 * C3_B) * z * y * g[10];
    v[1] += c(2.0 * C3_B) * z * x * g[10];
    v[2] += c(2.0 * C3_B) * x * y * g[10];
    v[1] += tmp_c * g[11];
    v[2] += c(2.0 * C3_CZ) * z * y * g[11];
    v[2] += (c(3.0 * C3_DZ) * z * z - c(C3_D0)) * g[12];
    v[0] += tmp_c * g[13];
    v[2] += c(2.0 * C3_CZ) * z * x * g[13];
    v[0] += c(2.0 * C3_B) * z * x * g[14];
    v[1] -= c(2.0 * C3_B) * z * y * g[14];
    v[2] += c(C3_B) * (xx - yy) * g[14];
    v[0] += c(C3_A) * c(3.0) * (xx - yy) * g[15];
    v[1] -= c(C3_A) * c(6.0) * x * y * g[15];
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numerical integration over the sphere: the basis must be orthonormal (which checks the
    /// constants), up to the sign conventions that only the gsplat fixtures pin down.
    #[test]
    fn basis_is_orthonormal_on_the_sphere() {
        let n = basis_len(3);
        let mut gram = vec![0.0f64; n * n];
        let (nt, np) = (200, 400);
        let mut y = vec![0.0f64; n];
        for i in 0..nt {
            let theta = std::f64::consts::PI * (i as f64 + 0.5) / nt as f64;
            for j in 0..np {
                let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64;
                let d = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
                basis(3, d, &mut y);
                let w = theta.sin()
                    * (std::f64::consts::PI / nt as f64)
                    * (2.0 * std::f64::consts::PI / np as f64);
                for a in 0..n {
                    for b in 0..n {
                        gram[a * n + b] += w * y[a] * y[b];
                    }
                }
            }
        }
        for a in 0..n {
            for b in 0..n {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((gram[a * n + b] - want).abs() < 1e-3, "gram[{a}][{b}] = {}", gram[a * n + b]);
            }
        }
    }

    #[test]
    fn basis_gradient_matches_central_differences() {
        let n = basis_len(3);
        let d = [0.3f64, -0.5, 0.7];
        let g: Vec<f64> = (0..n).map(|k| 0.1 * k as f64 - 0.6).collect();
        let v = basis_vjp(3, d, &g);
        let f = |d: [f64; 3]| {
            let mut y = vec![0.0; n];
            basis(3, d, &mut y);
            y.iter().zip(&g).map(|(a, b)| a * b).sum::<f64>()
        };
        for i in 0..3 {
            let h = 1e-6;
            let (mut p, mut m) = (d, d);
            p[i] += h;
            m[i] -= h;
            let fd = (f(p) - f(m)) / (2.0 * h);
            assert!((fd - v[i]).abs() < 1e-8, "axis {i}: fd {fd} vs {}", v[i]);
        }
    }
}
