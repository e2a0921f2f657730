//! The fitted face as the default body's head: its mesh in the rest frame, coloured from the
//! pictures it was fitted to, its expressions as blend shapes, and the edges an overlay draws.

use glam::DVec3;
use mannequin_body::{BodyModel, FaceModel};
use mannequin_data::Image;
use mannequin_mesh::{BlendShapeMesh, TriMesh};

use crate::error::FitError;
use crate::face_fit::FaceFit;
use crate::face_texture::{Texture, View, fit_texture, mirror_vertices};

/// The default body's head with the fitted shape and expression, in the body's rest frame.
pub fn fitted_head(body: &BodyModel, face: &FaceModel, fitted: &FaceFit) -> Result<TriMesh, FitError> {
    let mut positions = body.v_template.clone();
    face.apply(&mut positions, &fitted.shape, &fitted.expression)?;
    let faces = face.head_faces(body);
    let head: Vec<[f32; 3]> = face.vertices.iter().map(|&v| positions[v]).collect();
    Ok(TriMesh::new(head, faces))
}

/// [`fitted_head`] of the first view, coloured by the photometric term over every view
/// (`face_texture`: an albedo per vertex and a light per view). A view is a fit and the picture
/// it was fitted to.
pub fn head_mesh(
    body: &BodyModel,
    face: &FaceModel,
    views: &[(&FaceFit, &Image)],
) -> Result<(TriMesh, Texture), FitError> {
    if views.is_empty() {
        return Err(FitError::Picture("a head needs at least one view to be coloured from".into()));
    }
    let heads = views.iter().map(|(fit, _)| fitted_head(body, face, fit)).collect::<Result<Vec<_>, _>>()?;
    let placed: Vec<Vec<DVec3>> = heads
        .iter()
        .zip(views)
        .map(|(head, (fit, _))| head.positions.iter().map(|p| fit.to_camera(*p)).collect())
        .collect();
    let pictures: Vec<View> = placed
        .iter()
        .zip(views)
        .map(|(points, (fit, image))| View { points, camera: &fit.camera, image })
        .collect();
    let rest: Vec<[f32; 3]> = face.vertices.iter().map(|&v| body.v_template[v]).collect();
    let mut head = heads.into_iter().next().expect("one head per view");
    let texture = fit_texture(&pictures, &head.faces, &mirror_vertices(&rest))?;
    head.colors = Some(texture.albedo.clone());
    Ok((head, texture))
}

/// The fitted head as blend shapes: the 52 expression units as named morph targets over the
/// head without its expression, shown at the fitted weights (so a viewer shows the fitted face,
/// and moving a weight animates it).
pub fn expression_shapes(face: &FaceModel, head: &TriMesh, expression: &[f32]) -> BlendShapeMesh {
    let v = face.vertices.len();
    let shapes: Vec<Vec<[f32; 3]>> = (0..face.num_expressions())
        .map(|k| {
            face.expression_basis[k * v * 3..(k + 1) * v * 3]
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect()
        })
        .collect();
    let mut neutral = head.clone();
    for (shape, &w) in shapes.iter().zip(expression) {
        neutral.positions.iter_mut().zip(shape).for_each(|(p, d)| (0..3).for_each(|c| p[c] -= w * d[c]));
    }
    BlendShapeMesh {
        name: "face".into(),
        mesh: neutral,
        shape_names: face.expression_names.clone(),
        shapes,
        weights: expression.to_vec(),
    }
}

/// The head's edges that face the camera, projected: what the overlay draws.
pub fn projected_edges(head: &TriMesh, fitted: &FaceFit) -> Vec<[[f32; 2]; 2]> {
    let mut edges = Vec::new();
    for f in &head.faces {
        let p: Vec<DVec3> = f.iter().map(|&v| fitted.to_camera(head.positions[v as usize])).collect();
        // Counter-clockwise from outside: facing the camera when the normal points back at it.
        if (p[1] - p[0]).cross(p[2] - p[0]).dot(p[0]) >= 0.0 {
            continue;
        }
        let uv: Vec<[f32; 2]> =
            p.iter().map(|x| fitted.camera.project(*x)).map(|[u, v]| [u as f32, v as f32]).collect();
        edges.extend([[uv[0], uv[1]], [uv[1], uv[2]], [uv[2], uv[0]]]);
    }
    edges
}
