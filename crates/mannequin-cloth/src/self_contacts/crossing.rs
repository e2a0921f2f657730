//! When, within a substep, four particles moving in straight lines became coplanar: the root of
//! their triple product, which is cubic in time. A vertex can only have passed through a triangle,
//! or an edge through an edge, at such a moment, so the contacts look there.

use glam::Vec3;

/// Bisection steps: the root is found to 2⁻¹² of the substep.
const STEPS: u32 = 12;

/// The triple product (b − a) × (c − a) · (d − a) of four points.
pub(crate) fn volume([a, b, c, d]: [Vec3; 4]) -> f32 {
    (b - a).cross(c - a).dot(d - a)
}

/// The four points a fraction `t` of the way from `start` to `end`.
pub(crate) fn between(start: [Vec3; 4], end: [Vec3; 4], t: f32) -> [Vec3; 4] {
    [0, 1, 2, 3].map(|k| start[k] + t * (end[k] - start[k]))
}

/// A time in [0, 1] where the volume of points moving from `start` to `end` changes sign, found by
/// bisection; the caller has checked that it has opposite signs at the two ends.
pub(crate) fn coplanar_time(start: [Vec3; 4], end: [Vec3; 4]) -> f32 {
    let first = volume(start).signum();
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..STEPS {
        let mid = 0.5 * (lo + hi);
        if volume(between(start, end, mid)).signum() == first { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertex falling through the plane z = 0 at a steady speed crosses at the time its height
    /// says, whatever the triangle does within its plane.
    #[test]
    fn a_falling_vertex_meets_the_plane_when_its_height_is_zero() {
        let start = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.2, 0.2, 0.3)];
        let end = [
            Vec3::new(0.1, 0.0, 0.0),
            Vec3::new(1.2, 0.1, 0.0),
            Vec3::new(0.0, 1.1, 0.0),
            Vec3::new(0.3, 0.2, -0.1),
        ];
        let t = coplanar_time(start, end);
        assert!((t - 0.75).abs() < 1e-3, "{t}");
    }
}
