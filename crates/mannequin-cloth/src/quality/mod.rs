//! Quality measures of a simulated frame, written apart from the solver's own collision code so
//! they can judge it: cloth vertices inside the body, intersecting cloth triangles (by exact
//! predicates), and edge strain.

mod exact;
mod inside;
mod self_intersection;
mod separating_axis;
mod strain;
mod triangle_intersection;

pub use self_intersection::{crossing_pairs, pair_place, self_intersecting_pairs, self_intersections};
pub use strain::{edge_strain, stretch_quantile};

/// How many cloth vertices lie inside the closed body mesh (`body_positions`, `body_faces`).
pub fn vertices_inside_body(
    cloth_positions: &[[f32; 3]],
    body_positions: &[[f32; 3]],
    body_faces: &[[u32; 3]],
) -> usize {
    inside::count_inside(cloth_positions, body_positions, body_faces)
}
