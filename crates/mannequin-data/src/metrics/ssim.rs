//! Structural similarity (Wang et al. 2004, eq. 13) as `skimage.metrics.structural_similarity`
//! computes it with `gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
//! data_range=1` and `torchmetrics`' SSIM with its defaults: an 11-tap Gaussian window, local
//! statistics `μ = G∗x`, `σ² = G∗x² − μ²`, `C1 = 0.01²`, `C2 = 0.03²`, the SSIM map averaged over
//! the pixels whose window lies inside the image (a 5-pixel border is cropped), then over the
//! three channels.

use rayon::prelude::*;

use crate::error::DataError;
use crate::image::Image;

const RADIUS: usize = 5;
const TAPS: usize = 2 * RADIUS + 1;
const SIGMA: f64 = 1.5;
const C1: f64 = 0.01 * 0.01;
const C2: f64 = 0.03 * 0.03;

/// The normalised Gaussian window, `exp(-d²/2σ²)` for d = −5..5.
fn window() -> [f64; TAPS] {
    let w: [f64; TAPS] = std::array::from_fn(|i| {
        let d = i as f64 - RADIUS as f64;
        (-d * d / (2.0 * SIGMA * SIGMA)).exp()
    });
    let sum: f64 = w.iter().sum();
    w.map(|v| v / sum)
}

/// SSIM from the five local moments of one pixel.
fn ssim_at(mx: f64, my: f64, mxx: f64, myy: f64, mxy: f64) -> f64 {
    let (vx, vy, vxy) = (mxx - mx * mx, myy - my * my, mxy - mx * my);
    ((2.0 * mx * my + C1) * (2.0 * vxy + C2)) / ((mx * mx + my * my + C1) * (vx + vy + C2))
}

/// Both images must have one size, with room for the whole window.
fn check(a: &Image, b: &Image) -> Result<(), DataError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(DataError::Invalid(format!(
            "SSIM of images of different sizes: {}×{} and {}×{}",
            a.width, a.height, b.width, b.height
        )));
    }
    if a.width < TAPS || a.height < TAPS {
        return Err(DataError::Invalid(format!(
            "SSIM needs images of at least {TAPS}×{TAPS} pixels (its window), got {}×{}",
            a.width, a.height
        )));
    }
    Ok(())
}

/// `out[x] = Σ_k g[k] · row[x + k]` for every x where the window fits: a row of the separable
/// filter, written as axpy loops so that it vectorises.
fn filter_row(g: &[f64; TAPS], row: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (k, &gk) in g.iter().enumerate() {
        for (o, &v) in out.iter_mut().zip(&row[k..]) {
            *o += gk * v;
        }
    }
}

/// Mean SSIM of two RGB images in [0, 1]: per channel, the five moment planes are filtered
/// separably (rows, then columns), rows in parallel.
pub fn ssim(a: &Image, b: &Image) -> Result<f64, DataError> {
    check(a, b)?;
    let (w, h) = (a.width, a.height);
    let (ow, oh) = (w - 2 * RADIUS, h - 2 * RADIUS);
    let g = window();
    let mut total = 0.0;
    for c in 0..3 {
        // Horizontal pass of x, y, x², y², xy: plane-major, h rows of ow values each.
        let mut horiz = vec![0.0f64; 5 * h * ow];
        horiz.par_chunks_mut(ow).enumerate().for_each(|(r, out)| {
            let (m, y) = (r / h, r % h);
            let src = &a.pixels[y * w..(y + 1) * w];
            let ref_ = &b.pixels[y * w..(y + 1) * w];
            let row: Vec<f64> = src
                .iter()
                .zip(ref_)
                .map(|(p, q)| {
                    let (u, v) = (p[c] as f64, q[c] as f64);
                    [u, v, u * u, v * v, u * v][m]
                })
                .collect();
            filter_row(&g, &row, out);
        });
        // Vertical pass and the SSIM map, summed per output row.
        let sum: f64 = (0..oh)
            .into_par_iter()
            .map(|y| {
                let mut m = [const { Vec::new() }; 5];
                for (plane, acc) in m.iter_mut().enumerate() {
                    *acc = vec![0.0f64; ow];
                    for (k, &gk) in g.iter().enumerate() {
                        let start = (plane * h + y + k) * ow;
                        for (o, &v) in acc.iter_mut().zip(&horiz[start..start + ow]) {
                            *o += gk * v;
                        }
                    }
                }
                (0..ow).map(|x| ssim_at(m[0][x], m[1][x], m[2][x], m[3][x], m[4][x])).sum::<f64>()
            })
            .sum();
        total += sum / (ow * oh) as f64;
    }
    Ok(total / 3.0)
}

/// The same quantity by the definition: a direct 11×11 window per pixel, single-threaded. It is
/// the reference the fast version is tested and benchmarked against.
pub fn ssim_direct(a: &Image, b: &Image) -> Result<f64, DataError> {
    check(a, b)?;
    let (w, h) = (a.width, a.height);
    let g = window();
    let mut total = 0.0;
    for c in 0..3 {
        let mut sum = 0.0;
        for y in RADIUS..h - RADIUS {
            for x in RADIUS..w - RADIUS {
                let mut m = [0.0; 5];
                for dy in 0..TAPS {
                    for dx in 0..TAPS {
                        let gk = g[dy] * g[dx];
                        let p = (y + dy - RADIUS) * w + x + dx - RADIUS;
                        let (u, v) = (a.pixels[p][c] as f64, b.pixels[p][c] as f64);
                        m[0] += gk * u;
                        m[1] += gk * v;
                        m[2] += gk * u * u;
                        m[3] += gk * v * v;
                        m[4] += gk * u * v;
                    }
                }
                sum += ssim_at(m[0], m[1], m[2], m[3], m[4]);
            }
        }
        total += sum / ((w - 2 * RADIUS) * (h - 2 * RADIUS)) as f64;
    }
    Ok(total / 3.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_score_one_and_direct_matches_fast() {
        let mut r = crate::rng::SplitMix64::new(3);
        let a = Image {
            width: 23,
            height: 17,
            pixels: (0..23 * 17).map(|_| [0; 3].map(|_| r.uniform() as f32)).collect(),
        };
        let b = Image {
            width: 23,
            height: 17,
            pixels: a.pixels.iter().map(|p| p.map(|v| (v * 0.8 + 0.1).min(1.0))).collect(),
        };
        assert!((ssim(&a, &a).unwrap() - 1.0).abs() < 1e-12);
        let (fast, direct) = (ssim(&a, &b).unwrap(), ssim_direct(&a, &b).unwrap());
        assert!((fast - direct).abs() < 1e-12, "{fast} vs {direct}");
        assert!(fast < 0.99);
    }
}
