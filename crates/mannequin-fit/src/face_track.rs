//! A face followed through a video (`mannequin face track`, issue 22). The face mesh is tracked
//! as MediaPipe does (each crop from the last frame's points); the face's shape is fitted once,
//! as the mean of full fits on a few frames spread over the clip, then each frame fits
//! expression and head pose with that shape, started from and pulled toward the previous
//! frame's fit. Writes `face.glb` (the expressions as morph targets, keyed per frame, and the
//! head's motion; its colours blended from the frames the shape was fitted on), an overlay per
//! frame, and `track.json`. A checkpoint every 50 frames lets a stopped track resume; a finished
//! one removes it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DQuat;
use mannequin_body::{BodyModel, FaceModel};
use mannequin_data::Image;
use mannequin_io::progress::bar;
use mannequin_io::write_video;
use mannequin_mesh::{BlendShapeAnimation, write_blend_shape_glb};
use rayon::prelude::*;

use crate::error::FitError;
use crate::face_fit::{FaceFit, FaceFitter};
use crate::face_landmarker::FaceLandmarks;
use crate::face_models::{FaceModels, MIN_FACE_PX};
use crate::face_track_checkpoint::{Done, TrackRun, read_checkpoint, write_checkpoint};
use crate::fit_settings::FitSettings;
use crate::frame_source::{FrameSource, Frames};
use crate::head_mesh::{expression_shapes, fitted_head, head_mesh, projected_edges};
use crate::output::{CHECKPOINT, create_dir, write_report};
use crate::overlay::face_overlay;

/// Frames whose full fits are averaged into the video's face shape.
const SHAPE_FRAMES: usize = 5;
/// The animation's rate when frames come from a folder and no --fps is given.
const DEFAULT_FPS: f64 = 30.0;
/// Frames between checkpoints, in each stage.
const CHECKPOINT_EVERY: usize = 50;

/// Everything a face track reads: its frames, the camera, and where it writes.
#[derive(Clone, Debug, Default, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
pub struct FaceTrackSettings {
    #[command(flatten)]
    pub input: FrameSource,
    #[command(flatten)]
    pub fitting: FitSettings,
    /// Output folder. A track that was stopped resumes from its checkpoint there.
    #[arg(long)]
    pub out: PathBuf,
    /// Ignore a checkpoint in --out and start over.
    #[arg(long)]
    pub restart: bool,
}

/// How a track went, for the closing line.
pub struct FaceTrackSummary {
    pub frames: usize,
    pub frames_with_face: usize,
    /// The landmark error over the inter-ocular distance, the mean over frames.
    pub mean_error_iod: f32,
    pub frames_per_second: f64,
}

/// Tracks the face through the clip and writes the track into `settings.out`.
pub fn track_face(settings: &FaceTrackSettings) -> Result<FaceTrackSummary, FitError> {
    let start = Instant::now();
    settings.fitting.check_face_body()?;
    let scratch = settings.out.with_extension("frames.partial");
    let frames = settings.input.frames(&scratch)?;
    let result = track_frames(settings, &frames, start);
    if frames.decoded {
        let _ = std::fs::remove_dir_all(&scratch);
    }
    result
}

