//! One photo to a fitted body (`mannequin fit`): the person found with the shipped person
//! models, the body fitted to their landmarks (thesis §2.2.2) and, on the default body, their
//! face fitted too (thesis §2.3) so the body carries the fitted head. Writes the body in SMPL's
//! layout with its camera, as meshes, an overlay to check it by, and the fit's numbers.

use std::path::Path;
use std::time::Instant;

use mannequin_body::{BodyModel, FaceModel, skeletal_animation, skinned_body};
use mannequin_data::Image;
use mannequin_io::{NpyArray, NpzWriter};

use crate::body_fit::{BodyFit, fit_body};
use crate::error::FitError;
use crate::face_fit::{FaceFit, FaceFitter};
use crate::face_models::{FaceModels, MIN_FACE_PX};
use crate::fit_check::{check_picture, posed_mesh};
use crate::fit_settings::FitSettings;
use crate::output::{create_dir, write_report};
use crate::person_models::{Person, PersonModels, pick_person};
use crate::pose_landmarker::PoseLandmarks;

/// The detector reads a 224² letterbox: smaller pictures hold too little to find a body in.
const MIN_SIDE: usize = 128;

/// What to fit and where to write it.
pub struct BodyPhoto<'a> {
    pub image: &'a Path,
    /// Which person, counting from 0 in order of size (by default the largest).
    pub person: Option<usize>,
    pub fitting: &'a FitSettings,
    /// Fit the face too (on the default body only).
    pub face: bool,
    pub out: &'a Path,
}

/// How a photo's fit went, for the closing line.
pub struct BodyPhotoSummary {
    pub median_error_px: Option<f32>,
    pub mask_iou: f64,
    pub seconds: f64,
}

