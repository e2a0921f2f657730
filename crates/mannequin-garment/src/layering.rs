//! Layers in rest space: an outer garment worn over an inner one must stand off the body by more
//! than the inner one wherever both cover it, or the two start inside each other and the
//! simulator cannot tell which side each belongs on. Both hang on the same body surface points
//! (rows of I^g), so the fix is a longer offset D^g over the inner garment's cover, which
//! Eq. 3.2 then carries to every body shape.

use glam::Vec3;
use mannequin_body::BodyModel;

use crate::error::GarmentError;
use crate::garment::Garment;

impl Garment {
    /// This garment worn over `inner` (innermost first), all on `model`: wherever an inner
    /// garment covers the body face a vertex hangs on, its offset grows to at least that
    /// garment's offset there plus `gap`, along the same direction. A garment made on a model of
    /// another topology is refused.
    pub fn over(&self, inner: &[&Garment], gap: f32, model: &BodyModel) -> Result<Garment, GarmentError> {
        for g in inner.iter().copied().chain([self]) {
            g.check_body(model)?;
        }
        let body_faces = &model.faces;
        // Per body vertex, the largest offset of any inner garment hanging on a face around it.
        let mut cover = vec![0.0f32; model.num_vertices()];
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
        Ok(Garment { offsets, ..self.clone() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Category, Ease, Recipe};
    use mannequin_cloth::Material;
    use mannequin_mesh::{SurfacePoint, TriMesh};

    fn hanging(model: &BodyModel, faces_hung: &[u32], offset: f32) -> Garment {
        let recipe = Recipe {
            category: Category::Tshirt,
            fit: Ease::size("M").unwrap(),
            edge_length: 0.015,
            material: Material::COTTON,
            body: "test".into(),
            betas: vec![],
            body_vertices: model.num_vertices(),
            body_faces: model.faces.len(),
        };
        let n = faces_hung.len();
        Garment {
            recipe,
            mesh: TriMesh::new(vec![[0.0; 3]; n], vec![]),
            binding: faces_hung.iter().map(|&f| SurfacePoint { face: f, bary: [1.0 / 3.0; 3] }).collect(),
            offsets: vec![[0.0, 0.0, offset]; n],
        }
    }

    /// An inner garment on a body face 2 cm out: an outer vertex on that face or on one sharing a
    /// corner with it moves to 2 cm + gap; one already farther keeps its place; one on a face
    /// away from it does not move.
    #[test]
    fn outer_offsets_clear_the_inner_garment() {
        let model = BodyModel::default_body_lod1();
        let first = model.faces[0];
        let shares = |f: &[u32; 3]| f.iter().any(|v| first.contains(v));
        let beside = model.faces.iter().skip(1).position(shares).unwrap() as u32 + 1;
        let away = model.faces.iter().position(|f| !shares(f)).unwrap() as u32;
        let inner = hanging(&model, &[0], 0.02);
        let mut outer = hanging(&model, &[0, beside, beside, away], 0.01);
        outer.offsets[2] = [0.0, 0.0, 0.05];
        let layered = outer.over(&[&inner], 0.005, &model).unwrap();
        let z: Vec<f32> = layered.offsets.iter().map(|d| d[2]).collect();
        assert!((z[0] - 0.025).abs() < 1e-7 && (z[1] - 0.025).abs() < 1e-7, "{z:?}");
        assert_eq!(z[2], 0.05);
        assert_eq!(z[3], 0.01);
    }

    /// Issue 42: a garment made on the default body, worn on the light one, indexed past its
    /// faces and panicked; it is refused naming both models' sizes, inner or outer.
    #[test]
    fn a_garment_of_another_body_is_refused() {
        let (light, default) = (BodyModel::default_body_lod1(), BodyModel::default_body());
        let made_on_default = hanging(&default, &[default.faces.len() as u32 - 1], 0.01);
        let fits = hanging(&light, &[0], 0.01);
        for e in [
            made_on_default.over(&[], 0.005, &light).unwrap_err(),
            fits.over(&[&made_on_default], 0.005, &light).unwrap_err(),
        ] {
            let e = e.to_string();
            let sizes = format!("({} vertices, {} faces)", default.num_vertices(), default.faces.len());
            assert!(e.starts_with("body: the garment was made on 'test' ") && e.contains(&sizes), "{e}");
            assert!(e.contains("make it again on this body"), "{e}");
        }
    }
}
