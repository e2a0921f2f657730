//! A garment template: its mesh on the body it was made for, and how each vertex hangs on that
//! body, as the thesis's Eq. 3.1 writes it: G^g = I^g T(β^g, 0) + D^g. Row i of the indicator
//! I^g is a point of the body surface (a face and barycentric weights: the MakeHuman clothing
//! form of MGN's vertex selection), and D^g the offset from it.

use glam::Vec3;
use mannequin_body::BodyModel;
use mannequin_cloth::Material;
use mannequin_mesh::{ClosestPoint, SurfacePoint, TriMesh, UvLayout};
use serde::{Deserialize, Serialize};

use crate::category::Category;
use crate::ease::Ease;
use crate::error::GarmentError;

/// How the template was made: enough to make it again on another body model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Recipe {
    pub category: Category,
    pub fit: Ease,
    /// Target edge length of the remeshed garment (m).
    pub edge_length: f32,
    /// The cloth it is made of (stored by name; a name the simulator does not know is refused
    /// when the recipe is read).
    pub material: Material,
    /// The body model the template hangs on (`default`, or a model file's name) and its shape.
    pub body: String,
    pub betas: Vec<f32>,
    /// The body model's vertex and face counts: a template is refused on another model.
    pub body_vertices: usize,
    pub body_faces: usize,
}

/// Target edge lengths a template is made at (m): under 5 mm a long coat passes the simulator's
/// [`mannequin_cloth::MAX_GARMENT_FACES`]; over 10 cm a sleeve is a few triangles round.
pub const EDGE_LENGTH_RANGE: std::ops::RangeInclusive<f32> = 0.005..=0.1;

impl Recipe {
    /// Refuses what [`crate::make_garment`] never makes: a fit out of range, an edge length
    /// outside [`EDGE_LENGTH_RANGE`], shape coefficients that are not numbers, or a body model
    /// with no faces. (A material the cloth simulator does not know is refused as it is read.)
    pub fn validate(&self) -> Result<(), GarmentError> {
        self.fit.validate()?;
        check_edge_length(self.edge_length)?;
        if let Some(i) = self.betas.iter().position(|b| !b.is_finite()) {
            return Err(GarmentError::invalid("betas", format!("coefficient {i} is {}", self.betas[i])));
        }
        if self.body_vertices < 3 || self.body_faces == 0 {
            return Err(GarmentError::invalid(
                "body_vertices",
                format!(
                    "{} vertices and {} faces; expected a body model's (at least 3 and 1)",
                    self.body_vertices, self.body_faces
                ),
            ));
        }
        Ok(())
    }
}

/// Refuses an edge length outside [`EDGE_LENGTH_RANGE`].
pub(crate) fn check_edge_length(edge_length: f32) -> Result<(), GarmentError> {
    if EDGE_LENGTH_RANGE.contains(&edge_length) {
        return Ok(());
    }
    Err(GarmentError::invalid(
        "edge_length",
        format!("{edge_length} m; expected {} to {} m", EDGE_LENGTH_RANGE.start(), EDGE_LENGTH_RANGE.end()),
    ))
}

#[derive(Debug, Clone, PartialEq)]
pub struct Garment {
    pub recipe: Recipe,
    /// G^g: the garment at rest on the template body, with its faces and UVs.
    pub mesh: TriMesh,
    /// I^g: per garment vertex, its point on the template body's surface.
    pub binding: Vec<SurfacePoint>,
    /// D^g (Eq. 3.1), per garment vertex.
    pub offsets: Vec<[f32; 3]>,
}

impl Garment {
    /// Binds each vertex of `mesh` (the garment on a body at rest) to its closest point of that
    /// body's surface, found through `body`, and stores the rest as offsets: Eq. 3.1.
    pub fn bind(recipe: Recipe, mesh: TriMesh, body: &ClosestPoint) -> Garment {
        let (binding, offsets) = mesh
            .positions
            .iter()
            .map(|&g| {
                let g = Vec3::from(g);
                let (point, on_body) =
                    body.query(g).unwrap_or((SurfacePoint { face: 0, bary: [1.0, 0.0, 0.0] }, g));
                (point, (g - on_body).to_array())
            })
            .unzip();
        Garment { recipe, mesh, binding, offsets }
    }

    /// Eq. 3.2 at one body state: I^g T + D^g, with T the body's vertices (rest or pose-corrected).
    pub fn on_body(&self, body: &[[f32; 3]], body_faces: &[[u32; 3]]) -> Vec<[f32; 3]> {
        self.binding
            .iter()
            .zip(&self.offsets)
            .map(|(point, d)| (point.locate(body, body_faces) + Vec3::from(*d)).to_array())
            .collect()
    }

    /// Refuses a body model of another topology than the one the template was made on: its
    /// binding (I^g) names that model's faces. Every use of a template on a body goes through here.
    pub fn check_body(&self, model: &BodyModel) -> Result<(), GarmentError> {
        let recipe = &self.recipe;
        let faces = model.faces.len();
        if recipe.body_vertices == model.num_vertices() && recipe.body_faces == faces {
            return Ok(());
        }
        Err(GarmentError::invalid(
            "body",
            format!(
                "the garment was made on '{}' ({} vertices, {} faces), this body has {} and {faces}: \
                 make it again on this body",
                recipe.body,
                recipe.body_vertices,
                recipe.body_faces,
                model.num_vertices(),
            ),
        ))
    }

    pub fn vertex_count(&self) -> usize {
        self.mesh.vertex_count()
    }

    pub fn uv(&self) -> Option<&UvLayout> {
        self.mesh.uv.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A two-triangle "body" square and a garment hovering over it: binding then Eq. 3.2 on the
    /// same body gives the garment back; on the body scaled by s it gives s·(G − D) + D, the
    /// hand-worked value of I^g (sT) + D^g.
    #[test]
    fn eq_3_2_returns_the_template_and_scales_with_the_body() {
        let body = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let faces = vec![[0, 1, 2], [0, 2, 3]];
        let garment_points = vec![[0.2, 0.3, 0.05], [0.7, 0.1, 0.02], [0.5, 0.9, 0.1]];
        let recipe = Recipe {
            category: Category::Tshirt,
            fit: Ease::size("M").unwrap(),
            edge_length: 0.015,
            material: Material::COTTON,
            body: "square".into(),
            betas: vec![],
            body_vertices: 4,
            body_faces: 2,
        };
        let index = ClosestPoint::new(&body, &faces, 0.5);
        let g = Garment::bind(recipe, TriMesh::new(garment_points.clone(), vec![[0, 1, 2]]), &index);
        let same = g.on_body(&body, &faces);
        for (a, b) in same.iter().zip(&garment_points) {
            assert!(Vec3::from(*a).distance(Vec3::from(*b)) < 1e-6);
        }
        let offsets = [[0.0, 0.0, 0.05], [0.0, 0.0, 0.02], [0.0, 0.0, 0.1]];
        for (d, e) in g.offsets.iter().zip(offsets) {
            assert!(Vec3::from(*d).distance(Vec3::from(e)) < 1e-6, "{d:?} vs {e:?}");
        }
        let s = 1.7;
        let scaled: Vec<[f32; 3]> = body.iter().map(|p| p.map(|x| s * x)).collect();
        let moved = g.on_body(&scaled, &faces);
        for ((m, p), d) in moved.iter().zip(&garment_points).zip(offsets) {
            let expected = s * (Vec3::from(*p) - Vec3::from(d)) + Vec3::from(d);
            assert!(Vec3::from(*m).distance(expected) < 1e-5, "{m:?} vs {expected}");
        }
    }
}
