//! `mannequin fit --image photo.jpg --out DIR`: finds the person in a photo, reads their
//! landmarks and mask with the shipped person models, and fits the body to them (thesis §2.2.2).
//! Writes the body in SMPL's layout with its camera, as meshes, an overlay to check it by, and
//! the fit's numbers. On the default body the person's face is fitted too (`face fit`), and the
//! body carries the fitted head.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use mannequin_body::{BodyModel, FaceModel, forward, skeletal_animation, skinned_body};
use mannequin_data::Image;
use mannequin_raster::{RasterMesh, Shading, rasterize};
use mannequin_fit::FaceModels;
use mannequin_fit::body_fit::assumed_focal;
use mannequin_fit::face_fit::{FaceFit, FaceFitter};
use mannequin_fit::overlay::overlay;
use mannequin_fit::pose_landmarker::PoseLandmarks;
use mannequin_fit::{BodyFit, Person, PersonModels, fit_body, pick_person};
use mannequin_io::limits::FOCAL_RANGE_PER_SIDE;
use mannequin_io::{NpyArray, NpzWriter};
use mannequin_mesh::TriMesh;

use mannequin_body::load_body;
use crate::face::MIN_FACE_PX;

/// The detector reads a 224² letterbox: smaller pictures hold too little to find a body in.
const MIN_SIDE: usize = 128;

#[derive(clap::Args)]
pub struct Args {
    /// The photo: PNG or JPEG.
    #[arg(long)]
    image: PathBuf,
    /// Which person to fit, counting from 0 in order of size (largest first).
    #[arg(long)]
    person: Option<usize>,
    #[command(flatten)]
    fitting: FitArgs,
    /// Do not fit the face (by default the default body's face is fitted too when the face is
    /// at least 48 pixels across, adding about half a second).
    #[arg(long)]
    no_face: bool,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

/// The body and camera options `fit` and `capture` share.
#[derive(clap::Args)]
pub struct FitArgs {
    /// The body model (the landmark table is made for the embedded default).
    #[arg(long, default_value = "default")]
    pub body: String,
    /// Focal length in pixels; by default the picture's long side (a 53° view across it).
    #[arg(long)]
    pub focal: Option<f64>,
}

impl FitArgs {
    /// Refuses a focal length that is no length.
    pub fn check(&self) -> Result<()> {
        if let Some(f) = self.focal.filter(|f| !(f.is_finite() && *f > 0.0)) {
            bail!("--focal: expected a positive number of pixels, found {f}");
        }
        Ok(())
    }

