//! The image losses of NGD §3.4 on one rendered frame, with their gradients with respect to the
//! rendered image:
//! - **mask**: the mean squared difference between the rendered garment mask and the label map's,
//!   over the pixels that count (hands left out, Eq. 13);
//! - **normals**: the Huber loss of the rendered camera-space normal against the normal map's,
//!   over the pixels that are the garment both in the label map and fully in the render (a
//!   silhouette pixel's normal is blended with whatever lies behind it), plus 1 − SSIM of the two
//!   normal maps on those pixels (each component as ½ n + ½, zero elsewhere), over the box
//!   around them: SSIM compares the local structure (folds), which a per-pixel loss does not see.

use mannequin_data::metrics::ssim::ssim_plane_with_gradient;

use super::scene::CHANNELS;
use super::target::Target;

/// The Huber loss's switch from quadratic to linear, per normal component.
const HUBER_DELTA: f64 = 0.1;
/// A rendered pixel counts for the normal loss when this much of it is the garment.
const COVERED: f64 = 0.999;

#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct LossParts {
    pub mask: f64,
    pub normal: f64,
    pub normal_ssim: f64,
}

/// The normal terms' weights against the mask loss.
#[derive(Debug, Clone, Copy)]
pub struct LossWeights {
    pub normal: f64,
    pub ssim: f64,
}

/// The weighted losses of `image` (`width` pixels a row) against `target`, and the gradient of
/// their sum with respect to each pixel's channels.
pub fn image_loss(
    image: &[[f64; CHANNELS]],
    width: usize,
    target: &Target,
    weights: LossWeights,
) -> (LossParts, Vec<[f64; CHANNELS]>) {
    let mut grad = vec![[0.0; CHANNELS]; image.len()];
    let counted = target.counts.iter().filter(|c| **c).count().max(1) as f64;
    let mut parts = LossParts::default();
    for ((g, r), (m, &c)) in grad.iter_mut().zip(image).zip(target.mask.iter().zip(&target.counts)) {
        if c {
            parts.mask += (r[0] - m).powi(2) / counted;
            g[0] = 2.0 * (r[0] - m) / counted;
        }
    }
    let Some(normals) = target.normals.as_ref().filter(|_| weights.normal > 0.0 || weights.ssim > 0.0) else {
        return (parts, grad);
    };
    let on_garment = |i: usize| {
        target.counts[i] && target.mask[i] > 0.5 && image[i][0] >= COVERED && normals[i] != [0.0; 3]
    };
    let pixels: Vec<usize> = (0..image.len()).filter(|&i| on_garment(i)).collect();
    if weights.ssim > 0.0 {
        parts.normal_ssim = structure(image, width, normals, &pixels, weights.ssim, &mut grad);
    }
    let normal_weight = weights.normal;
    let n = pixels.len().max(1) as f64;
    for i in pixels.iter().copied().filter(|_| normal_weight > 0.0) {
        for c in 0..3 {
            let x = image[i][c + 1] - normals[i][c];
            let (value, slope) = if x.abs() <= HUBER_DELTA {
                (0.5 * x * x, x)
            } else {
                (HUBER_DELTA * (x.abs() - 0.5 * HUBER_DELTA), HUBER_DELTA * x.signum())
            };
            parts.normal += value / n;
            grad[i][c + 1] += normal_weight * slope / n;
        }
    }
    parts.normal *= normal_weight;
    (parts, grad)
}

