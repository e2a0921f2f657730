//! The image losses of NGD §3.4 on one rendered frame, with their gradients with respect to the
//! rendered image:
//! - **mask**: the mean squared difference between the rendered garment mask and the label map's,
//!   over the pixels that count (hands left out, Eq. 13);
//! - **normals**: the Huber loss of the rendered camera-space normal against the normal map's,
//!   over the pixels that are the garment both in the label map and fully in the render (a
//!   silhouette pixel's normal is blended with whatever lies behind it).

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
}

/// The weighted losses of `image` against `target`, and the gradient of `mask + normal_weight ·
/// normal` with respect to each pixel's channels.
pub fn image_loss(
    image: &[[f64; CHANNELS]],
    target: &Target,
    normal_weight: f64,
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
    let Some(normals) = target.normals.as_ref().filter(|_| normal_weight > 0.0) else {
        return (parts, grad);
    };
    let on_garment = |i: usize| {
        target.counts[i] && target.mask[i] > 0.5 && image[i][0] >= COVERED && normals[i] != [0.0; 3]
    };
    let pixels: Vec<usize> = (0..image.len()).filter(|&i| on_garment(i)).collect();
    let n = pixels.len().max(1) as f64;
    for i in pixels {
        for c in 0..3 {
            let x = image[i][c + 1] - normals[i][c];
            let (value, slope) = if x.abs() <= HUBER_DELTA {
                (0.5 * x * x, x)
            } else {
                (HUBER_DELTA * (x.abs() - 0.5 * HUBER_DELTA), HUBER_DELTA * x.signum())
            };
            parts.normal += value / n;
            grad[i][c + 1] = normal_weight * slope / n;
        }
    }
    parts.normal *= normal_weight;
    (parts, grad)
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
        let weight = 0.5;
        let total = |im: &[[f64; CHANNELS]]| {
            let (p, _) = image_loss(im, &t, weight);
            p.mask + p.normal
        };
        let (_, grad) = image_loss(&image, &t, weight);
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
}
