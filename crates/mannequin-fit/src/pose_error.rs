//! PA-MPJPE, the pose error the fitting literature reports: the mean distance between two
//! bodies' joints once one is moved onto the other by the similarity (rotation, translation,
//! scale) that best aligns them, so neither the camera, the global placement nor the body's
//! size counts, only the articulation.

use glam::DVec3;
use mannequin_body::BodyModel;

use crate::error::FitError;
use crate::rigid_alignment::best_rotation;

/// Mean distance between `a` and `b` once `a` is moved onto `b` by the best similarity;
/// `None` when the points fix no rotation (fewer than three, or all on a line).
pub fn aligned_error(a: &[DVec3], b: &[DVec3]) -> Option<f64> {
    let r = best_rotation(a, b, &vec![1.0; a.len()])?;
    let mean = |p: &[DVec3]| p.iter().copied().sum::<DVec3>() / p.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let num: f64 = a.iter().zip(b).map(|(p, q)| (r * (*p - ma)).dot(*q - mb)).sum();
    let den: f64 = a.iter().map(|p| (*p - ma).length_squared()).sum();
    let s = num / den;
    Some(a.iter().zip(b).map(|(p, q)| (s * (r * (*p - ma)) + mb - *q).length()).sum::<f64>() / a.len() as f64)
}

/// PA-MPJPE (metres) over the model's joints between body `a` and body `b`, each given as
/// (β, 72-value axis-angle pose).
pub fn pa_mpjpe(model: &BodyModel, a: (&[f32], &[f32]), b: (&[f32], &[f32])) -> Result<f64, FitError> {
    let joints = |(betas, pose): (&[f32], &[f32])| -> Result<Vec<DVec3>, FitError> {
        let posed = mannequin_body::forward(model, betas, pose, &[0.0; 3])?;
        Ok(posed.joints.chunks_exact(3).map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)).collect())
    };
    aligned_error(&joints(a)?, &joints(b)?)
        .ok_or_else(|| FitError::Setting("the joints fix no rotation to align them by".into()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    #[test]
    fn a_similar_copy_has_no_error_and_a_moved_point_its_share() {
        let a: Vec<DVec3> =
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]].map(DVec3::from).to_vec();
        let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let b: Vec<DVec3> = a.iter().map(|p| 2.5 * (turn * *p) + DVec3::new(4.0, -1.0, 0.5)).collect();
        assert!(aligned_error(&a, &b).unwrap() < 1e-12);
        assert!(aligned_error(&a[..2], &b[..2]).is_none());
    }

    #[test]
    fn bending_an_elbow_costs_joint_error_and_the_global_turn_none() {
        let model = BodyModel::default_body();
        let betas = vec![0.0; model.num_shape_coeffs()];
        let rest = vec![0.0; 72];
        let mut turned = rest.clone();
        turned[1] = 1.2;
        assert!(pa_mpjpe(&model, (&betas, &rest), (&betas, &turned)).unwrap() < 1e-6);
        let mut bent = rest.clone();
        bent[3 * 18 + 1] = 1.0; // left elbow
        let e = pa_mpjpe(&model, (&betas, &rest), (&betas, &bent)).unwrap();
        assert!(e > 0.005 && e < 0.1, "{e}");
    }
}
