//! Normal-map errors, in the two forms the papers use.
//!
//! - `mse_x1e3`: the full-frame mean squared error of the normal maps as unit vectors (zero on
//!   the background), over all pixels and the three components, times 10³ (Tavatar, Table 3).
//! - `angular_deg`: the mean angle in degrees between predicted and ground-truth normals over the
//!   ground-truth foreground; a predicted background pixel there counts as 90°.

use crate::error::DataError;
use crate::maps::NormalMap;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalError {
    pub mse_x1e3: f64,
    pub angular_deg: f64,
}

/// Both error forms; normal maps of different sizes are an error.
pub fn normal_error(pred: &NormalMap, gt: &NormalMap) -> Result<NormalError, DataError> {
    if (pred.width, pred.height) != (gt.width, gt.height) {
        return Err(DataError::Invalid(format!(
            "normal error of maps of different sizes: prediction {}×{}, ground truth {}×{}",
            pred.width, pred.height, gt.width, gt.height
        )));
    }
    let mut sq = 0.0;
    let (mut angle, mut count) = (0.0, 0usize);
    for (p, g) in pred.normals.iter().zip(&gt.normals) {
        sq += (0..3).map(|c| (p[c] as f64 - g[c] as f64).powi(2)).sum::<f64>();
        if *g != [0.0; 3] {
            let (pv, gv) = (glam::DVec3::from(p.map(f64::from)), glam::DVec3::from(g.map(f64::from)));
            let cos = match pv.try_normalize() {
                Some(pn) => pn.dot(gv.normalize()).clamp(-1.0, 1.0),
                None => 0.0,
            };
            angle += cos.acos().to_degrees();
            count += 1;
        }
    }
    Ok(NormalError {
        mse_x1e3: 1e3 * sq / (3 * pred.normals.len()) as f64,
        angular_deg: if count > 0 { angle / count as f64 } else { 0.0 },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_angles_and_squared_errors() {
        let s = std::f32::consts::FRAC_1_SQRT_2;
        let gt = NormalMap {
            width: 4,
            height: 1,
            normals: vec![[0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0; 3]],
        };
        let pred = NormalMap {
            width: 4,
            height: 1,
            normals: vec![[0.0, 0.0, -1.0], [s, 0.0, -s], [0.0; 3], [0.0; 3]],
        };
        let e = normal_error(&pred, &gt).unwrap();
        // Angles 0°, 45°, 90° (missing prediction) over three foreground pixels.
        assert!((e.angular_deg - 45.0).abs() < 1e-5, "{}", e.angular_deg);
        // Squared differences: 0, (s² + (1 − s)²), 1, 0 over 12 components.
        let want = 1e3 * ((s * s + (1.0 - s).powi(2)) as f64 + 1.0) / 12.0;
        assert!((e.mse_x1e3 - want).abs() < 1e-3, "{} vs {want}", e.mse_x1e3);
    }
}
