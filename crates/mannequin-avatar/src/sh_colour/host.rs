//! The forward and backward passes over host slices, one Gaussian at a time (rayon over chunks).

use mannequin_splat::sh::{self, MAX_DEGREE};
use rayon::prelude::*;

use super::ColourConfig;

/// Gaussians per rayon task.
const CHUNK: usize = 1024;

/// The unit direction from the eye to `mean` and the distance.
fn direction(mean: &[f32], eye: [f32; 3]) -> ([f32; 3], f32) {
    let v = [mean[0] - eye[0], mean[1] - eye[1], mean[2] - eye[2]];
    let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (v.map(|x| x / r), r)
}

/// The basis at `d` and the three colours before the clamp.
fn evaluate(d: [f32; 3], coeffs: &[f32], degree: usize) -> ([f32; 16], [f32; 3]) {
    let mut y = [0.0f32; sh::basis_len(MAX_DEGREE)];
    let k = sh::basis_len(degree);
    sh::basis(degree, d, &mut y[..k]);
    let mut rgb = [0.5f32; 3];
    for (yk, c) in y[..k].iter().zip(coeffs.chunks_exact(3)) {
        for ch in 0..3 {
            rgb[ch] += yk * c[ch];
        }
    }
    (y, rgb)
}

pub fn forward(means: &[f32], coeffs: &[f32], config: &ColourConfig) -> Vec<f32> {
    let k3 = 3 * sh::basis_len(config.degree);
    let mut out = vec![0.0f32; means.len()];
    out.par_chunks_mut(3 * CHUNK)
        .zip(means.par_chunks(3 * CHUNK))
        .zip(coeffs.par_chunks(k3 * CHUNK))
        .for_each(|((out, means), coeffs)| {
            for ((o, m), c) in out.chunks_exact_mut(3).zip(means.chunks_exact(3)).zip(coeffs.chunks_exact(k3))
            {
                let (d, _) = direction(m, config.eye);
                let (_, rgb) = evaluate(d, c, config.degree);
                o.copy_from_slice(&rgb.map(|x| x.max(0.0)));
            }
        });
    out
}

/// `(dL/dmeans, dL/dcoeffs)`: the clamp passes the gradient where the colour is positive; the
/// means get it through the view direction, projected off the direction (normalisation).
pub fn backward(means: &[f32], coeffs: &[f32], grad: &[f32], config: &ColourConfig) -> (Vec<f32>, Vec<f32>) {
    let k = sh::basis_len(config.degree);
    let k3 = 3 * k;
    let mut dm = vec![0.0f32; means.len()];
    let mut dc = vec![0.0f32; coeffs.len()];
    dm.par_chunks_mut(3 * CHUNK)
        .zip(dc.par_chunks_mut(k3 * CHUNK))
        .zip(means.par_chunks(3 * CHUNK))
        .zip(coeffs.par_chunks(k3 * CHUNK))
        .zip(grad.par_chunks(3 * CHUNK))
        .for_each(|((((dm, dc), means), coeffs), grad)| {
            let rows = dm
                .chunks_exact_mut(3)
                .zip(dc.chunks_exact_mut(k3))
                .zip(means.chunks_exact(3))
                .zip(coeffs.chunks_exact(k3))
                .zip(grad.chunks_exact(3));
            for ((((dm, dc), m), c), g) in rows {
                let (d, r) = direction(m, config.eye);
                let (y, rgb) = evaluate(d, c, config.degree);
                let g: [f32; 3] = std::array::from_fn(|ch| if rgb[ch] > 0.0 { g[ch] } else { 0.0 });
                let mut per_basis = [0.0f32; sh::basis_len(MAX_DEGREE)];
                for (kk, (dck, ck)) in dc.chunks_exact_mut(3).zip(c.chunks_exact(3)).enumerate() {
                    for ch in 0..3 {
                        dck[ch] = y[kk] * g[ch];
                    }
                    per_basis[kk] = ck[0] * g[0] + ck[1] * g[1] + ck[2] * g[2];
                }
                // d = v/|v|: dL/dv = (dL/dd − d (d·dL/dd)) / |v|.
                let gd = sh::basis_vjp(config.degree, d, &per_basis[..k]);
                let along = gd[0] * d[0] + gd[1] * d[1] + gd[2] * d[2];
                for i in 0..3 {
                    dm[i] = (gd[i] - d[i] * along) / r;
                }
            }
        });
    (dm, dc)
}
