//! The signed dihedral angle at a hinge and its exact gradient.
//!
//! Eq. 3.21 takes the arccos of the normals' dot product. Its gradient is singular where the
//! angle is 0 or π (arccos′ = −1/√(1−x²)), which is exactly the flat rest state of most cloth.
//! Here the angle is atan2(sin, cos) of the two normals, which is well conditioned everywhere
//! and signed, and its gradient is the closed form of Bridson et al. 2003 (§4.2): each wing
//! vertex moves along its triangle's normal over its height above the hinge.

use glam::Vec3;

/// A hinge: edge `a`–`b` shared by the triangles (a, b, c) and (a, b, d).
/// Normals n1 = (b−a)×(c−a) and n2 = (d−a)×(b−a) agree on a flat hinge, where the angle is 0;
/// it grows positive as d folds towards n1's side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Hinge {
    pub a: Vec3,
    pub b: Vec3,
    pub c: Vec3,
    pub d: Vec3,
}

impl Hinge {
    fn normals(&self) -> (Vec3, Vec3, Vec3) {
        let e = self.b - self.a;
        (e, e.cross(self.c - self.a), (self.d - self.a).cross(e))
    }

    /// The angle in (−π, π], or `None` when either triangle or the hinge edge is degenerate.
    pub fn angle(&self) -> Option<f32> {
        let (e, n1, n2) = self.normals();
        let len = e.length();
        if len <= f32::MIN_POSITIVE || n1 == Vec3::ZERO || n2 == Vec3::ZERO {
            return None;
        }
        Some(n2.cross(n1).dot(e / len).atan2(n1.dot(n2)))
    }

    /// The angle and its gradient with respect to a, b, c and d.
    pub fn angle_and_gradient(&self) -> Option<(f32, [Vec3; 4])> {
        let angle = self.angle()?;
        let (e, n1, n2) = self.normals();
        let len = e.length();
        let unit = e / len;
        let m1 = n1 / n1.length_squared();
        let m2 = n2 / n2.length_squared();
        let grad_c = len * m1;
        let grad_d = len * m2;
        let grad_a = (self.c - self.b).dot(unit) * m1 + (self.d - self.b).dot(unit) * m2;
        let grad_b = -((self.c - self.a).dot(unit) * m1 + (self.d - self.a).dot(unit) * m2);
        Some((angle, [grad_a, grad_b, grad_c, grad_d]))
    }
}

/// `x` brought into (−π, π], so a constraint pulls the short way round.
pub(crate) fn wrap_angle(x: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    let r = x.rem_euclid(TAU);
    if r > PI { r - TAU } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hinge(c: [f32; 3], d: [f32; 3]) -> Hinge {
        Hinge { a: Vec3::ZERO, b: Vec3::X, c: Vec3::from(c), d: Vec3::from(d) }
    }

    #[test]
    fn flat_is_zero_and_a_right_angle_fold_is_a_quarter_turn() {
        assert_eq!(hinge([0.3, 1.0, 0.0], [0.6, -1.0, 0.0]).angle(), Some(0.0));
        let folded = hinge([0.3, 1.0, 0.0], [0.6, 0.0, 1.0]).angle().unwrap();
        assert!((folded.abs() - std::f32::consts::FRAC_PI_2).abs() < 1e-6, "{folded}");
        let other_way = hinge([0.3, 1.0, 0.0], [0.6, 0.0, -1.0]).angle().unwrap();
        assert!((other_way + folded).abs() < 1e-6, "signed: {folded} vs {other_way}");
    }

    #[test]
    fn the_angle_is_how_far_one_wing_turned_from_flat() {
        for k in 1..12 {
            let fold = k as f32 * 0.25;
            let d = [0.4, -fold.cos(), fold.sin()];
            let got = hinge([0.7, 1.0, 0.0], d).angle().unwrap().abs();
            assert!((got - fold).abs() < 1e-5, "fold {fold}: {got}");
        }
    }

    /// The gradient against central differences of the angle, in f64 around the f32 formula.
    #[test]
    fn the_gradient_matches_finite_differences() {
        let configs = [
            hinge([0.3, 1.0, 0.1], [0.6, -1.0, 0.2]),
            hinge([0.3, 1.0, 0.0], [0.6, 0.2, 1.0]),
            hinge([-0.5, 0.7, 0.4], [1.4, -0.3, -0.9]),
            Hinge {
                a: Vec3::new(0.1, 0.2, -0.3),
                b: Vec3::new(1.1, 0.4, 0.2),
                c: Vec3::new(0.2, 1.3, 0.5),
                d: Vec3::new(0.9, -0.8, 0.1),
            },
        ];
        for h in configs {
            let (_, grad) = h.angle_and_gradient().unwrap();
            let eps = 1e-3f32;
            for (vertex, g) in grad.iter().enumerate() {
                for axis in 0..3 {
                    let shifted = |s: f32| {
                        let mut p = [h.a, h.b, h.c, h.d];
                        p[vertex][axis] += s;
                        let angle = Hinge { a: p[0], b: p[1], c: p[2], d: p[3] }.angle().unwrap();
                        angle as f64
                    };
                    let fd = (shifted(eps) - shifted(-eps)) / (2.0 * eps as f64);
                    let analytic = g.as_dvec3()[axis];
                    assert!(
                        (fd - analytic).abs() < 2e-3,
                        "vertex {vertex} axis {axis}: fd {fd} vs {analytic}"
                    );
                }
            }
        }
    }

    #[test]
    fn wrapping_takes_the_short_way() {
        assert!((wrap_angle(3.0 * std::f32::consts::PI / 2.0) + std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert!((wrap_angle(-0.25) + 0.25).abs() < 1e-7);
    }
}
