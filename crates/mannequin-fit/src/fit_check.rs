//! What a user checks a body fit by: the fitted body posed as a mesh, drawn over the picture
//! with the landmarks, and how well its silhouette covers the person's mask.

use mannequin_body::{BodyModel, forward};
use mannequin_data::Image;
use mannequin_mesh::TriMesh;
use mannequin_raster::{Raster, RasterMesh, Shading, rasterize};

use crate::body_fit::BodyFit;
use crate::error::FitError;
use crate::overlay::overlay;
use crate::pose_landmarker::PoseLandmarks;

/// The overlay a user checks a fit by ([`overlay`]), and the IoU of the body's silhouette with
/// the person's mask.
pub fn check_picture(
    image: &Image,
    mesh: &TriMesh,
    landmarks: &PoseLandmarks,
    fit: &BodyFit,
) -> (Image, f64) {
    let raster = render(mesh, fit);
    let person = landmarks.person_mask(image.width, image.height);
    let confident: Vec<bool> = fit.errors_px.iter().map(Option::is_some).collect();
    (overlay(image, &raster, &landmarks.points, &confident, &fit.reprojected), raster.mask.iou(&person))
}

/// The body in the fitted shape and pose, as a mesh.
pub fn posed_mesh(model: &BodyModel, fit: &BodyFit) -> Result<TriMesh, FitError> {
    let posed = forward(model, &fit.betas, &fit.pose, &fit.transl)?;
    let mut mesh = model.template_mesh();
    mesh.positions = posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Ok(mesh)
}

/// The mesh seen by the fit's camera, flat white.
fn render(mesh: &TriMesh, fit: &BodyFit) -> Raster {
    let normals = mannequin_mesh::normals::vertex_normals(&mesh.positions, &mesh.faces);
    let raster_mesh = RasterMesh {
        positions: &mesh.positions,
        faces: &mesh.faces,
        normals: &normals,
        shading: Shading::Flat([1.0; 3]),
    };
    rasterize(&raster_mesh, &fit.camera, [0.0; 3])
}
