//! Refuses garments the solver cannot simulate, naming the field at fault: too many vertices or
//! triangles, indices out of range, non-finite positions, zero-area triangles, edges shared by
//! more than two triangles, repeated triangles, flipped neighbours, vertices where the surface
//! pinches (a bowtie), vertices in no triangle, and pins out of range.

use glam::DVec3;
use mannequin_mesh::{MeshError, TriMesh, manifold::check_manifold};

use crate::constraint_graph::{ConstraintGraph, constraint_graph};
use crate::error::ClothError;

/// A triangle is degenerate when its area is below this fraction of its longest edge squared,
/// i.e. when its smallest angle is under about a microradian.
const DEGENERATE_RATIO: f64 = 1e-6;

/// Most vertices of a garment: 20 times a long coat cut at 1.5 cm (about 10,000), and what keeps
/// a file of a few megabytes from asking the solver for gigabytes.
pub const MAX_GARMENT_VERTICES: usize = 200_000;

/// Most triangles of a garment: twice [`MAX_GARMENT_VERTICES`], as a triangle mesh has about
/// twice as many triangles as vertices.
pub const MAX_GARMENT_FACES: usize = 2 * MAX_GARMENT_VERTICES;

/// Refuses a garment mesh the solver cannot simulate: every fault is named with its field and
/// index (a caller prefixes its file).
pub fn check_garment(mesh: &TriMesh) -> Result<(), ClothError> {
    checked_constraint_graph(mesh).map(drop)
}

/// [`check_garment`], giving the constraint graph it built on the way.
pub(crate) fn checked_constraint_graph(mesh: &TriMesh) -> Result<ConstraintGraph, ClothError> {
    let count = mesh.positions.len();
    for (field, n, max) in
        [("positions", count, MAX_GARMENT_VERTICES), ("faces", mesh.faces.len(), MAX_GARMENT_FACES)]
    {
        if n > max {
            return Err(ClothError::invalid(field, format!("{n} entries; expected at most {max}")));
        }
    }
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
    let graph = constraint_graph(&mesh.faces)?;
    check_manifold(&mesh.positions, &mesh.faces).map_err(|e| match e {
        MeshError::NotManifold(reason) => ClothError::invalid("faces", reason),
        other => ClothError::invalid("faces", other.to_string()),
    })?;
    let mut used = vec![false; count];
    mesh.faces.iter().flatten().for_each(|&v| used[v as usize] = true);
    if let Some(v) = used.iter().position(|&u| !u) {
        return Err(ClothError::invalid(
            "positions",
            format!("vertex {v} is in no triangle; expected every vertex in one (a loose point has no mass)"),
        ));
    }
    Ok(graph)
}

/// Refuses pins naming a vertex past the garment's `count`.
pub(crate) fn check_pins(pins: &[u32], count: usize) -> Result<(), ClothError> {
    match pins.iter().enumerate().find(|&(_, &v)| v as usize >= count) {
        Some((index, &vertex)) => Err(ClothError::PinIndex { index, vertex, count }),
        None => Ok(()),
    }
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
        check_garment(&m).unwrap();
        check_pins(&[2], 3).unwrap();
    }

    #[test]
    fn each_fault_names_its_field() {
        let ok = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let cases = [
            (mesh(ok.clone(), vec![]), "faces: the garment has no triangles"),
            (
                mesh(vec![[0.0; 3], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]),
                "positions[1] is not finite",
            ),
            (mesh(ok.clone(), vec![[0, 1, 3]]), "faces[0] refers to vertex 3, but there are 3 vertices"),
            (
                mesh(vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], vec![[0, 1, 2]]),
                "faces[0] is degenerate (zero area)",
            ),
            (mesh(ok, vec![[0, 1, 1]]), "faces[0] is degenerate (zero area)"),
        ];
        for (m, message) in cases {
            assert_eq!(check_garment(&m).unwrap_err().to_string(), message);
        }
        assert_eq!(
            check_pins(&[0, 7], 3).unwrap_err().to_string(),
            "pins[1] = 7 is out of range: the garment has 3 vertices"
        );
    }

    /// Issue 42: a bowtie, a flipped neighbour and a loose vertex were simulated; each is
    /// refused naming the vertex or the faces.
    #[test]
    fn surfaces_the_solver_cannot_hold_are_refused() {
        let square = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let flipped = mesh(square.clone(), vec![[0, 1, 2], [0, 3, 2]]);
        let e = check_garment(&flipped).unwrap_err().to_string();
        assert!(e.starts_with("faces: faces 0 and 1 both run edge 2–0 the same way"), "{e}");
        let mut bowtie = square.clone();
        bowtie.extend([[-1.0, 0.0, 0.0], [-1.0, -1.0, 0.0]]);
        let e = check_garment(&mesh(bowtie, vec![[0, 1, 2], [0, 4, 3]])).unwrap_err().to_string();
        assert!(e.starts_with("faces: vertex 0 joins 2 faces that form more than one fan"), "{e}");
        let e = check_garment(&mesh(square, vec![[0, 1, 2]])).unwrap_err().to_string();
        assert!(e.starts_with("positions: vertex 3 is in no triangle"), "{e}");
        let many = mesh(vec![[0.0; 3]; MAX_GARMENT_VERTICES + 1], vec![[0, 1, 2]]);
        let e = check_garment(&many).unwrap_err().to_string();
        assert_eq!(e, "positions: 200001 entries; expected at most 200000");
    }
}
