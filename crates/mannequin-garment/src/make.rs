//! Making a template (thesis §3.2): the covered region of the body's rest surface, pushed out
//! along the body's normal by the fit's ease and remeshed there to near-uniform triangles; for
//! garments that hang below the seat, a flared panel sewn on and draped. UVs come from the
//! body's own layout, so a body texture's regions carry over.

use glam::Vec3;
use mannequin_body::{BodyModel, shape_body};
use mannequin_cloth::{Material, check_garment};
use mannequin_mesh::barycentric::plane_barycentric;
use mannequin_mesh::normals::vertex_normals;
use mannequin_mesh::remesh::remesh;
use mannequin_mesh::{ClosestPoint, TriMesh, UvLayout};

use crate::category::Category;
use crate::ease::Ease;
use crate::ease_relief::{check_uncrossed, smooth_out_crossings};
use crate::error::GarmentError;
use crate::garment::{Garment, Recipe, check_edge_length};
use crate::region::{Landmarks, covered_region, open_front};
use crate::sewing::sew_skirt;

/// Changes whenever a recipe makes a different mesh, so that templates cached by an older one
/// are made anew.
pub const TEMPLATE_REVISION: u32 = 5;

/// Remeshing rounds: Botsch & Kobbelt find 5–10 enough; the body's 5 cm edges need the upper end.
const REMESH_ROUNDS: usize = 10;
/// Rounds after a panel is sewn on, a front cut open or crossings smoothed out, where only the
/// seam, the cut, the folds and the smoothed patch need them.
const SEWN_REMESH_ROUNDS: usize = 3;

/// The template of `category` cut to `fit`, remeshed to `edge_length`, on `model` (named
/// `body_name`) with shape `betas`, in `material`.
pub fn make_garment(
    category: Category,
    fit: Ease,
    edge_length: f32,
    material: Material,
    model: &BodyModel,
    body_name: &str,
    betas: &[f32],
) -> Result<Garment, GarmentError> {
    fit.validate()?;
    check_edge_length(edge_length)?;
    let shaped = shape_body(model, betas)?;
    let rest: Vec<[f32; 3]> = shaped.vertices.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    let mut body = model.template_mesh();
    body.positions = rest.clone();
    let marks = Landmarks::new(&rest, &shaped.joints);
    let region = covered_region(&body, &marks, category, &fit);
    if region.faces.is_empty() {
        return Err(GarmentError::invalid(
            "fit",
            format!("the {} cuts leave nothing of the body: check hem_height and sleeve", category.name()),
        ));
    }
    // Remesh on the eased surface itself (each point moved along the body's normal at its
    // closest body point to the ease at that height), not on the body: in a hollow (the crotch,
    // the small of the back) offsetting after remeshing would bunch the vertices together.
    let surface = ClosestPoint::new(&rest, &body.faces, 0.03);
    let body_normals: Vec<f32> = vertex_normals(&rest, &body.faces).into_iter().flatten().collect();
    let onto_eased = |p: Vec3| {
        let Some((point, q)) = surface.query(p) else { return p };
        let n = Vec3::from_slice(&point.interpolate(&body.faces, &body_normals, 3)).normalize_or_zero();
        // Along the normal only, keeping p's place across it: every point near a convex body
        // vertex has that vertex as its closest point, and mapping them all to one point would
        // collapse their triangles.
        p - n * ((p - q).dot(n) - marks.ease_at(&fit, q.y))
    };
    let start: Vec<[f32; 3]> =
        region.positions.iter().map(|&p| onto_eased(Vec3::from(p)).to_array()).collect();
    let (positions, faces) = remesh(&start, &region.faces, edge_length, REMESH_ROUNDS, onto_eased);
    let mut mesh = TriMesh::new(positions, faces);
    let depth = marks.seat() - marks.hem(category, &fit);
    let panel = category.flare().filter(|_| depth > 2.0 * edge_length);
    if panel.is_some() || category == Category::LongCoat {
        let sewn = match panel {
            Some(flare) => sew_skirt(&mesh, depth, flare, edge_length, &material, &body)?,
            None => mesh,
        };
        // The coat opens down the front, through bodice and skirt at once.
        let cut = if category == Category::LongCoat { open_front(&sewn, &marks) } else { sewn.clone() };
        // Even out the triangles the seam, the folds and the cut left, on the draped surface.
        mesh = evened(&cut, &sewn, edge_length);
    }
    if smooth_out_crossings(&mut mesh.positions, &mesh.faces)? {
        // Even out the triangles the smoothing squeezed, on the smoothed surface.
        mesh = evened(&mesh, &mesh, edge_length);
        check_uncrossed(&mesh.positions, &mesh.faces, "after smoothing and remeshing")?;
    }
    let recipe = Recipe {
        category,
        fit,
        edge_length,
        material,
        body: body_name.to_string(),
        betas: betas.to_vec(),
        body_vertices: model.num_vertices(),
        body_faces: body.faces.len(),
    };
    // A template is made to be simulated: one the solver cannot hold is not handed on.
    check_garment(&mesh).map_err(|e| GarmentError::invalid("template", e.to_string()))?;
    let garment = Garment::bind(recipe, mesh.clone(), &surface);
    mesh.uv = body.uv.as_ref().map(|uv| carried_uvs(&garment, &rest, &body.faces, uv));
    Ok(Garment { mesh, ..garment })
}

/// `mesh` after [`SEWN_REMESH_ROUNDS`] rounds of remeshing to `edge_length` on the surface of
/// `on`: where a step (a seam, a cut, a smoothing) left its triangles uneven.
fn evened(mesh: &TriMesh, on: &TriMesh, edge_length: f32) -> TriMesh {
    let surface = ClosestPoint::new(&on.positions, &on.faces, 0.03);
    let (positions, faces) = remesh(&mesh.positions, &mesh.faces, edge_length, SEWN_REMESH_ROUNDS, |p| {
        surface.query(p).map_or(p, |(_, q)| q)
    });
    TriMesh::new(positions, faces)
}

/// Per-corner UVs from the body's layout: each garment face takes the chart of the body face
/// under its first corner, and its corners' positions in that face's plane, so a face never
/// straddles a body seam.
fn carried_uvs(garment: &Garment, body: &[[f32; 3]], body_faces: &[[u32; 3]], uv: &UvLayout) -> UvLayout {
    let on_body: Vec<Vec3> = garment.binding.iter().map(|s| s.locate(body, body_faces)).collect();
    let mut coords = Vec::with_capacity(3 * garment.mesh.faces.len());
    let mut faces = Vec::with_capacity(garment.mesh.faces.len());
    for tri in &garment.mesh.faces {
        let chart = garment.binding[tri[0] as usize].face as usize;
        let [a, b, c] = body_faces[chart].map(|i| Vec3::from(body[i as usize]));
        let corners_uv = uv.faces[chart].map(|i| uv.coords[i as usize]);
        let start = coords.len() as u32;
        for &v in tri {
            let w = plane_barycentric(on_body[v as usize], a, b, c);
            coords.push([0, 1].map(|k| (0..3).map(|j| w[j] * corners_uv[j][k]).sum::<f32>()));
        }
        faces.push([start, start + 1, start + 2]);
    }
    UvLayout { coords, faces }
}
