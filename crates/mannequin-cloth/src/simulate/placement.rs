//! A garment given to `cloth simulate` must be around the body at rest: one in another unit or
//! placed elsewhere is refused before simulating.

use std::path::Path;

use mannequin_mesh::TriMesh;

use crate::simulate_error::SimulateError;

/// Refuses a garment that is not around the body: half its vertices farther than this from the
/// nearest body vertex at rest (m) means another unit or another placement.
const FAR_FROM_BODY: f32 = 0.15;

/// Refuses `garment` (read from `path`) when half its vertices are over [`FAR_FROM_BODY`] from
/// the `body` vertices at rest.
pub fn check_placement(path: &Path, garment: &TriMesh, body: &[[f32; 3]]) -> Result<(), SimulateError> {
    let mut distances: Vec<f32> = garment
        .positions
        .iter()
        .map(|p| {
            body.iter()
                .map(|b| (0..3).map(|d| (p[d] - b[d]).powi(2)).sum::<f32>())
                .fold(f32::INFINITY, f32::min)
        })
        .map(f32::sqrt)
        .collect();
    distances.sort_by(f32::total_cmp);
    let median = distances[distances.len() / 2];
    if median > FAR_FROM_BODY {
        return Err(SimulateError::invalid(
            path.display().to_string(),
            format!(
                "the garment is far from the body: half its vertices are over {median:.2} m from it at \
                 rest (expected within {FAR_FROM_BODY} m: a garment in metres, modelled around the rest pose)"
            ),
        ));
    }
    Ok(())
}
