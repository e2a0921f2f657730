//! Smoothing out where the ease crosses a garment through itself. Pushing the body's surface out
//! along its normals crosses it wherever a hollow is narrower than twice the ease: between the
//! thighs, pants of size XL started with their two inner legs through each other (25 pairs of
//! triangles), and a crossed cloth cannot be simulated with its contacts. Taking the ease out
//! there does not mend it, as the crossing vertices' nearest body point is already the other
//! thigh's; moving each vertex of a crossing, and two rings around it, to the mean of its
//! neighbours unfolds it, as layering uncrosses its growth.

use glam::Vec3;
use mannequin_cloth::quality::{pair_place, self_intersections};
use mannequin_mesh::adjacency::one_rings;

use crate::error::GarmentError;

/// Rounds of smoothing: pants XL need 5, `--ease-hips 0.04` about 20.
const ROUNDS: usize = 32;
/// How many rings of neighbours around a crossing are smoothed with it, so the fit changes
/// gradually.
const RINGS: usize = 2;

/// Smooths `positions` where `faces` cross until no two do, and says whether it moved any; an
/// error with the count and the place if they still cross after [`ROUNDS`] rounds.
pub(crate) fn smooth_out_crossings(
    positions: &mut [[f32; 3]],
    faces: &[[u32; 3]],
) -> Result<bool, GarmentError> {
    let rings = one_rings(positions.len(), faces);
    for round in 0..ROUNDS {
        let crossed = self_intersections(positions, faces);
        if crossed.is_empty() {
            return Ok(round > 0);
        }
        let mut marked = vec![false; positions.len()];
        let mut front: Vec<u32> = crossed.iter().flatten().flat_map(|&f| faces[f]).collect();
        for ring in 0..=RINGS {
            let mut next = Vec::new();
            for v in front {
                if !std::mem::replace(&mut marked[v as usize], true) && ring < RINGS {
                    next.extend_from_slice(&rings[v as usize]);
                }
            }
            front = next;
        }
        let smoothed: Vec<(usize, Vec3)> = (0..positions.len())
            .filter(|&v| marked[v])
            .map(|v| {
                let sum = rings[v].iter().map(|&w| Vec3::from(positions[w as usize])).sum::<Vec3>();
                (v, sum / rings[v].len() as f32)
            })
            .collect();
        for (v, p) in smoothed {
            positions[v] = p.to_array();
        }
    }
    check_uncrossed(positions, faces, &format!("after {ROUNDS} rounds of smoothing"))?;
    Ok(true)
}

/// An error naming the count and the place of the first crossing pair of `faces`, if any.
pub(crate) fn check_uncrossed(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    when: &str,
) -> Result<(), GarmentError> {
    let crossed = self_intersections(positions, faces);
    let Some(&pair) = crossed.first() else { return Ok(()) };
    let [x, y, z] = pair_place(positions, faces, pair);
    Err(GarmentError::invalid(
        "fit",
        format!(
            "the eased garment crosses itself {when}: pairs of triangles crossing: {}, the \
             first near ({:.3}, {:.3}, {:.3}) m (a smaller ease there may clear it)",
            crossed.len(),
            x,
            y,
            z
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle in the floor pierced by an upright one: refused with the count and the place
    /// (the mean of their six corners); the floor alone passes.
    #[test]
    fn a_crossed_garment_is_refused_with_count_and_place() {
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.2, -0.5, 0.2],
            [0.2, 0.5, 0.2],
            [0.8, 0.5, 0.8],
        ];
        let message =
            check_uncrossed(&positions, &[[0, 1, 2], [3, 4, 5]], "at rest").unwrap_err().to_string();
        assert!(message.contains("crosses itself at rest: pairs of triangles crossing: 1"), "{message}");
        assert!(message.contains("near (0.367, 0.083, 0.367) m"), "{message}");
        assert!(check_uncrossed(&positions, &[[0, 1, 2]], "at rest").is_ok());
    }
}
