//! How far apart two elements of a pair are at the start of a substep, and along which
//! direction: the line between their closest points. For convex elements (a point, an edge, a
//! triangle) every point of the second lies at least the distance beyond every point of the
//! first along it, so that direction is a separating axis, and it stays one while the moves keep
//! the elements' projections on it apart. This lets the safe step tell a pair pushed apart from
//! one closing in: the spread of its moves alone cannot.

use glam::Vec3;

/// A pair's distance at the start of the substep and the unit direction from the first
/// element's closest point to the second's (zero where they touch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Apart {
    pub distance: f32,
    pub axis: Vec3,
}

impl Apart {
    /// The pair whose closest points are `first` on the first element and `second` on the
    /// second.
    pub fn between(first: Vec3, second: Vec3) -> Self {
        let away = second - first;
        let distance = away.length();
        let axis = if distance > f32::MIN_POSITIVE { away / distance } else { Vec3::ZERO };
        Self { distance, axis }
    }

    /// The gap along the axis between the two elements' points, `ends[..split]` the first's and
    /// `ends[split..]` the second's: the least by which the second's projections exceed the
    /// first's. Positive, the elements are apart; it is at least `distance` at the start.
    pub fn along_axis(&self, ends: [Vec3; 4], split: usize) -> f32 {
        let (first, second) = ends.split_at(split);
        let low = second.iter().map(|x| x.dot(self.axis)).fold(f32::INFINITY, f32::min);
        let high = first.iter().map(|x| x.dot(self.axis)).fold(f32::NEG_INFINITY, f32::max);
        low - high
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertex 2 mm over the middle of a triangle: the axis is the triangle's normal and the
    /// gap along it is the distance; lifted higher, the gap grows; pushed through, it is negative.
    #[test]
    fn the_gap_along_the_axis_of_a_vertex_over_a_triangle() {
        let triangle = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let vertex = Vec3::new(0.25, 0.25, 0.002);
        let apart = Apart::between(Vec3::new(0.25, 0.25, 0.0), vertex);
        assert!((apart.distance - 0.002).abs() < 1e-7 && (apart.axis - Vec3::Z).length() < 1e-6);
        let at = |z: f32| apart.along_axis([triangle[0], triangle[1], triangle[2], vertex.with_z(z)], 3);
        assert!((at(0.002) - 0.002).abs() < 1e-7);
        assert!((at(0.01) - 0.01).abs() < 1e-7);
        assert!(at(-0.001) < 0.0);
    }

    /// Two crossed edges 1 mm apart: every end of the second lies 1 mm beyond every end of the
    /// first along the axis, and a tilt of the second that brings one end lower shows.
    #[test]
    fn the_gap_along_the_axis_of_two_edges() {
        let first = [Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)];
        let second = [Vec3::new(0.0, -1.0, 0.001), Vec3::new(0.0, 1.0, 0.001)];
        let apart = Apart::between(Vec3::ZERO, Vec3::new(0.0, 0.0, 0.001));
        let gap = apart.along_axis([first[0], first[1], second[0], second[1]], 2);
        assert!((gap - 0.001).abs() < 1e-7, "{gap}");
        let tilted = apart.along_axis([first[0], first[1], second[0], Vec3::new(0.0, 1.0, -0.5)], 2);
        assert!((tilted + 0.5).abs() < 1e-6, "{tilted}");
    }
}
