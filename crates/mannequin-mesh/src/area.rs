//! Triangle areas in f64, the common ingredient of every discrete operator here.

use glam::{DVec3, Vec3};

/// A face's corner positions promoted to f64, so operators built from f32 meshes stay accurate.
pub(crate) fn corners(positions: &[[f32; 3]], tri: [u32; 3]) -> [DVec3; 3] {
    tri.map(|i| Vec3::from(positions[i as usize]).as_dvec3())
}

/// Twice each face's area (libigl's `doublearea`): the length of the face's cross product,
/// which is what the gradient and mass formulas divide by.
pub fn double_areas(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Vec<f64> {
    faces
        .iter()
        .map(|&t| {
            let [a, b, c] = corners(positions, t);
            (b - a).cross(c - a).length()
        })
        .collect()
}
