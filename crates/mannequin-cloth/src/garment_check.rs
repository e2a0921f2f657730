//! Refuses garments the solver cannot simulate, naming the field at fault: indices out of range,
//! non-finite positions, zero-area triangles, and pins out of range. (Edges shared by more than two
//! triangles are found where the edges are listed, in [`crate::topology`].)

use glam::DVec3;
use mannequin_mesh::TriMesh;

use crate::error::ClothError;

/// A triangle is degenerate when its area is below this fraction of its longest edge squared,
/// i.e. when its smallest angle is under about a microradian.
const DEGENERATE_RATIO: f64 = 1e-6;

pub(crate) fn check_garment(mesh: &TriMesh, pins: &[u32]) -> Result<(), ClothError> {
    let count = mesh.positions.len();
    if mesh.faces.is_empty() {
        return Err(ClothError::invalid("faces", "the garment has no triangles"));
    }
    if let Some(index) = mesh.positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(ClothError::NonFiniteInput { field: "positions", index });
    }
    for (face, tri) in mesh.faces.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= count) {
            return Err(ClothError::FaceIndex { face, index, count });
        }
        if is_degenerate(tri.map(|i| DVec3::from(mesh.positions[i as usize].map(f64::from)))) {
            return Err(ClothError::DegenerateFace { face });
        }
    }
    if let Some((index, &vertex)) = pins.iter().enumerate().find(|&(_, &v)| v as usize >= count) {
        return Err(ClothError::PinIndex { index, vertex, count });
    }
    Ok(())
}

fn is_degenerate([a, b, c]: [DVec3; 3]) -> bool {
    let longest = (b - a).length_squared().max((c - a).length_squared()).max((c - b).length_squared());
    (b - a).cross(c - a).length() <= DEGENERATE_RATIO * longest
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(positions: Vec<[f32; 3]>, faces: Vec<[u32; 3]>) -> TriMesh {
        TriMesh::new(positions, faces)
    }

    #[test]
    fn a_good_triangle_passes() {
        let m = mesh(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
        check_garment(&m, &[2]).unwrap();
    }

    #[test]
    fn each_fault_names_its_field() {
        let ok = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let cases = [
            (mesh(ok.clone(), vec![]), &[][..], "faces: the garment has no triangles"),
            (
                mesh(vec![[0.0; 3], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]),
                &[],
                "positions[1] is not finite",
            ),
            (mesh(ok.clone(), vec![[0, 1, 3]]), &[], "faces[0] refers to vertex 3, but there are 3 vertices"),
            (
                mesh(vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], vec![[0, 1, 2]]),
                &[],
                "faces[0] is degenerate (zero area)",
            ),
            (mesh(ok.clone(), vec![[0, 1, 1]]), &[], "faces[0] is degenerate (zero area)"),
            (mesh(ok, vec![[0, 1, 2]]), &[0, 7], "pins[1] = 7 is out of range: the garment has 3 vertices"),
        ];
        for (m, pins, message) in cases {
            assert_eq!(check_garment(&m, pins).unwrap_err().to_string(), message);
        }
    }
}
