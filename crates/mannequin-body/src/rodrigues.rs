//! Axis-angle to rotation matrix (Rodrigues' formula, thesis §SMPL):
//! R = I + sin‖r‖ K + (1 − cos‖r‖) K², with K the cross-product matrix of r/‖r‖.

use glam::{Mat3, Quat, Vec3};

/// Below this angle the series form is used, so the zero rotation has no 0/0.
const SMALL_ANGLE: f32 = 1e-6;

/// Rotation matrix of the axis-angle vector `r` (radians).
pub fn rodrigues(r: [f32; 3]) -> Mat3 {
    let v = Vec3::from(r);
    let theta = v.length();
    let k = Mat3::from_cols(Vec3::new(0.0, v.z, -v.y), Vec3::new(-v.z, 0.0, v.x), Vec3::new(v.y, -v.x, 0.0));
    // sinθ/θ and (1 − cosθ)/θ² on the unnormalised K, with their Taylor series near zero.
    let (a, b) = if theta < SMALL_ANGLE {
        (1.0 - theta * theta / 6.0, 0.5 - theta * theta / 24.0)
    } else {
        (theta.sin() / theta, (1.0 - theta.cos()) / (theta * theta))
    };
    Mat3::IDENTITY + k * a + k * k * b
}

/// The same rotation as a unit quaternion.
pub fn axis_angle_quat(r: [f32; 3]) -> Quat {
    let v = Vec3::from(r);
    let theta = v.length();
    if theta < SMALL_ANGLE {
        Quat::from_xyzw(0.5 * v.x, 0.5 * v.y, 0.5 * v.z, 1.0).normalize()
    } else {
        Quat::from_axis_angle(v / theta, theta)
    }
}

/// Axis-angle vector of a rotation (inverse of [`rodrigues`] for angles below π).
pub fn quat_axis_angle(q: Quat) -> [f32; 3] {
    let (axis, angle) = q.to_axis_angle();
    (axis * angle).to_array()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_turn_about_z_maps_x_to_y() {
        let r = rodrigues([0.0, 0.0, std::f32::consts::FRAC_PI_2]);
        let y = r * Vec3::X;
        assert!((y - Vec3::Y).length() < 1e-6, "{y}");
    }

    #[test]
    fn matches_quaternion_and_is_orthonormal() {
        for r in [[0.3, -1.2, 0.7], [1e-9, 0.0, 0.0], [0.0, 3.0, 0.1], [-2.0, 0.5, 0.5]] {
            let m = rodrigues(r);
            let q = Mat3::from_quat(axis_angle_quat(r));
            assert!((m - q).abs_diff_eq(Mat3::ZERO, 1e-5), "{r:?}");
            assert!((m * m.transpose()).abs_diff_eq(Mat3::IDENTITY, 1e-5));
            assert!((m.determinant() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn axis_angle_round_trip() {
        let r = [0.4, -0.2, 1.1];
        let back = quat_axis_angle(axis_angle_quat(r));
        for c in 0..3 {
            assert!((back[c] - r[c]).abs() < 1e-5);
        }
    }
}