    /// The focal length for pictures of `width` × `height` pixels, within
    /// [`FOCAL_RANGE_PER_SIDE`] of their longer side (`--focal 1e30` once put the body 1.5e27 m
    /// away).
    pub fn focal(&self, width: usize, height: usize) -> Result<f64> {
        let Some(f) = self.focal else { return Ok(assumed_focal(width, height)) };
        let side = width.max(height) as f64;
        let (lo, hi) = FOCAL_RANGE_PER_SIDE;
        if f < lo * side || f > hi * side {
            bail!(
                "--focal: {f} pixels for a {width}×{height} picture: expected {lo}–{hi} times its longer side ({}–{} px)",
                lo * side,
                hi * side
            );
        }
        Ok(f)
    }
}

pub fn run(args: Args) -> Result<()> {
    let start = Instant::now();
    let image = Image::read(&args.image)?;
    if image.width.min(image.height) < MIN_SIDE {
        bail!(
            "{}: the picture is {}×{}; fitting needs at least {MIN_SIDE} pixels on the short side",
            args.image.display(),
            image.width,
            image.height
        );
    }
    args.fitting.check()?;
    let model = load_body(&args.fitting.body)?;
    let models = PersonModels::load()?;
    let people = models.people(&image)?;
    let person = pick_person(&people, args.person).with_context(|| args.image.display().to_string())?;
    let landmarks = models.refine(&image, person.landmarks.clone())?;
    let focal = args.fitting.focal(image.width, image.height)?;
    let fit = fit_body(&model, &landmarks, image.width, image.height, focal)
        .with_context(|| format!("fitting the body to {}", args.image.display()))?;
    let face_model = (!args.no_face && args.fitting.body == "default").then(FaceModel::default_face);
    let head = match &face_model {
        None => Head::NotAsked,
        Some(face_model) => fit_head(&model, face_model, &image, &landmarks, focal)
            .with_context(|| format!("fitting the face in {}", args.image.display()))?,
    };
    let model = match (&head, &face_model) {
        (Head::Fitted(face), Some(face_model)) => with_head(model, face_model, face)?,
        _ => model,
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let mesh = posed_mesh(&model, &fit)?;
    let (picture, iou) = check_picture(&image, &mesh, &landmarks, &fit);
    write_body_npz(&args.out.join("body.npz"), &fit, &head)?;
    mannequin_mesh::write_mesh(&args.out.join("body.obj"), &mesh)?;
    write_glb(&args.out.join("body.glb"), &model, &fit)?;
    picture.write_png(&args.out.join("overlay.png"))?;
    let mut report = report(&fit, person, iou, focal, start.elapsed().as_secs_f64());
    report["face"] = head.report();
    mannequin_io::write_atomic(&args.out.join("fit.json"), serde_json::to_string_pretty(&report)?.as_bytes())
        .with_context(|| format!("writing {}", args.out.join("fit.json").display()))?;
    tracing::info!(
        "fitted {}: median landmark error {:.1} px, mask IoU {:.3}, {:.1} s; wrote {}",
        args.image.display(),
        report["landmark_error_px"]["median"].as_f64().unwrap_or(f64::NAN),
        iou,
        start.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}

/// Whether the body carries the person's fitted face.
enum Head {
    Fitted(Box<FaceFit>),
    /// Why not: no face at the person's head, or one too small.
    Skipped(String),
    /// `--no-face`, or a body the face model is not made for.
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

/// The face (thesis §2.3) of the person whose body was fitted: the largest face whose box holds
/// the body's nose landmark, when it is large enough to fit.
fn fit_head(
    body: &BodyModel,
    face_model: &FaceModel,
    image: &Image,
    landmarks: &PoseLandmarks,
    focal: f64,
) -> Result<Head> {
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
fn with_head(mut model: BodyModel, face_model: &FaceModel, face: &FaceFit) -> Result<BodyModel> {
    face_model.apply(&mut model.v_template, &face.shape, &face.expression)?;
    Ok(model)
}

/// The overlay a user checks a fit by (`mannequin_fit::overlay`), and the IoU of the body's
/// silhouette with the person's mask.
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

pub fn posed_mesh(model: &BodyModel, fit: &BodyFit) -> Result<TriMesh> {
    let posed = forward(model, &fit.betas, &fit.pose, &fit.transl)?;
    let mut mesh = model.template_mesh();
    mesh.positions = posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Ok(mesh)
}

fn render(mesh: &TriMesh, fit: &BodyFit) -> mannequin_raster::Raster {
    let normals = mannequin_mesh::normals::vertex_normals(&mesh.positions, &mesh.faces);
    let raster_mesh = RasterMesh {
        positions: &mesh.positions,
        faces: &mesh.faces,
        normals: &normals,
        shading: Shading::Flat([1.0; 3]),
    };
    rasterize(&raster_mesh, &fit.camera, [0.0; 3])
}

/// SMPL's layout as PeopleSnapshot's pose files have it (one frame), plus the camera as its
/// `cameras.npz` has it.
fn write_body_npz(path: &Path, fit: &BodyFit, head: &Head) -> Result<()> {
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
    w.write(path).with_context(|| format!("writing {}", path.display()))
}

/// The shaped body, skinned, holding the fitted pose as a one-frame animation.
fn write_glb(path: &Path, model: &BodyModel, fit: &BodyFit) -> Result<()> {
    let skinned = skinned_body(model, &fit.betas)?;
    let animation = skeletal_animation(model.num_joints(), &fit.pose, &fit.transl, 30.0)?;
    mannequin_mesh::gltf::write_glb(path, &skinned, Some(&animation))
        .with_context(|| format!("writing {}", path.display()))
}

fn report(fit: &BodyFit, person: &Person, iou: f64, focal: f64, seconds: f64) -> serde_json::Value {
    let errors: Vec<f32> = fit.errors_px.iter().flatten().copied().collect();
    let mean = errors.iter().sum::<f32>() / errors.len().max(1) as f32;
    let max = errors.iter().copied().reduce(f32::max);
    let per_landmark: serde_json::Map<String, serde_json::Value> = mannequin_fit::blazepose::LANDMARKS
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
