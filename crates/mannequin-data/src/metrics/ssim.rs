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

/// The Gaussian window applied where it fits: a `w`×`h` plane to its (w − 10)×(h − 10) interior.
fn blur_valid(g: &[f64; TAPS], plane: &[f64], w: usize, h: usize) -> Vec<f64> {
    let (ow, oh) = (w - 2 * RADIUS, h - 2 * RADIUS);
    let mut rows = vec![0.0; h * ow];
    for y in 0..h {
        filter_row(g, &plane[y * w..(y + 1) * w], &mut rows[y * ow..(y + 1) * ow]);
    }
    let mut out = vec![0.0; ow * oh];
    for y in 0..oh {
        for (k, &gk) in g.iter().enumerate() {
            let src = &rows[(y + k) * ow..(y + k + 1) * ow];
            out[y * ow..(y + 1) * ow].iter_mut().zip(src).for_each(|(o, v)| *o += gk * v);
        }
    }
    out
}

/// The transpose of [`blur_valid`]: an interior plane spread back over the `w`×`h` plane.
fn blur_valid_transpose(g: &[f64; TAPS], interior: &[f64], w: usize, h: usize) -> Vec<f64> {
    let (ow, oh) = (w - 2 * RADIUS, h - 2 * RADIUS);
    let mut rows = vec![0.0; h * ow];
    for y in 0..oh {
        for (k, &gk) in g.iter().enumerate() {
            let src = &interior[y * ow..(y + 1) * ow];
            rows[(y + k) * ow..(y + k + 1) * ow].iter_mut().zip(src).for_each(|(o, v)| *o += gk * v);
        }
    }
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for (k, &gk) in g.iter().enumerate() {
            let src = &rows[y * ow..(y + 1) * ow];
            out[y * w + k..y * w + k + ow].iter_mut().zip(src).for_each(|(o, v)| *o += gk * v);
        }
    }
    out
}

/// Mean SSIM of one plane `x` against `y` (`w`×`h`, as [`ssim`] computes each channel), and its
/// gradient with respect to `x`: for a loss on images, such as NGD's on normal maps. Per interior
/// pixel S = A₁A₂ / (B₁B₂) with A₁ = 2μₓμᵧ + C₁, A₂ = 2σₓᵧ + C₂, B₁ = μₓ² + μᵧ² + C₁ and
/// B₂ = σₓ² + σᵧ² + C₂ differentiates in the moments μₓ, E[x²] and E[xy], which the window's
/// transpose carries back to the pixels.
pub fn ssim_plane_with_gradient(
    x: &[f64],
    y: &[f64],
    w: usize,
    h: usize,
) -> Result<(f64, Vec<f64>), DataError> {
    if x.len() != w * h || y.len() != w * h || w < TAPS || h < TAPS {
        return Err(DataError::Invalid(format!(
            "SSIM of planes of {} and {} values as {w}×{h} (at least {TAPS}×{TAPS})",
            x.len(),
            y.len()
        )));
    }
    let g = window();
    let product =
        |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> { x.iter().zip(y).map(|(&a, &b)| f(a, b)).collect() };
    let [mx, my, mxx, myy, mxy] = [
        product(&|a, _| a),
        product(&|_, b| b),
        product(&|a, _| a * a),
        product(&|_, b| b * b),
        product(&|a, b| a * b),
    ]
    .map(|p| blur_valid(&g, &p, w, h));
    let n = mx.len() as f64;
    let (mut total, mut d_mx, mut d_mxx, mut d_mxy) =
        (0.0, vec![0.0; mx.len()], vec![0.0; mx.len()], vec![0.0; mx.len()]);
    for i in 0..mx.len() {
        let (a, b) = (mx[i], my[i]);
        let (vx, vy, vxy) = (mxx[i] - a * a, myy[i] - b * b, mxy[i] - a * b);
        let (a1, a2, b1, b2) = (2.0 * a * b + C1, 2.0 * vxy + C2, a * a + b * b + C1, vx + vy + C2);
        let s = a1 * a2 / (b1 * b2);
        total += s;
        d_mx[i] = s * (2.0 * b / a1 - 2.0 * b / a2 - 2.0 * a / b1 + 2.0 * a / b2) / n;
        d_mxx[i] = -s / b2 / n;
        d_mxy[i] = 2.0 * s / a2 / n;
    }
    let [gx, gxx, gxy] = [d_mx, d_mxx, d_mxy].map(|d| blur_valid_transpose(&g, &d, w, h));
    let gradient = (0..w * h).map(|p| gx[p] + 2.0 * x[p] * gxx[p] + y[p] * gxy[p]).collect();
    Ok((total / n, gradient))
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
        let mut r = mannequin_io::rng::SplitMix64::new(3);
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
        // One plane at a time, the same value.
        let plane =
            |im: &Image, c: usize| -> Vec<f64> { im.pixels.iter().map(|p| f64::from(p[c])).collect() };
        let by_planes: f64 = (0..3)
            .map(|c| ssim_plane_with_gradient(&plane(&a, c), &plane(&b, c), 23, 17).unwrap().0)
            .sum::<f64>()
            / 3.0;
        assert!((by_planes - direct).abs() < 1e-12, "{by_planes} vs {direct}");
    }

    #[test]
    fn plane_gradient_matches_finite_differences() {
        let mut r = mannequin_io::rng::SplitMix64::new(11);
        let (w, h) = (14, 12);
        let x: Vec<f64> = (0..w * h).map(|_| r.uniform()).collect();
        let y: Vec<f64> = x.iter().map(|v| (0.7 * v + 0.2 * r.uniform()).min(1.0)).collect();
        let (_, grad) = ssim_plane_with_gradient(&x, &y, w, h).unwrap();
        for p in (0..w * h).step_by(7) {
            let (mut a, mut b) = (x.clone(), x.clone());
            a[p] += 1e-6;
            b[p] -= 1e-6;
            let numeric = (ssim_plane_with_gradient(&a, &y, w, h).unwrap().0
                - ssim_plane_with_gradient(&b, &y, w, h).unwrap().0)
                / 2e-6;
            assert!((numeric - grad[p]).abs() < 1e-7, "pixel {p}: {numeric} vs {}", grad[p]);
        }
    }
}
