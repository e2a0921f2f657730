//! `mannequin face fit --image portrait.jpg --out DIR`: finds the largest face, reads its 468
//! face-mesh landmarks with the shipped face models, and fits the default body's face model to
//! them (thesis §2.3, `mannequin_fit::face_fit`). Writes the fitted head with colours taken from
//! the photo (with its expressions as blend shapes in `face.glb`), an overlay to check it by, and
//! the fit's numbers.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Subcommand;
use glam::DVec3;
use mannequin_body::{BodyModel, FaceModel};
use mannequin_data::Image;
use mannequin_fit::face_fit::{FaceFit, FaceFitter, OUTER_EYE_CORNERS};
use mannequin_fit::face_texture::{Texture, View, fit_texture, mirror_vertices};
use mannequin_fit::overlay::face_overlay;
use mannequin_fit::{Face, FaceModels};
use mannequin_mesh::{BlendShapeMesh, TriMesh, write_blend_shape_glb};

use crate::fit::FitArgs;

/// The face mesh reads a 192² crop 1.5× the face box: a box much under 48 pixels is upsampled
/// past what the network saw in training.
pub(crate) const MIN_FACE_PX: f32 = 48.0;

#[derive(Subcommand)]
pub enum FaceCommand {
    /// Fit the default body's face (shape, expression, head pose) to a portrait: face.obj with
    /// colours, face.glb with the 52 expressions as morph targets, overlay.png and fit.json.
    Fit(FaceFitArgs),
    /// Follow the face through a video: shape fitted once, expression and head pose per frame;
    /// face.glb with the expressions keyed per frame, overlay frames and track.json.
    Track(crate::face_track::FaceTrackArgs),
}

#[derive(clap::Args)]
pub struct FaceFitArgs {
    /// The portrait: PNG or JPEG.
    #[arg(long)]
    image: PathBuf,
    #[command(flatten)]
    fitting: FitArgs,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(command: FaceCommand) -> Result<()> {
    match command {
        FaceCommand::Fit(args) => fit(args),
        FaceCommand::Track(args) => crate::face_track::track(args),
    }
}

fn fit(args: FaceFitArgs) -> Result<()> {
    let start = Instant::now();
    check_face_body(&args.fitting)?;
    let image = Image::read(&args.image)?;
    let models = FaceModels::load()?;
    let faces = models.faces(&image)?;
    let Some(face) = faces.first() else {
        bail!(
            "{}: no face found (the detector finds faces turned less than about 60° from the camera)",
            args.image.display()
        );
    };
    let side = face.detection.side();
    if side < MIN_FACE_PX {
        bail!(
            "{}: the face is {side:.0} pixels across; fitting needs at least {MIN_FACE_PX}",
            args.image.display()
        );
    }
    let focal = args.fitting.focal(image.width, image.height)?;
    let (body, face_model) = (BodyModel::default_body(), FaceModel::default_face());
    let fitter = FaceFitter::new(&body, &face_model, image.width, image.height, focal)?;
    let fitted = fitter
        .fit(&face.landmarks)
        .with_context(|| format!("fitting the face in {}", args.image.display()))?;
    let (head, texture) = head_mesh(&body, &face_model, &[(&fitted, &image)])?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    mannequin_mesh::write_mesh(&args.out.join("face.obj"), &head)?;
    let shapes = expression_shapes(&face_model, &head, &fitted.expression);
    write_blend_shape_glb(args.out.join("face.glb"), &shapes, None)?;
    let picture =
        face_overlay(&image, &face.landmarks.points, &fitted.reprojected, &projected_edges(&head, &fitted));
    picture.write_png(&args.out.join("overlay.png"))?;
    let report = report(face, &fitted, &texture, start.elapsed().as_secs_f64());
    mannequin_io::write_atomic(&args.out.join("fit.json"), serde_json::to_string_pretty(&report)?.as_bytes())
        .with_context(|| format!("writing {}", args.out.join("fit.json").display()))?;
    tracing::info!(
        "fitted the face in {}: landmark error {:.2} % of the eyes' distance (mean), {:.2} s; wrote {}",
        args.image.display(),
        100.0 * fitted.mean_error_iod(),
        start.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}

/// Refuses a focal length that is no length and a body the face model is not made for.
pub(crate) fn check_face_body(fitting: &FitArgs) -> Result<()> {
    fitting.check()?;
    if fitting.body != "default" {
        bail!("--body {}: the face model is the embedded default body's; use --body default", fitting.body);
    }
    Ok(())
}

/// The default body's head with the fitted shape and expression, in the body's rest frame.
pub(crate) fn fitted_head(body: &BodyModel, face: &FaceModel, fitted: &FaceFit) -> Result<TriMesh> {
    let mut positions = body.v_template.clone();
    face.apply(&mut positions, &fitted.shape, &fitted.expression)?;
    let faces = face.head_faces(body);
    let head: Vec<[f32; 3]> = face.vertices.iter().map(|&v| positions[v]).collect();
    Ok(TriMesh::new(head, faces))
}

/// [`fitted_head`] of the first view, coloured by the photometric term over every view
/// (`mannequin_fit::face_texture`: an albedo per vertex and a light per view). A view is a fit
/// and the picture it was fitted to.
pub(crate) fn head_mesh(
    body: &BodyModel,
    face: &FaceModel,
    views: &[(&FaceFit, &Image)],
) -> Result<(TriMesh, Texture)> {
    if views.is_empty() {
        bail!("a head needs at least one view to be coloured from");
    }
    let heads = views.iter().map(|(fit, _)| fitted_head(body, face, fit)).collect::<Result<Vec<_>>>()?;
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
pub(crate) fn expression_shapes(face: &FaceModel, head: &TriMesh, expression: &[f32]) -> BlendShapeMesh {
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
pub(crate) fn projected_edges(head: &TriMesh, fitted: &FaceFit) -> Vec<[[f32; 2]; 2]> {
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

fn report(face: &Face, fitted: &FaceFit, texture: &Texture, seconds: f64) -> serde_json::Value {
    let mut sorted = fitted.errors_iod.clone();
    sorted.sort_by(f32::total_cmp);
    let [a, b] = OUTER_EYE_CORNERS.map(|i| face.landmarks.points[i]);
    serde_json::json!({
        "landmark_error_iod": {
            "mean": fitted.mean_error_iod(),
            "median": sorted[sorted.len() / 2],
            "max": sorted[sorted.len() - 1],
            "per_landmark": fitted.errors_iod,
        },
        "inter_ocular_px": (a[0] - b[0]).hypot(a[1] - b[1]),
        "landmarks_px": face.landmarks.points,
        "face_box": face.detection.bbox,
        "detection_score": face.detection.score,
        "shape": fitted.shape,
        "expression": fitted.expression,
        "head_rotation_xyzw": fitted.rotation.to_array(),
        "head_translation_m": fitted.translation.to_array(),
        "focal_px": fitted.camera.intrinsic[0][0],
        "photometric_error_rms": texture.rms,
        "light": { "ambient": texture.lights[0][0], "direction_camera": &texture.lights[0][1..] },
        "stages": fitted.stages.iter().map(|s| serde_json::json!({
            "initial_cost": s.initial_cost, "final_cost": s.final_cost, "iterations": s.iterations,
        })).collect::<Vec<_>>(),
        "seconds": seconds,
    })
}
