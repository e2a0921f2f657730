//! Layers in rest space: an outer garment worn over an inner one must stand off the body by more
//! than the inner one wherever both cover it, or the two start inside each other and the
//! simulator cannot tell which side each belongs on. Both hang on the same body surface points
//! (rows of I^g), so the fix is a longer offset D^g over the inner garment's cover, which
//! Eq. 3.2 then carries to every body shape; where the inner garment bridges a hollow, its own
//! surface, not its offsets, says how much longer.

use std::collections::HashSet;

use glam::Vec3;
use mannequin_body::BodyModel;
use mannequin_cloth::quality::self_intersections;
use mannequin_mesh::adjacency::one_rings;
use mannequin_mesh::closest_point::ClosestPoint;
use mannequin_mesh::normals::{face_normals, vertex_normals};

use crate::error::GarmentError;
use crate::garment::Garment;

impl Garment {
    /// This garment worn over `inner` (innermost first), all on `model`: wherever an inner
    /// garment covers the body face a vertex hangs on, its offset grows by what it lacks of that
    /// garment's offset there plus `gap`, along the garment's own outward normal; then it is
    /// pushed clear of the inner garments' surfaces ([`Garment::clear_of`]) and kept from
    /// crossing itself ([`Garment::uncrossed`]). A garment made on a model of another topology
    /// is refused.
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
        let normals = vertex_normals(&self.mesh.positions, &self.mesh.faces);
        let offsets = self
            .binding
            .iter()
            .zip(self.offsets.iter().zip(&normals))
            .map(|(point, (d, normal))| {
                let under =
                    body_faces[point.face as usize].iter().map(|&v| cover[v as usize]).fold(0.0, f32::max);
                let d = Vec3::from(*d);
                if under == 0.0 || d.length() >= under + gap {
                    return d.to_array();
                }
                // Along the garment's own normal, outward, so neighbours move alike.
                let n = Vec3::from(*normal);
                let out = if n == Vec3::ZERO { d.normalize_or_zero() } else { n * n.dot(d).signum() };
                (d + (under + gap - d.length()) * out).to_array()
            })
            .collect();
        let offsets = self.clear_of(inner, offsets, gap, model);
        Ok(Garment { offsets: self.uncrossed(offsets), ..self.clone() })
    }

    /// `offsets` pushed on, along the inner garments' normals, wherever a vertex is nearer than
    /// `gap` to their surface or behind it, on the model's template body: where an inner garment
    /// bridges a hollow (the seat between the buttocks), its offsets from the body points around
    /// say little of where its surface is.
    fn clear_of(
        &self,
        inner: &[&Garment],
        mut offsets: Vec<[f32; 3]>,
        gap: f32,
        model: &BodyModel,
    ) -> Vec<[f32; 3]> {
        if inner.is_empty() {
            return offsets;
        }
        let body = (model.v_template.as_slice(), model.faces.as_slice());
        let (mut positions, mut faces, mut away) = (Vec::new(), Vec::new(), Vec::new());
        for g in inner {
            let first = positions.len() as u32;
            positions.extend(g.on_body(body.0, body.1));
            faces.extend(g.mesh.faces.iter().map(|f| f.map(|i| i + first)));
            away.extend(g.offsets.iter().map(|&d| Vec3::from(d)));
        }
        // Each inner face's normal, turned away from the body.
        let normals: Vec<Vec3> = face_normals(&positions, &faces)
            .into_iter()
            .zip(&faces)
            .map(|(n, f)| {
                let n = Vec3::from(n);
                n * n.dot(f.iter().map(|&i| away[i as usize]).sum::<Vec3>()).signum()
            })
            .collect();
        let surface = ClosestPoint::new(&positions, &faces, 2.0 * gap);
        let points: Vec<Vec3> = self.binding.iter().map(|b| b.locate(body.0, body.1)).collect();
        for _ in 0..CLEARING_ROUNDS {
            let mut pushed = false;
            for (point, d) in points.iter().zip(&mut offsets) {
                let p = *point + Vec3::from(*d);
                let Some((on, q)) = surface.query_within(p, CLEARING_REACH * gap) else { continue };
                let (n, apart) = (normals[on.face as usize], p - q);
                let clearance = apart.dot(n);
                if clearance < gap {
                    *d = (Vec3::from(*d) + (gap - clearance) * n).to_array();
                    pushed = true;
                }
            }
            if !pushed {
                break;
            }
        }
        offsets
    }

    /// `offsets` where they do not make the garment cross itself: grown where the garment
    /// passes over a narrow place (the seat between the buttocks), two sides can be pushed past
    /// each other, and a garment that starts crossed cannot be simulated with its contacts. The
    /// growth of each vertex of a pair crossed anew is smoothed, the mean of its own and its
    /// neighbours', until none is.
    fn uncrossed(&self, mut offsets: Vec<[f32; 3]>) -> Vec<[f32; 3]> {
        let faces = &self.mesh.faces;
        let own = |v: usize| Vec3::from(self.offsets[v]);
        let at = |offsets: &[[f32; 3]]| -> Vec<[f32; 3]> {
            let moved = self.mesh.positions.iter().zip(offsets).enumerate();
            moved.map(|(v, (p, d))| (Vec3::from(*p) + Vec3::from(*d) - own(v)).to_array()).collect()
        };
        let rings = one_rings(self.vertex_count(), faces);
        let before: HashSet<[usize; 2]> =
            self_intersections(&self.mesh.positions, faces).into_iter().collect();
        for _ in 0..UNCROSSING_ROUNDS {
            let crossed: HashSet<u32> = self_intersections(&at(&offsets), faces)
                .into_iter()
                .filter(|p| !before.contains(p))
                .flat_map(|[f, g]| faces[f].into_iter().chain(faces[g]))
                .collect();
            if crossed.is_empty() {
                break;
            }
            let growth = |v: usize| Vec3::from(offsets[v]) - own(v);
            let smoothed: Vec<(usize, Vec3)> = crossed
                .iter()
                .map(|&v| {
                    let ring = &rings[v as usize];
                    let sum = ring.iter().map(|&w| growth(w as usize)).sum::<Vec3>() + growth(v as usize);
                    (v as usize, sum / (ring.len() + 1) as f32)
                })
                .collect();
            for (v, g) in smoothed {
                offsets[v] = (own(v) + g).to_array();
            }
        }
        offsets
    }
}

/// Rounds of pushing vertices clear of the inner garments: a push can bring a vertex near
/// another part of them.
const CLEARING_ROUNDS: usize = 4;
/// Vertices farther than this many gaps from an inner garment are beside it, not over it.
const CLEARING_REACH: f32 = 3.0;

/// Rounds of smoothing the growth of vertices that cross: each round's may bring neighbours
/// into a crossing.
const UNCROSSING_ROUNDS: usize = 16;

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
