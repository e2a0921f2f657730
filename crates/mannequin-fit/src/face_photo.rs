//! One portrait to a fitted face (`mannequin face fit`): the largest face's 468 face-mesh
//! landmarks read with the shipped face models and the default body's face model fitted to them
//! (thesis §2.3, [`crate::face_fit`]). Writes the fitted head with colours taken from the photo
//! (with its expressions as blend shapes in `face.glb`), an overlay to check it by, and the
//! fit's numbers.

use std::path::Path;
use std::time::Instant;

use mannequin_body::{BodyModel, FaceModel};
use mannequin_data::Image;
use mannequin_mesh::write_blend_shape_glb;

use crate::error::FitError;
use crate::face_fit::{FaceFit, FaceFitter, OUTER_EYE_CORNERS};
use crate::face_models::{Face, FaceModels, MIN_FACE_PX};
use crate::face_texture::Texture;
use crate::fit_settings::FitSettings;
use crate::head_mesh::{expression_shapes, head_mesh, projected_edges};
use crate::output::{create_dir, write_report};
use crate::overlay::face_overlay;

/// How a portrait's fit went, for the closing line.
pub struct FacePhotoSummary {
    /// The mean landmark error over the inter-ocular distance.
    pub mean_error_iod: f32,
    pub seconds: f64,
}

/// Fits the face in `image` and writes `face.obj`, `face.glb`, `overlay.png` and `fit.json`
/// into `out`.
pub fn fit_face_photo(
    image_path: &Path,
    fitting: &FitSettings,
    out: &Path,
) -> Result<FacePhotoSummary, FitError> {
    let start = Instant::now();
    fitting.check_face_body()?;
    let image = Image::read(image_path)?;
    let models = FaceModels::load()?;
    let faces = models.faces(&image)?;
    let what = image_path.display().to_string();
    let Some(face) = faces.first() else {
        return Err(FitError::input(
            what,
            "no face found (the detector finds faces turned less than about 60° from the camera)",
        ));
    };
    let side = face.detection.side();
    if side < MIN_FACE_PX {
        return Err(FitError::input(
            what,
            format!("the face is {side:.0} pixels across; fitting needs at least {MIN_FACE_PX}"),
        ));
    }
    let focal = fitting.focal(image.width, image.height)?;
    let (body, face_model) = (BodyModel::default_body(), FaceModel::default_face());
    let fitter = FaceFitter::new(&body, &face_model, image.width, image.height, focal)?;
    let fitted = fitter
        .fit(&face.landmarks)
        .map_err(|e| FitError::within(format!("fitting the face in {what}"), e))?;
    let (head, texture) = head_mesh(&body, &face_model, &[(&fitted, &image)])?;
    create_dir(out)?;
    mannequin_mesh::write_obj(out.join("face.obj"), &head)?;
    let shapes = expression_shapes(&face_model, &head, &fitted.expression);
    write_blend_shape_glb(out.join("face.glb"), &shapes, None)?;
    let picture =
        face_overlay(&image, &face.landmarks.points, &fitted.reprojected, &projected_edges(&head, &fitted));
    picture.write_png(&out.join("overlay.png"))?;
    write_report(&out.join("fit.json"), &report(face, &fitted, &texture, start.elapsed().as_secs_f64()))?;
    Ok(FacePhotoSummary { mean_error_iod: fitted.mean_error_iod(), seconds: start.elapsed().as_secs_f64() })
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
