//! Layers in rest space: an outer garment worn over an inner one must stand off the body by more
//! than the inner one wherever both cover it, or the two start inside each other and the
//! simulator cannot tell which side each belongs on. Both hang on the same body surface points
//! (rows of I^g), so the fix is a longer offset D^g over the inner garment's cover, which
//! Eq. 3.2 then carries to every body shape.

use glam::Vec3;

use crate::garment::Garment;

impl Garment {
    /// This garment worn over `inner` (all on the same body model, innermost first): wherever an
    /// inner garment covers the body face a vertex hangs on, its offset grows to at least that
    /// garment's offset there plus `gap`, along the same direction.
    pub fn over(&self, inner: &[&Garment], gap: f32, body_faces: &[[u32; 3]]) -> Garment {
        // Per body vertex, the largest offset of any inner garment hanging on a face around it.
        let body_vertices = body_faces.iter().flatten().map(|&v| v as usize + 1).max().unwrap_or(0);
        let mut cover = vec![0.0f32; body_vertices];
        for g in inner {
            for (point, d) in g.binding.iter().zip(&g.offsets) {
                let length = Vec3::from(*d).length();
                for v in body_faces[point.face as usize] {
                    cover[v as usize] = cover[v as usize].max(length);
                }
            }
        }
        let offsets = self
            .binding
            .iter()
            .zip(&self.offsets)
            .map(|(point, d)| {
                let under =
                    body_faces[point.face as usize].iter().map(|&v| cover[v as usize]).fold(0.0, f32::max);
                let d = Vec3::from(*d);
                if under == 0.0 || d.length() >= under + gap {
                    return d.to_array();
                }
                (d.normalize_or_zero() * (under + gap)).to_array()
            })
            .collect();
        Garment { offsets, ..self.clone() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Category, Fit, Recipe};
    use mannequin_mesh::{SurfacePoint, TriMesh};

    fn hanging(faces_hung: &[u32], offset: f32) -> Garment {
        let recipe = Recipe {
            category: Category::Tshirt,
            fit: Fit::size("M").unwrap(),
            edge_length: 0.015,
            material: "cotton".into(),
            body: "test".into(),
            betas: vec![],
            body_vertices: 4,
            body_faces: 2,
        };
        let n = faces_hung.len();
        Garment {
            recipe,
            mesh: TriMesh::new(vec![[0.0; 3]; n], vec![]),
            binding: faces_hung.iter().map(|&f| SurfacePoint { face: f, bary: [1.0 / 3.0; 3] }).collect(),
            offsets: vec![[0.0, 0.0, offset]; n],
        }
    }

    /// Two body faces sharing an edge, an inner garment on the first 2 cm out: an outer vertex on
    /// either face (they share corners) moves to 2 cm + gap; one already farther keeps its place;
    /// on a body far from the inner garment's faces nothing moves.
    #[test]
    fn outer_offsets_clear_the_inner_garment() {
        let body_faces = [[0, 1, 2], [0, 2, 3], [4, 5, 6]];
        let inner = hanging(&[0], 0.02);
        let outer = hanging(&[0, 1, 1, 2], 0.01);
        let mut outer_far = outer.clone();
        outer_far.offsets[2] = [0.0, 0.0, 0.05];
        let layered = outer_far.over(&[&inner], 0.005, &body_faces);
        let z: Vec<f32> = layered.offsets.iter().map(|d| d[2]).collect();
        assert!((z[0] - 0.025).abs() < 1e-7 && (z[1] - 0.025).abs() < 1e-7, "{z:?}");
        assert_eq!(z[2], 0.05);
        assert_eq!(z[3], 0.01);
    }
}
