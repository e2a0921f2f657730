//! `mannequin face track --video clip.mp4 | --frames DIR --out DIR`: the face followed through a
//! video (issue 22). The face mesh is tracked as MediaPipe does (each crop from the last frame's
//! points); the face's shape is fitted once, as the mean of full fits on a few frames spread over
//! the clip, then each frame fits expression and head pose with that shape, started from and
//! pulled toward the previous frame's fit. Writes `face.glb` (the expressions as morph targets,
//! keyed per frame, and the head's motion), an overlay per frame, and `track.json`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::DQuat;
use mannequin_body::{BodyModel, FaceModel};
use mannequin_data::Image;
use mannequin_fit::FaceModels;
use mannequin_fit::face_fit::{FaceFit, FaceFitter};
use mannequin_fit::face_landmarker::FaceLandmarks;
use mannequin_fit::overlay::face_overlay;
use mannequin_mesh::{BlendShapeAnimation, write_blend_shape_glb};
use rayon::prelude::*;

use crate::animate::write_video;
use crate::capture::{decode_video, frame_files};
use crate::face::{MIN_FACE_PX, expression_shapes, fitted_head, head_mesh, projected_edges};
use crate::fit::FitArgs;
use crate::progress::{JobTimer, bar};

/// Frames whose full fits are averaged into the video's face shape.
const SHAPE_FRAMES: usize = 5;
/// The animation's rate when frames come from a folder and no --fps is given.
const DEFAULT_FPS: f64 = 30.0;