/// Fits the body (and face) to the photo and writes `body.npz`, `body.obj`, `body.glb`,
/// `overlay.png` and `fit.json` into the output folder.
pub fn fit_photo(job: &BodyPhoto) -> Result<BodyPhotoSummary, FitError> {
    let start = Instant::now();
    let image = Image::read(job.image)?;
    if image.width.min(image.height) < MIN_SIDE {
        return Err(FitError::input(
            job.image.display().to_string(),
            format!(
                "the picture is {}×{}; fitting needs at least {MIN_SIDE} pixels on the short side",
                image.width, image.height
            ),
        ));
    }
    job.fitting.check()?;
    let model = job.fitting.body_model()?;
    let models = PersonModels::load()?;
    let people = models.people(&image, job.person)?;
    let person =
        pick_person(&people, job.person).map_err(|e| FitError::within(job.image.display().to_string(), e))?;
    let landmarks = models.refine(&image, person.landmarks.clone())?;
    let focal = job.fitting.focal(image.width, image.height)?;
    let fit = fit_body(&model, &landmarks, image.width, image.height, focal)
        .map_err(|e| FitError::within(format!("fitting the body to {}", job.image.display()), e))?;
    let face_model = (job.face && job.fitting.is_default_body()).then(FaceModel::default_face);
    let head = match &face_model {
        None => Head::NotAsked,
        Some(face_model) => fit_head(&model, face_model, &image, &landmarks, focal)
            .map_err(|e| FitError::within(format!("fitting the face in {}", job.image.display()), e))?,
    };
    let model = match (&head, &face_model) {
        (Head::Fitted(face), Some(face_model)) => with_head(model, face_model, face)?,
        _ => model,
    };
    create_dir(job.out)?;
    let mesh = posed_mesh(&model, &fit)?;
    let (picture, iou) = check_picture(&image, &mesh, &landmarks, &fit);
    write_body_npz(&job.out.join("body.npz"), &fit, &head)?;
    mannequin_mesh::write_obj(job.out.join("body.obj"), &mesh)?;
    write_glb(&job.out.join("body.glb"), &model, &fit)?;
    picture.write_png(&job.out.join("overlay.png"))?;
    let mut report = report(&fit, person, iou, focal, start.elapsed().as_secs_f64());
    report["face"] = head.report();
    write_report(&job.out.join("fit.json"), &report)?;
    Ok(BodyPhotoSummary {
        median_error_px: fit.median_error_px(),
        mask_iou: iou,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Whether the body carries the person's fitted face.
enum Head {
    Fitted(Box<FaceFit>),
    /// Why not: no face at the person's head, or one too small.
    Skipped(String),
    /// Not asked for, or a body the face model is not made for.
    NotAsked,
}

impl Head {
    fn report(&self) -> serde_json::Value {
        match self {
            Head::Fitted(f) => serde_json::json!({
                "fitted": true,
                "landmark_error_iod": f.mean_error_iod(),
                "shape": f.shape,
                "expression": f.expression,
            }),
            Head::Skipped(why) => serde_json::json!({ "fitted": false, "why": why }),
            Head::NotAsked => {
                serde_json::json!({ "fitted": false, "why": "not asked (--no-face or a body other than the default)" })
            }
        }
    }
}

/// The face of the person whose body was fitted: the largest face whose box holds the body's
/// nose landmark, when it is large enough to fit.
fn fit_head(
    body: &BodyModel,
    face_model: &FaceModel,
    image: &Image,
    landmarks: &PoseLandmarks,
    focal: f64,
) -> Result<Head, FitError> {
    let nose = landmarks.points[0];
    let faces = FaceModels::load()?.faces(image)?;
    let Some(face) = faces.into_iter().find(|f| {
        let [x0, y0, x1, y1] = f.detection.bbox;
        (x0..=x1).contains(&nose[0]) && (y0..=y1).contains(&nose[1])
    }) else {
        return Ok(Head::Skipped("no face found at the person's head".into()));
    };
    let side = face.detection.side();
    if side < MIN_FACE_PX {
        return Ok(Head::Skipped(format!("the face is {side:.0} pixels across, under {MIN_FACE_PX}")));
    }
    let fitter = FaceFitter::new(body, face_model, image.width, image.height, focal)?;
    Ok(Head::Fitted(Box::new(fitter.fit(&face.landmarks)?)))
}

/// The default body with the fitted face's shape and expression on its head: every output
/// (meshes, skinned glTF) then carries the head.
fn with_head(mut model: BodyModel, face_model: &FaceModel, face: &FaceFit) -> Result<BodyModel, FitError> {
    face_model.apply(&mut model.v_template, &face.shape, &face.expression)?;
    Ok(model)
}

/// SMPL's layout as PeopleSnapshot's pose files have it (one frame), plus the camera as its
/// `cameras.npz` has it.
fn write_body_npz(path: &Path, fit: &BodyFit, head: &Head) -> Result<(), FitError> {
    let c = &fit.camera;
    let mut w = NpzWriter::new();
    w.add("betas", NpyArray::f32(vec![1, fit.betas.len()], fit.betas.clone()))
        .add("global_orient", NpyArray::f32(vec![1, 3], fit.pose[..3].to_vec()))
        .add("body_pose", NpyArray::f32(vec![1, fit.pose.len() - 3], fit.pose[3..].to_vec()))
        .add("transl", NpyArray::f32(vec![1, 3], fit.transl.to_vec()))
        .add("intrinsic", NpyArray::f64(vec![3, 3], c.intrinsic.iter().flatten().copied().collect()))
        .add("extrinsic", NpyArray::f64(vec![4, 4], c.extrinsic.iter().flatten().copied().collect()))
        .add("height", NpyArray::i64(vec![], vec![c.height as i64]))
        .add("width", NpyArray::i64(vec![], vec![c.width as i64]));
    if let Head::Fitted(face) = head {
        // The default body's face model coefficients (`mannequin_body::FaceModel`).
        w.add("face_shape", NpyArray::f32(vec![1, face.shape.len()], face.shape.clone()))
            .add("face_expression", NpyArray::f32(vec![1, face.expression.len()], face.expression.clone()));
    }
    w.write(path).map_err(|e| FitError::within(format!("writing {}", path.display()), e))
}

/// The shaped body, skinned, holding the fitted pose as a one-frame animation.
fn write_glb(path: &Path, model: &BodyModel, fit: &BodyFit) -> Result<(), FitError> {
    let skinned = skinned_body(model, &fit.betas)?;
    let animation = skeletal_animation(model.num_joints(), &fit.pose, &fit.transl, 30.0)?;
    mannequin_mesh::gltf::write_glb(path, &skinned, Some(&animation))
        .map_err(|e| FitError::within(format!("writing {}", path.display()), e))
}

fn report(fit: &BodyFit, person: &Person, iou: f64, focal: f64, seconds: f64) -> serde_json::Value {
    let errors: Vec<f32> = fit.errors_px.iter().flatten().copied().collect();
    let mean = errors.iter().sum::<f32>() / errors.len().max(1) as f32;
    let max = errors.iter().copied().reduce(f32::max);
    let per_landmark: serde_json::Map<String, serde_json::Value> = crate::blazepose::LANDMARKS
        .iter()
        .zip(&fit.errors_px)
        .map(|((name, _), e)| (name.to_string(), e.map_or(serde_json::Value::Null, |e| serde_json::json!(e))))
        .collect();
    serde_json::json!({
        "landmark_error_px": { "mean": mean, "median": fit.median_error_px(), "max": max, "per_landmark": per_landmark },
        "mask_iou": iou,
        "seconds": seconds,
        "focal_px": focal,
        "detection": { "score": person.detection.score, "box": person.detection.bbox },
        "pose_flag": person.landmarks.flag,
        "stages": fit.stages.iter().map(|s| serde_json::json!({
            "initial_cost": s.initial_cost, "final_cost": s.final_cost, "iterations": s.iterations
        })).collect::<Vec<_>>(),
    })
}
