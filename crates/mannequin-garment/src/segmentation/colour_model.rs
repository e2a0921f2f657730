//! A class's colours as a smoothed histogram over RGB: the garments print patterns of two or more
//! colours, which one Gaussian would blur into a colour they do not show.

/// Bins per channel.
const BINS: usize = 16;
/// Counts added to every bin before normalising, as a share of the mean bin: colours never seen
/// are unlikely, not impossible.
const FLOOR: f64 = 0.05;

#[derive(Debug, Clone)]
pub struct ColourModel {
    counts: Vec<f64>,
    log_density: Vec<f32>,
}

impl Default for ColourModel {
    fn default() -> Self {
        Self { counts: vec![0.0; BINS * BINS * BINS], log_density: vec![0.0; BINS * BINS * BINS] }
    }
}

fn bin(rgb: [f32; 3]) -> usize {
    let b = rgb.map(|c| ((c.clamp(0.0, 1.0) * BINS as f32) as usize).min(BINS - 1));
    (b[0] * BINS + b[1]) * BINS + b[2]
}

impl ColourModel {
    pub fn add(&mut self, rgb: [f32; 3], weight: f64) {
        self.counts[bin(rgb)] += weight;
    }

    pub fn merge(&mut self, other: &ColourModel) {
        self.counts.iter_mut().zip(&other.counts).for_each(|(a, b)| *a += b);
    }

    /// Blurs the counts over neighbouring bins (shading moves a colour by a bin or two) and
    /// makes the log densities [`ColourModel::log_likelihood`] reads.
    pub fn finish(&mut self) {
        let blurred = blur(&self.counts);
        let total: f64 = blurred.iter().sum();
        let floor = FLOOR * total.max(1.0) / blurred.len() as f64;
        let norm = total + floor * blurred.len() as f64;
        self.log_density =
            blurred.iter().map(|&c| (((c + floor) / norm) * blurred.len() as f64).ln() as f32).collect();
    }

    /// Log of the colour's density relative to a uniform one.
    pub fn log_likelihood(&self, rgb: [f32; 3]) -> f32 {
        self.log_density[bin(rgb)]
    }

    /// Bhattacharyya coefficient of the two colour distributions: 1 when they are the same.
    pub fn overlap(&self, other: &ColourModel) -> f64 {
        let (a, b) = (blur(&self.counts), blur(&other.counts));
        let (sa, sb) = (a.iter().sum::<f64>().max(1e-12), b.iter().sum::<f64>().max(1e-12));
        a.iter().zip(&b).map(|(x, y)| (x / sa * y / sb).sqrt()).sum()
    }
}

/// A [1 2 1]/4 blur along each of the three axes.
fn blur(counts: &[f64]) -> Vec<f64> {
    let mut a = counts.to_vec();
    for stride in [BINS * BINS, BINS, 1] {
        let b = a.clone();
        for (i, out) in a.iter_mut().enumerate() {
            let k = (i / stride) % BINS;
            let lo = if k > 0 { b[i - stride] } else { b[i] };
            let hi = if k + 1 < BINS { b[i + stride] } else { b[i] };
            *out = 0.25 * lo + 0.5 * b[i] + 0.25 * hi;
        }
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_seen_colour_is_likelier_than_an_unseen_one() {
        let mut m = ColourModel::default();
        for _ in 0..100 {
            m.add([0.8, 0.1, 0.1], 1.0);
        }
        m.finish();
        assert!(m.log_likelihood([0.8, 0.1, 0.1]) > m.log_likelihood([0.1, 0.1, 0.8]) + 3.0);
    }

    #[test]
    fn overlap_is_one_for_the_same_colours_and_near_zero_for_others() {
        let (mut a, mut b) = (ColourModel::default(), ColourModel::default());
        a.add([0.2, 0.6, 0.2], 5.0);
        b.add([0.2, 0.6, 0.2], 2.0);
        assert!((a.overlap(&b) - 1.0).abs() < 1e-9);
        let mut c = ColourModel::default();
        c.add([0.9, 0.1, 0.9], 1.0);
        assert!(a.overlap(&c) < 1e-6);
    }
}