#[derive(clap::Args)]
pub struct FaceTrackArgs {
    /// A folder of frames (PNG or JPEG), taken in file-name order.
    #[arg(long, conflicts_with = "video", required_unless_present = "video")]
    frames: Option<PathBuf>,
    /// A video file, decoded by the ffmpeg program.
    #[arg(long)]
    video: Option<PathBuf>,
    /// Frames per second: taken from the video (default: every frame), and the animation's rate
    /// (default 30 for a folder of frames).
    #[arg(long)]
    fps: Option<f64>,
    /// Use at most this many frames, from the start.
    #[arg(long)]
    max_frames: Option<usize>,
    #[command(flatten)]
    fitting: FitArgs,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

/// One frame's tracked face: its landmarks and fit, or nothing where the face was lost.
struct Tracked {
    file: PathBuf,
    landmarks: Option<FaceLandmarks>,
    fit: Option<FaceFit>,
}

pub fn track(args: FaceTrackArgs) -> Result<()> {
    let _timer = JobTimer::start("face track");
    let start = Instant::now();
    args.fitting.check()?;
    if args.fitting.body != "default" {
        bail!(
            "--body {}: the face model is the embedded default body's; use --body default",
            args.fitting.body
        );
    }
    if let Some(fps) = args.fps
        && !(fps.is_finite() && fps > 0.0)
    {
        bail!("--fps {fps}: expected a positive frame rate");
    }
    let scratch = args.out.with_extension("frames.partial");
    let decoded = match &args.video {
        Some(video) => Some(decode_video(video, args.fps, &scratch)?),
        None => None,
    };
    let result = track_frames(&args, decoded.as_deref().or(args.frames.as_deref()), start);
    if decoded.is_some() {
        let _ = std::fs::remove_dir_all(&scratch);
    }
    result
}

fn track_frames(args: &FaceTrackArgs, dir: Option<&Path>, start: Instant) -> Result<()> {
    let dir = dir.context("give --frames DIR or --video FILE")?;
    let mut files = frame_files(dir)?;
    if let Some(n) = args.max_frames {
        files.truncate(n);
    }
    if files.is_empty() {
        bail!("{}: no frames (PNG or JPEG) to track", dir.display());
    }
    let models = FaceModels::load()?;
    let (body, face) = (BodyModel::default_body(), FaceModel::default_face());

    let progress = bar(files.len() as u64, "face landmarks");
    let mut frames = Vec::with_capacity(files.len());
    let mut size = None;
    let mut previous = None;
    let landmarks_start = Instant::now();
    for file in &files {
        let image = Image::read(file)?;
        match size {
            None => size = Some((image.width, image.height)),
            Some(s) if s != (image.width, image.height) => bail!(
                "{}: {}×{} pixels, but the first frame is {}×{}; a video's frames share one size",
                file.display(),
                image.width,
                image.height,
                s.0,
                s.1
            ),
            Some(_) => {}
        }
        let landmarks = models.track(&image, previous)?;
        previous = landmarks.as_ref().map(FaceLandmarks::next_roi);
        frames.push(Tracked { file: file.clone(), landmarks, fit: None });
        progress.inc(1);
    }
    progress.finish();
    let landmark_seconds = landmarks_start.elapsed().as_secs_f64();
    let found: Vec<usize> = (0..frames.len()).filter(|&i| frames[i].landmarks.is_some()).collect();
    let Some(&first) = found.first() else {
        bail!(
            "{}: no face found in any of its {} frames (the detector finds faces turned less than about 60° from the camera)",
            dir.display(),
            frames.len()
        );
    };
    let side = face_side(frames[first].landmarks.as_ref().expect("found"));
    if side < MIN_FACE_PX {
        bail!(
            "{}: the face is {side:.0} pixels across; tracking needs at least {MIN_FACE_PX}",
            frames[first].file.display()
        );
    }

    let (width, height) = size.expect("at least one frame");
    let fitter = FaceFitter::new(&body, &face, width, height, args.fitting.focal(width, height))?;
    let shape_start = Instant::now();
    let shape = video_shape(&fitter, &frames, &found)?;
    let shape_seconds = shape_start.elapsed().as_secs_f64();
    let fit_start = Instant::now();
    let progress = bar(frames.len() as u64, "face fit");
    let mut last: Option<FaceFit> = None;
    for frame in &mut frames {
        if let Some(landmarks) = &frame.landmarks {
            let fit = fitter
                .track(landmarks, &shape, last.as_ref())
                .with_context(|| format!("fitting the face in {}", frame.file.display()))?;
            last = Some(fit.clone());
            frame.fit = Some(fit);
        } else {
            // A lost face starts the next stretch afresh rather than from a stale pose.
            last = None;
        }
        progress.inc(1);
    }
    progress.finish();
    let fit_seconds = fit_start.elapsed().as_secs_f64();

    let fps = args.fps.unwrap_or(DEFAULT_FPS);
    std::fs::create_dir_all(args.out.join("overlay"))
        .with_context(|| format!("creating {}", args.out.join("overlay").display()))?;
    let shown = frames[first].fit.as_ref().expect("fitted");
    let head = head_mesh(&body, &face, shown, &Image::read(&frames[first].file)?)?;
    let shapes = expression_shapes(&face, &head, &shown.expression);
    write_blend_shape_glb(args.out.join("face.glb"), &shapes, Some(&animation(&frames, fps)))?;
    write_overlays(&args.out, &body, &face, &frames)?;
    write_video(&args.out.join("overlay"), &args.out.join("overlay.mp4"), frames.len(), fps as f32)?;
    let per_second = frames.len() as f64 / (landmark_seconds + shape_seconds + fit_seconds);
    let report = serde_json::json!({
        "frames": frames.iter().map(frame_report).collect::<Vec<_>>(),
        "frames_with_face": found.len(),
        "shape": shape,
        "fps": fps,
        "seconds": {
            "landmarks": landmark_seconds,
            "shape": shape_seconds,
            "per_frame_fits": fit_seconds,
            "total": start.elapsed().as_secs_f64(),
        },
        "tracking_frames_per_second": per_second,
    });
    let path = args.out.join("track.json");
    mannequin_io::write_atomic(&path, serde_json::to_string_pretty(&report)?.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    let errors: Vec<f32> =
        frames.iter().filter_map(|f| f.fit.as_ref().map(FaceFit::mean_error_iod)).collect();
    tracing::info!(
        "tracked the face in {} of {} frames: landmark error {:.2} % of the eyes' distance (mean over frames), {:.1} frames per second; wrote {}",
        found.len(),
        frames.len(),
        100.0 * errors.iter().sum::<f32>() / errors.len() as f32,
        per_second,
        args.out.display()
    );
    Ok(())
}

/// The long side of the box around a face's points, in pixels.
fn face_side(landmarks: &FaceLandmarks) -> f32 {
    let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
    for p in &landmarks.points {
        (0..2).for_each(|c| (lo[c], hi[c]) = (lo[c].min(p[c]), hi[c].max(p[c])));
    }
    (hi[0] - lo[0]).max(hi[1] - lo[1])
}

/// The face's shape for the whole video: the mean of full fits on up to `SHAPE_FRAMES` frames
/// spread evenly over those with a face.
fn video_shape(fitter: &FaceFitter, frames: &[Tracked], found: &[usize]) -> Result<Vec<f32>> {
    let picks: Vec<usize> = match found.len() <= SHAPE_FRAMES {
        true => found.to_vec(),
        false => (0..SHAPE_FRAMES).map(|k| found[k * (found.len() - 1) / (SHAPE_FRAMES - 1)]).collect(),
    };
    let fits: Vec<FaceFit> = picks
        .par_iter()
        .map(|&i| {
            let landmarks = frames[i].landmarks.as_ref().expect("picked among frames with a face");
            fitter.fit(landmarks).with_context(|| format!("fitting the face in {}", frames[i].file.display()))
        })
        .collect::<Result<_>>()?;
    let mut shape = vec![0.0; fits[0].shape.len()];
    for fit in &fits {
        shape.iter_mut().zip(&fit.shape).for_each(|(s, a)| *s += a / fits.len() as f32);
    }
    Ok(shape)
}

/// The expression weights per frame and the head's motion as glTF sees it: the camera's axes
/// (x right, y down, z ahead) turned to glTF's (y up, z toward the viewer), the head about its
/// rest position and moved as it moves in the video. A frame without a face holds the nearest
/// fitted frame's values.
fn animation(frames: &[Tracked], fps: f64) -> BlendShapeAnimation {
    let fitted: Vec<usize> = (0..frames.len()).filter(|&i| frames[i].fit.is_some()).collect();
    let nearest = |i: usize| {
        let k = fitted.iter().min_by_key(|&&j| j.abs_diff(i)).expect("at least one fitted frame");
        frames[*k].fit.as_ref().expect("fitted")
    };
    let flip = DQuat::from_rotation_x(std::f64::consts::PI);
    let origin = nearest(0).translation;
    let (weights, node_pose) = (0..frames.len())
        .map(|i| {
            let fit = nearest(i);
            let q = flip * fit.rotation;
            let t = flip * (fit.translation - origin) + fit.centre - q * fit.centre;
            (fit.expression.clone(), (q.as_quat().to_array(), t.as_vec3().to_array()))
        })
        .unzip();
    BlendShapeAnimation { fps: fps as f32, weights, node_pose: Some(node_pose) }
}

/// `overlay/frame_%04d.png`: each frame with the fitted head's edges and both sets of points.
fn write_overlays(out: &Path, body: &BodyModel, face: &FaceModel, frames: &[Tracked]) -> Result<()> {
    let progress = bar(frames.len() as u64, "overlays");
    for (i, frame) in frames.iter().enumerate() {
        let image = Image::read(&frame.file)?;
        let picture = match (&frame.landmarks, &frame.fit) {
            (Some(landmarks), Some(fit)) => {
                let head = fitted_head(body, face, fit)?;
                face_overlay(&image, &landmarks.points, &fit.reprojected, &projected_edges(&head, fit))
            }
            _ => image,
        };
        picture.write_png(&out.join("overlay").join(format!("frame_{i:04}.png")))?;
        progress.inc(1);
    }
    progress.finish();
    Ok(())
}

fn frame_report(frame: &Tracked) -> serde_json::Value {
    let name = frame.file.file_name().map(|n| n.to_string_lossy().into_owned());
    match &frame.fit {
        None => serde_json::json!({ "file": name, "face": false }),
        Some(fit) => serde_json::json!({
            "file": name,
            "face": true,
            "landmark_error_iod": fit.mean_error_iod(),
            "expression": fit.expression,
            "head_rotation_xyzw": fit.rotation.to_array(),
            "head_translation_m": fit.translation.to_array(),
            "iterations": fit.stages.iter().map(|s| s.iterations).sum::<usize>(),
        }),
    }
}
