//! Which side of a triangle a vertex is on, or of an edge another edge: the sign of the triple
//! product of four points. The safe step keeps every pair from passing through each
//! other, so the side at the start of a substep is the side the pair belongs on.

use glam::Vec3;

/// The triple product (b − a) × (c − a) · (d − a) of four points.
pub(super) fn volume([a, b, c, d]: [Vec3; 4]) -> f32 {
    (b - a).cross(c - a).dot(d - a)
}