fn track_frames(
    settings: &FaceTrackSettings,
    frames: &Frames,
    start: Instant,
) -> Result<FaceTrackSummary, FitError> {
    let Frames { dir, files, .. } = frames;
    let out = &settings.out;
    if files.is_empty() {
        return Err(FitError::input(dir.display().to_string(), "no frames (PNG or JPEG) to track"));
    }
    let run = TrackRun {
        source: settings.input.fingerprint(files)?,
        fps: settings.input.fps,
        max_frames: settings.input.max_frames,
        focal: settings.fitting.focal,
    };
    let checkpoint = out.join(CHECKPOINT);
    let first = Image::read(&files[0])?;
    let (width, height) = (first.width, first.height);
    let (body, face) = (BodyModel::default_body(), FaceModel::default_face());
    let fitter = FaceFitter::new(&body, &face, width, height, settings.fitting.focal(width, height)?)?;
    let mut done = match !settings.restart && checkpoint.exists() {
        true => {
            let done = read_checkpoint(&checkpoint, &run, &fitter)?;
            tracing::info!(
                "resuming {} ({} of {} frames read, {} fitted)",
                checkpoint.display(),
                done.landmarks.len(),
                files.len(),
                done.fits.len()
            );
            done
        }
        false => Done::default(),
    };
    let models = FaceModels::load()?;
    let save = |done: &Done| write_checkpoint(&checkpoint, &run, done);

    let progress = bar(files.len() as u64, "face landmarks");
    progress.set_position(done.landmarks.len() as u64);
    let mut previous = done.landmarks.last().and_then(|l| l.as_ref().map(FaceLandmarks::next_roi));
    let landmarks_start = Instant::now();
    for file in &files[done.landmarks.len()..] {
        let image = Image::read(file)?;
        if (image.width, image.height) != (width, height) {
            return Err(FitError::input(
                file.display().to_string(),
                format!(
                    "{}×{} pixels, but the first frame is {width}×{height}; a video's frames share one size",
                    image.width, image.height
                ),
            ));
        }
        let landmarks = models.track(&image, previous)?;
        previous = landmarks.as_ref().map(FaceLandmarks::next_roi);
        done.landmarks.push(landmarks);
        if done.landmarks.len().is_multiple_of(CHECKPOINT_EVERY) {
            save(&done)?;
        }
        progress.inc(1);
    }
    progress.finish();
    let landmark_seconds = landmarks_start.elapsed().as_secs_f64();
    let found: Vec<usize> = (0..files.len()).filter(|&i| done.landmarks[i].is_some()).collect();
    let Some(&first) = found.first() else {
        // Nothing is kept of a refused track.
        let _ = std::fs::remove_file(&checkpoint);
        let _ = std::fs::remove_dir(out);
        return Err(FitError::input(
            dir.display().to_string(),
            format!(
                "no face found in any of its {} frames (the detector finds faces turned less than about 60° from the camera)",
                files.len()
            ),
        ));
    };
    let side = face_side(done.landmarks[first].as_ref().expect("found"));
    if side < MIN_FACE_PX {
        return Err(FitError::input(
            files[first].display().to_string(),
            format!("the face is {side:.0} pixels across; tracking needs at least {MIN_FACE_PX}"),
        ));
    }

    let shape_start = Instant::now();
    let shape = match &done.shape {
        Some(shape) => shape.clone(),
        None => {
            let shape = video_shape(&fitter, files, &done.landmarks, &found)?;
            done.shape = Some(shape.clone());
            save(&done)?;
            shape
        }
    };
    let shape_seconds = shape_start.elapsed().as_secs_f64();
    let fit_start = Instant::now();
    let overlays = out.join("overlay");
    create_dir(&overlays)?;
    let progress = bar(files.len() as u64, "face fit");
    progress.set_position(done.fits.len() as u64);
    for (i, file) in files.iter().enumerate().skip(done.fits.len()) {
        // A lost face starts the next stretch afresh rather than from a stale pose.
        let last = done.fits.last().and_then(Option::as_ref);
        let fit = match &done.landmarks[i] {
            Some(landmarks) => Some(
                fitter
                    .track(landmarks, &shape, last)
                    .map_err(|e| FitError::within(format!("fitting the face in {}", file.display()), e))?,
            ),
            None => None,
        };
        let image = Image::read(file)?;
        let picture = match (&done.landmarks[i], &fit) {
            (Some(landmarks), Some(fit)) => {
                let head = fitted_head(&body, &face, fit)?;
                face_overlay(&image, &landmarks.points, &fit.reprojected, &projected_edges(&head, fit))
            }
            _ => image,
        };
        picture.write_png(&overlays.join(format!("frame_{i:04}.png")))?;
        done.fits.push(fit);
        if done.fits.len().is_multiple_of(CHECKPOINT_EVERY) {
            save(&done)?;
        }
        progress.inc(1);
    }
    progress.finish();
    let fit_seconds = fit_start.elapsed().as_secs_f64();

    let fps = settings.input.fps.unwrap_or(DEFAULT_FPS);
    // Coloured from the frames the shape was fitted on, the first one's head shown.
    let mut views = Vec::new();
    for i in spread(&found) {
        if let Some(fit) = &done.fits[i] {
            views.push((fit, Image::read(&files[i])?));
        }
    }
    let views: Vec<(&FaceFit, &Image)> = views.iter().map(|(f, i)| (*f, i)).collect();
    let shown = views[0].0;
    let (head, texture) = head_mesh(&body, &face, &views)?;
    let shapes = expression_shapes(&face, &head, &shown.expression);
    write_blend_shape_glb(out.join("face.glb"), &shapes, Some(&animation(&done.fits, fps)))?;
    write_video(&overlays, &out.join("overlay.mp4"), files.len(), fps as f32)?;
    let per_second = files.len() as f64 / (landmark_seconds + shape_seconds + fit_seconds);
    let report = serde_json::json!({
        "frames": files.iter().zip(&done.fits).map(|(f, fit)| frame_report(f, fit.as_ref())).collect::<Vec<_>>(),
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
        "photometric_error_rms": texture.rms,
    });
    write_report(&out.join("track.json"), &report)?;
    if checkpoint.exists() {
        std::fs::remove_file(&checkpoint).map_err(FitError::file("removing", &checkpoint))?;
    }
    let errors: Vec<f32> = done.fits.iter().flatten().map(FaceFit::mean_error_iod).collect();
    Ok(FaceTrackSummary {
        frames: files.len(),
        frames_with_face: found.len(),
        mean_error_iod: errors.iter().sum::<f32>() / errors.len() as f32,
        frames_per_second: per_second,
    })
}

