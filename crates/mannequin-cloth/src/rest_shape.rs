//! The shape a cloth pulls back to. A garment cut from a surface rests in that surface's shape.
//! A garment sewn from a pattern rests flat, each triangle as it lies on its panel (Marvelous
//! Designer's model), so a panel placed stretched around a body, or across a seam, pulls back to
//! the pattern's lengths, and its folds are bends away from flat.

use glam::Vec3;
use mannequin_mesh::{TriMesh, UvLayout};

use crate::constraint_graph::ConstraintGraph;
use crate::dihedral::Hinge;
use crate::error::ClothError;

/// Per face, its three corners at rest; `flat` when they come from a pattern, whose hinges then
/// rest at angle 0.
pub(crate) struct RestShape {
    corners: Vec<[Vec3; 3]>,
    flat: bool,
}

/// A hinge at rest: its angle, the area of its two triangles and its edge's squared length.
pub(crate) struct HingeRest {
    pub angle: f32,
    pub areas: f32,
    pub edge_squared: f32,
}

impl RestShape {
    pub fn of_mesh(mesh: &TriMesh) -> Self {
        let at = |i: u32| Vec3::from(mesh.positions[i as usize]);
        Self { corners: mesh.faces.iter().map(|tri| tri.map(at)).collect(), flat: false }
    }

    /// The pattern `layout`: per face of `mesh`, its corners' places on their panel, in metres.
    pub fn of_pattern(mesh: &TriMesh, layout: &UvLayout) -> Result<Self, ClothError> {
        if layout.faces.len() != mesh.faces.len() {
            return Err(ClothError::invalid(
                "pattern.faces",
                format!("{} faces for a garment of {}", layout.faces.len(), mesh.faces.len()),
            ));
        }
        let mut corners = Vec::with_capacity(layout.faces.len());
        for (face, tri) in layout.faces.iter().enumerate() {
            let mut c = [Vec3::ZERO; 3];
            for (k, &i) in tri.iter().enumerate() {
                let Some(&[u, v]) = layout.coords.get(i as usize) else {
                    return Err(ClothError::invalid(
                        "pattern.faces",
                        format!("faces[{face}] names coordinate {i} of {}", layout.coords.len()),
                    ));
                };
                if !(u.is_finite() && v.is_finite()) {
                    return Err(ClothError::NonFiniteInput { field: "pattern.coords", index: i as usize });
                }
                c[k] = Vec3::new(u, v, 0.0);
            }
            if (c[1] - c[0]).cross(c[2] - c[0]).length_squared() <= f32::MIN_POSITIVE {
                return Err(ClothError::invalid("pattern.faces", format!("faces[{face}] has no area")));
            }
            corners.push(c);
        }
        Ok(Self { corners, flat: true })
    }

    /// Each vertex's share of the mass: a third of each of its triangles' area × `density`.
    pub fn masses(&self, faces: &[[u32; 3]], particles: usize, density: f32) -> Vec<f32> {
        let mut mass = vec![0.0f32; particles];
        for (tri, c) in faces.iter().zip(&self.corners) {
            let third = area(c) / 3.0 * density;
            for &i in tri {
                mass[i as usize] += third;
            }
        }
        mass
    }

    /// Each edge's rest length, the mean over the faces on its sides (which agree unless a seam
    /// joins panel edges of different lengths).
    pub fn edge_lengths(&self, faces: &[[u32; 3]], graph: &ConstraintGraph) -> Vec<f32> {
        graph
            .edges
            .iter()
            .zip(&graph.edge_faces)
            .map(|(&edge, sides)| {
                0.5 * sides.iter().map(|&f| self.edge(faces, f, edge).length()).sum::<f32>()
            })
            .collect()
    }

    pub fn hinges(&self, faces: &[[u32; 3]], graph: &ConstraintGraph) -> Vec<HingeRest> {
        graph
            .hinges
            .iter()
            .zip(&graph.hinge_faces)
            .map(|(&[a, b, c, d], &[f, g])| {
                let angle = if self.flat {
                    0.0
                } else {
                    let (ca, cb) = (self.corner(faces, f, a), self.corner(faces, f, b));
                    let (cc, cd) = (self.corner(faces, f, c), self.corner(faces, g, d));
                    Hinge { a: ca, b: cb, c: cc, d: cd }.angle().unwrap_or(0.0)
                };
                HingeRest {
                    angle,
                    areas: area(&self.corners[f]) + area(&self.corners[g]),
                    edge_squared: self.edge(faces, f, [a, b]).length_squared(),
                }
            })
            .collect()
    }

    /// Vertex `v`'s corner of face `f` at rest.
    fn corner(&self, faces: &[[u32; 3]], f: usize, v: u32) -> Vec3 {
        let k = faces[f].iter().position(|&i| i == v).unwrap_or(0);
        self.corners[f][k]
    }

    fn edge(&self, faces: &[[u32; 3]], f: usize, [a, b]: [u32; 2]) -> Vec3 {
        self.corner(faces, f, b) - self.corner(faces, f, a)
    }
}

fn area([a, b, c]: &[Vec3; 3]) -> f32 {
    0.5 * (*b - *a).cross(*c - *a).length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraint_graph::constraint_graph;

    /// A quad folded 90° about its diagonal: sewn from a flat pattern twice its size, its edges
    /// take the pattern's lengths and its hinge rests flat; cut from the folded mesh, the hinge
    /// rests folded.
    #[test]
    fn a_pattern_gives_its_lengths_and_rests_flat() {
        // A quad folded 90° about its diagonal 1–2, and its unfolded pattern.
        let mesh = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            vec![[0, 1, 2], [2, 1, 3]],
        );
        let layout = UvLayout {
            coords: vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [2.0, 2.0]],
            faces: vec![[0, 1, 2], [2, 1, 3]],
        };
        let t = constraint_graph(&mesh.faces).unwrap();
        let sewn = RestShape::of_pattern(&mesh, &layout).unwrap();
        let lengths = sewn.edge_lengths(&mesh.faces, &t);
        // Edges [0,1], [0,2], [1,2], [1,3], [2,3] at the pattern's scale.
        let diagonal = 8f32.sqrt();
        for (got, want) in lengths.iter().zip([2.0, 2.0, diagonal, 2.0, 2.0]) {
            assert!((got - want).abs() < 1e-6, "{lengths:?}");
        }
        let hinge = &sewn.hinges(&mesh.faces, &t)[0];
        assert_eq!(hinge.angle, 0.0);
        assert!((hinge.areas - 4.0).abs() < 1e-6 && (hinge.edge_squared - 8.0).abs() < 1e-5);
        assert_eq!(sewn.masses(&mesh.faces, 4, 3.0), vec![2.0, 4.0, 4.0, 2.0]);
        let cut = RestShape::of_mesh(&mesh).hinges(&mesh.faces, &t);
        assert!(cut[0].angle.abs() > 0.5, "the folded mesh rests folded: {}", cut[0].angle);
    }

    #[test]
    fn a_pattern_with_a_flat_triangle_is_refused() {
        let mesh = TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
        let layout = UvLayout { coords: vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], faces: vec![[0, 1, 2]] };
        let e = RestShape::of_pattern(&mesh, &layout).err().unwrap();
        assert_eq!(e.to_string(), "pattern.faces: faces[0] has no area");
    }
}
