//! NGD §3.1's pose encoding: the video's poses θ_i ∈ R^72, centred, projected onto their first k
//! principal components (k = 4 for geometry), each divided by its standard deviation so the
//! network sees inputs of unit scale. Conditioning on this rather than on time lets frames of the
//! same pose seen from different sides agree, and on it rather than on θ itself keeps the network
//! from fitting each frame.

use serde::Serialize;

/// Power-iteration rounds per component.
const ROUNDS: usize = 200;

#[derive(Debug, Clone, Serialize)]
pub struct PoseCode {
    mean: Vec<f64>,
    /// Unit principal directions, largest variance first.
    components: Vec<Vec<f64>>,
    /// Their standard deviations.
    deviations: Vec<f64>,
}

impl PoseCode {
    /// The first `k` principal components of `poses` (each the same length); fewer if the poses
    /// vary in fewer directions.
    pub fn fit(poses: &[Vec<f32>], k: usize) -> Self {
        let d = poses.first().map_or(0, Vec::len);
        let n = poses.len().max(1) as f64;
        let mean: Vec<f64> = (0..d).map(|j| poses.iter().map(|p| f64::from(p[j])).sum::<f64>() / n).collect();
        let centred: Vec<Vec<f64>> =
            poses.iter().map(|p| p.iter().zip(&mean).map(|(&x, m)| f64::from(x) - m).collect()).collect();
        let mut covariance = vec![vec![0.0; d]; d];
        for p in &centred {
            for i in 0..d {
                for j in 0..d {
                    covariance[i][j] += p[i] * p[j] / n;
                }
            }
        }
        let (mut components, mut deviations): (Vec<Vec<f64>>, Vec<f64>) = (Vec::new(), Vec::new());
        for c in 0..k.min(d) {
            // Power iteration from a fixed start, on the covariance deflated by the found ones.
            let mut v: Vec<f64> = (0..d).map(|j| 1.0 + ((j * 7 + c * 13) % 5) as f64 * 0.1).collect();
            let mut value = 0.0;
            for _ in 0..ROUNDS {
                let mut w: Vec<f64> = (0..d).map(|i| (0..d).map(|j| covariance[i][j] * v[j]).sum()).collect();
                for (u, s) in components.iter().zip(&deviations) {
                    let along: f64 = (0..d).map(|j| u[j] * v[j]).sum::<f64>() * s * s;
                    w.iter_mut().zip(u).for_each(|(x, ui)| *x -= along * ui);
                }
                value = w.iter().map(|x| x * x).sum::<f64>().sqrt();
                if value == 0.0 {
                    break;
                }
                v = w.into_iter().map(|x| x / value).collect();
            }
            if value <= 1e-12 {
                break;
            }
            components.push(v);
            deviations.push(value.sqrt());
        }
        Self { mean, components, deviations }
    }

    /// The code's length.
    pub fn len(&self) -> usize {
        self.components.len()
    }

    /// γ(θ): θ's whitened coordinates along the components.
    pub fn encode(&self, pose: &[f32]) -> Vec<f32> {
        self.components
            .iter()
            .zip(&self.deviations)
            .map(|(u, s)| {
                let along: f64 = u
                    .iter()
                    .zip(pose.iter().zip(&self.mean))
                    .map(|(a, (&x, m))| a * (f64::from(x) - m))
                    .sum();
                (along / s) as f32
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Poses spread along two known orthogonal directions with deviations 3 and 1 (plus a
    /// constant offset): the code finds them in order, whitened.
    #[test]
    fn finds_known_directions() {
        let d = 6;
        let u = [0.6, 0.8, 0.0, 0.0, 0.0, 0.0];
        let w = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
        let samples = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)];
        let poses: Vec<Vec<f32>> = samples
            .iter()
            .map(|&(a, b)| (0..d).map(|j| (0.5 + 3.0 * a * u[j] + b * w[j]) as f32).collect())
            .collect();
        let code = PoseCode::fit(&poses, 4);
        assert_eq!(code.len(), 2, "only two directions vary");
        assert!((code.deviations[0] - 3.0).abs() < 1e-6 && (code.deviations[1] - 1.0).abs() < 1e-6);
        assert!(
            (code.components[0].iter().zip(&u).map(|(a, b)| a * b).sum::<f64>().abs() - 1.0).abs() < 1e-6
        );
        let c = code.encode(&poses[3]);
        assert!((c[0].abs() - 1.0).abs() < 1e-5 && (c[1].abs() - 1.0).abs() < 1e-5, "{c:?}");
    }
}