/// `weight` (1 − mean SSIM) of the rendered and target normal maps on `pixels`, over their box
/// widened by the SSIM window; its gradient is added to `grad`.
fn structure(
    image: &[[f64; CHANNELS]],
    width: usize,
    normals: &[[f64; 3]],
    pixels: &[usize],
    weight: f64,
    grad: &mut [[f64; CHANNELS]],
) -> f64 {
    let height = image.len() / width.max(1);
    let (Some(x0), Some(x1)) =
        (pixels.iter().map(|i| i % width).min(), pixels.iter().map(|i| i % width).max())
    else {
        return 0.0;
    };
    let (y0, y1) = (pixels[0] / width, pixels[pixels.len() - 1] / width);
    let margin = 5;
    let (x0, y0) = (x0.saturating_sub(margin), y0.saturating_sub(margin));
    let (x1, y1) = ((x1 + margin).min(width - 1), (y1 + margin).min(height - 1));
    let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
    let mut inside = vec![false; w * h];
    for &i in pixels {
        inside[(i / width - y0) * w + i % width - x0] = true;
    }
    let at = |k: usize| (y0 + k / w) * width + x0 + k % w;
    let mut loss = 0.0;
    for c in 0..3 {
        let plane = |f: &dyn Fn(usize) -> f64| -> Vec<f64> {
            (0..w * h).map(|k| if inside[k] { 0.5 * f(at(k)) + 0.5 } else { 0.0 }).collect()
        };
        let (x, y) = (plane(&|i| image[i][c + 1]), plane(&|i| normals[i][c]));
        let Ok((ssim, d)) = ssim_plane_with_gradient(&x, &y, w, h) else { return 0.0 };
        loss += weight * (1.0 - ssim) / 3.0;
        for k in (0..w * h).filter(|&k| inside[k]) {
            grad[at(k)][c + 1] -= weight / 3.0 * 0.5 * d[k];
        }
    }
    loss
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target(normals: Vec<[f64; 3]>) -> Target {
        let n = normals.len();
        Target { frame: 0, mask: vec![1.0; n], counts: vec![true; n], normals: Some(normals) }
    }

    #[test]
    fn gradients_match_finite_differences() {
        let t = target(vec![[0.0, 0.0, -1.0], [0.6, 0.0, -0.8], [0.0, 0.0, 0.0]]);
        // Normal errors on both sides of the Huber switch; the last pixel has no normal.
        let image = vec![[1.0, 0.05, 0.02, -0.99], [1.0, 0.2, 0.3, -0.7], [0.7, 0.1, 0.1, 0.1]];
        let weights = LossWeights { normal: 0.5, ssim: 0.0 };
        let total = |im: &[[f64; CHANNELS]]| {
            let (p, _) = image_loss(im, 3, &t, weights);
            p.mask + p.normal
        };
        let (_, grad) = image_loss(&image, 3, &t, weights);
        let h = 1e-6;
        for i in 0..image.len() {
            for c in 0..CHANNELS {
                let (mut a, mut b) = (image.clone(), image.clone());
                a[i][c] += h;
                b[i][c] -= h;
                let numeric = (total(&a) - total(&b)) / (2.0 * h);
                assert!(
                    (numeric - grad[i][c]).abs() < 1e-6,
                    "pixel {i} channel {c}: {numeric} vs {}",
                    grad[i][c]
                );
            }
        }
    }

    /// The SSIM term on a 16×14 image whose garment is a disc with a fold in its normals, with
    /// the Huber term beside it: their gradient against central differences, and no SSIM loss
    /// when the render matches.
    #[test]
    fn structure_gradient_matches_finite_differences() {
        let (w, h) = (16, 14);
        let disc = |i: usize| ((i % w) as f64 - 8.0).powi(2) + ((i / w) as f64 - 7.0).powi(2) < 25.0;
        let fold = |i: usize| {
            let s = ((i % w) as f64 * 0.9).sin() * 0.4;
            [s, 0.1, -(1.0 - s * s - 0.01).sqrt()]
        };
        let normals: Vec<[f64; 3]> = (0..w * h).map(|i| if disc(i) { fold(i) } else { [0.0; 3] }).collect();
        let t = Target {
            frame: 0,
            mask: (0..w * h).map(|i| f64::from(u8::from(disc(i)))).collect(),
            counts: vec![true; w * h],
            normals: Some(normals.clone()),
        };
        let weights = LossWeights { normal: 0.3, ssim: 1.0 };
        let normal_terms = |im: &[[f64; CHANNELS]]| {
            let (p, _) = image_loss(im, w, &t, weights);
            p.normal + p.normal_ssim
        };
        let matching: Vec<[f64; CHANNELS]> = (0..w * h)
            .map(|i| if disc(i) { [1.0, normals[i][0], normals[i][1], normals[i][2]] } else { [0.0; 4] })
            .collect();
        assert!(image_loss(&matching, w, &t, weights).0.normal_ssim.abs() < 1e-12);
        // A render with the fold shifted.
        let image: Vec<[f64; CHANNELS]> = (0..w * h)
            .map(|i| {
                if disc(i) {
                    let n = fold(i + 1);
                    [1.0, n[0], n[1], n[2]]
                } else {
                    [0.0; 4]
                }
            })
            .collect();
        let (parts, grad) = image_loss(&image, w, &t, weights);
        assert!(parts.normal_ssim > 0.01);
        for i in (0..w * h).filter(|&i| disc(i)).step_by(5) {
            for c in 1..CHANNELS {
                let (mut a, mut b) = (image.clone(), image.clone());
                a[i][c] += 1e-6;
                b[i][c] -= 1e-6;
                let numeric = (normal_terms(&a) - normal_terms(&b)) / 2e-6;
                assert!(
                    (numeric - grad[i][c]).abs() < 1e-7,
                    "pixel {i} channel {c}: {numeric} vs {}",
                    grad[i][c]
                );
            }
        }
    }
}