/// The long side of the box around a face's points, in pixels.
fn face_side(landmarks: &FaceLandmarks) -> f32 {
    let (lo, hi) = landmarks.bounds();
    (hi[0] - lo[0]).max(hi[1] - lo[1])
}

/// Up to `SHAPE_FRAMES` of the frames with a face, spread evenly from the first to the last.
fn spread(found: &[usize]) -> Vec<usize> {
    match found.len() <= SHAPE_FRAMES {
        true => found.to_vec(),
        false => (0..SHAPE_FRAMES).map(|k| found[k * (found.len() - 1) / (SHAPE_FRAMES - 1)]).collect(),
    }
}

/// The face's shape for the whole video: the mean of full fits on the frames [`spread`] picks.
fn video_shape(
    fitter: &FaceFitter,
    files: &[PathBuf],
    landmarks: &[Option<FaceLandmarks>],
    found: &[usize],
) -> Result<Vec<f32>, FitError> {
    let picks = spread(found);
    let fits: Vec<FaceFit> = picks
        .par_iter()
        .map(|&i| {
            let landmarks = landmarks[i].as_ref().expect("picked among frames with a face");
            fitter
                .fit(landmarks)
                .map_err(|e| FitError::within(format!("fitting the face in {}", files[i].display()), e))
        })
        .collect::<Result<_, _>>()?;
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
fn animation(fits: &[Option<FaceFit>], fps: f64) -> BlendShapeAnimation {
    let fitted: Vec<usize> = (0..fits.len()).filter(|&i| fits[i].is_some()).collect();
    let nearest = |i: usize| {
        let k = fitted.iter().min_by_key(|&&j| j.abs_diff(i)).expect("at least one fitted frame");
        fits[*k].as_ref().expect("fitted")
    };
    let flip = DQuat::from_rotation_x(std::f64::consts::PI);
    let origin = nearest(0).translation;
    let (weights, node_pose) = (0..fits.len())
        .map(|i| {
            let fit = nearest(i);
            let q = flip * fit.rotation;
            let t = flip * (fit.translation - origin) + fit.centre - q * fit.centre;
            (fit.expression.clone(), (q.as_quat().to_array(), t.as_vec3().to_array()))
        })
        .unzip();
    BlendShapeAnimation { fps: fps as f32, weights, node_pose: Some(node_pose) }
}

fn frame_report(file: &Path, fit: Option<&FaceFit>) -> serde_json::Value {
    let name = file.file_name().map(|n| n.to_string_lossy().into_owned());
    match fit {
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
