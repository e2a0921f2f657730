//! `mannequin face track --video clip.mp4 | --frames DIR --out DIR`: the face followed through a
//! video (issue 22). The face mesh is tracked as MediaPipe does (each crop from the last frame's
//! points); the face's shape is fitted once, as the mean of full fits on a few frames spread over
//! the clip, then each frame fits expression and head pose with that shape, started from and
//! pulled toward the previous frame's fit. Writes `face.glb` (the expressions as morph targets,
//! keyed per frame, and the head's motion; its colours blended from the frames the shape was
//! fitted on), an overlay per frame, and `track.json`. A checkpoint
//! every 50 frames lets a stopped track resume; a finished one removes it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::{DQuat, DVec3};
use mannequin_body::{BodyModel, FaceModel};
use mannequin_data::Image;
use mannequin_fit::FaceModels;
use mannequin_fit::crop::RotatedRect;
use mannequin_fit::face_fit::{FaceFit, FaceFitter};
use mannequin_fit::face_landmarker::{FaceLandmarks, NUM_LANDMARKS};
use mannequin_fit::overlay::face_overlay;
use mannequin_io::{NpyArray, Npz, NpzWriter};
use mannequin_mesh::{BlendShapeAnimation, write_blend_shape_glb};
use rayon::prelude::*;

use mannequin_io::write_video;
use crate::checkpoint::{CHECKPOINT, add_run, check_run};
use crate::face::{MIN_FACE_PX, check_face_body, expression_shapes, fitted_head, head_mesh, projected_edges};
use crate::fit::FitArgs;
use crate::video_input::{Frames, VideoArgs};
use mannequin_io::progress::{JobTimer, bar};

/// Frames whose full fits are averaged into the video's face shape.
const SHAPE_FRAMES: usize = 5;
/// The animation's rate when frames come from a folder and no --fps is given.
const DEFAULT_FPS: f64 = 30.0;

#[derive(clap::Args)]
pub struct FaceTrackArgs {
    #[command(flatten)]
    input: VideoArgs,
    #[command(flatten)]
    fitting: FitArgs,
    /// Output folder. A track that was stopped resumes from its checkpoint there.
    #[arg(long)]
    out: PathBuf,
    /// Ignore a checkpoint in --out and start over.
    #[arg(long)]
    restart: bool,
}

/// Frames between checkpoints, in each stage.
const CHECKPOINT_EVERY: usize = 50;

/// What changes a track's result: a checkpoint of other settings is refused.
#[derive(serde::Serialize, serde::Deserialize, PartialEq)]
struct TrackRun {
    /// Each source frame's file name and hash, or the video's.
    source: Vec<String>,
    fps: Option<f64>,
    max_frames: Option<usize>,
    focal: Option<f64>,
}

/// What a track has done so far: per frame read, its face mesh (None: no face); the video's
/// shape once fitted; per frame fitted, its fit.
#[derive(Default)]
struct Done {
    landmarks: Vec<Option<FaceLandmarks>>,
    shape: Option<Vec<f32>>,
    fits: Vec<Option<FaceFit>>,
}

pub fn track(args: FaceTrackArgs) -> Result<()> {
    let _timer = JobTimer::start("face track");
    let start = Instant::now();
    check_face_body(&args.fitting)?;
    let scratch = args.out.with_extension("frames.partial");
    let frames = args.input.frames(&scratch)?;
    let result = track_frames(&args, &frames, start);
    if frames.decoded {
        let _ = std::fs::remove_dir_all(&scratch);
    }
    result
}

fn track_frames(args: &FaceTrackArgs, frames: &Frames, start: Instant) -> Result<()> {
    let Frames { dir, files, .. } = frames;
    if files.is_empty() {
        bail!("{}: no frames (PNG or JPEG) to track", dir.display());
    }
    let run = TrackRun {
        source: args.input.source(files)?,
        fps: args.input.fps,
        max_frames: args.input.max_frames,
        focal: args.fitting.focal,
    };
    let checkpoint = args.out.join(CHECKPOINT);
    let first = Image::read(&files[0])?;
    let (width, height) = (first.width, first.height);
    let (body, face) = (BodyModel::default_body(), FaceModel::default_face());
    let fitter = FaceFitter::new(&body, &face, width, height, args.fitting.focal(width, height)?)?;
    let mut done = match !args.restart && checkpoint.exists() {
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
            bail!(
                "{}: {}×{} pixels, but the first frame is {width}×{height}; a video's frames share one size",
                file.display(),
                image.width,
                image.height
            );
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
        let _ = std::fs::remove_dir(&args.out);
        bail!(
            "{}: no face found in any of its {} frames (the detector finds faces turned less than about 60° from the camera)",
            dir.display(),
            files.len()
        );
    };
    let side = face_side(done.landmarks[first].as_ref().expect("found"));
    if side < MIN_FACE_PX {
        bail!(
            "{}: the face is {side:.0} pixels across; tracking needs at least {MIN_FACE_PX}",
            files[first].display()
        );
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
    let overlays = args.out.join("overlay");
    std::fs::create_dir_all(&overlays).with_context(|| format!("creating {}", overlays.display()))?;
    let progress = bar(files.len() as u64, "face fit");
    progress.set_position(done.fits.len() as u64);
    for (i, file) in files.iter().enumerate().skip(done.fits.len()) {
        // A lost face starts the next stretch afresh rather than from a stale pose.
        let last = done.fits.last().and_then(Option::as_ref);
        let fit = match &done.landmarks[i] {
            Some(landmarks) => Some(
                fitter
                    .track(landmarks, &shape, last)
                    .with_context(|| format!("fitting the face in {}", file.display()))?,
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

    let fps = args.input.fps.unwrap_or(DEFAULT_FPS);
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
    write_blend_shape_glb(args.out.join("face.glb"), &shapes, Some(&animation(&done.fits, fps)))?;
    write_video(&overlays, &args.out.join("overlay.mp4"), files.len(), fps as f32)?;
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
    let path = args.out.join("track.json");
    mannequin_io::write_atomic(&path, serde_json::to_string_pretty(&report)?.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    if checkpoint.exists() {
        std::fs::remove_file(&checkpoint).with_context(|| format!("removing {}", checkpoint.display()))?;
    }
    let errors: Vec<f32> = done.fits.iter().flatten().map(FaceFit::mean_error_iod).collect();
    tracing::info!(
        "tracked the face in {} of {} frames: landmark error {:.2} % of the eyes' distance (mean over frames), {:.1} frames per second; wrote {}",
        found.len(),
        files.len(),
        100.0 * errors.iter().sum::<f32>() / errors.len() as f32,
        per_second,
        args.out.display()
    );
    Ok(())
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
) -> Result<Vec<f32>> {
    let picks = spread(found);
    let fits: Vec<FaceFit> = picks
        .par_iter()
        .map(|&i| {
            let landmarks = landmarks[i].as_ref().expect("picked among frames with a face");
            fitter.fit(landmarks).with_context(|| format!("fitting the face in {}", files[i].display()))
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

fn write_checkpoint(path: &Path, run: &TrackRun, done: &Done) -> Result<()> {
    let dir = path.parent().context("the checkpoint's folder")?;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut w = NpzWriter::new();
    add_run(&mut w, run)?;
    let found: Vec<&FaceLandmarks> = done.landmarks.iter().flatten().collect();
    let k = found.len();
    w.add(
        "found",
        NpyArray::i64(
            vec![done.landmarks.len()],
            done.landmarks.iter().map(|l| l.is_some() as i64).collect(),
        ),
    );
    w.add(
        "points",
        NpyArray::f32(
            vec![k, NUM_LANDMARKS, 3],
            found.iter().flat_map(|l| l.points.iter().flatten().copied()).collect(),
        ),
    );
    let rect = |r: &RotatedRect| [r.cx, r.cy, r.width, r.height, r.rotation];
    w.add("roi", NpyArray::f32(vec![k, 5], found.iter().flat_map(|l| rect(&l.roi)).collect()));
    w.add("flag", NpyArray::f32(vec![k], found.iter().map(|l| l.flag).collect()));
    if let Some(shape) = &done.shape {
        w.add("shape", NpyArray::f32(vec![shape.len()], shape.clone()));
    }
    w.add(
        "fitted",
        NpyArray::i64(vec![done.fits.len()], done.fits.iter().map(|f| f.is_some() as i64).collect()),
    );
    let fits: Vec<&FaceFit> = done.fits.iter().flatten().collect();
    let m = fits.len();
    w.add(
        "rotation_vector",
        NpyArray::f64(vec![m, 3], fits.iter().flat_map(|f| f.rotation_vector.to_array()).collect()),
    );
    w.add(
        "translation",
        NpyArray::f64(vec![m, 3], fits.iter().flat_map(|f| f.translation.to_array()).collect()),
    );
    let e = fits.first().map_or(0, |f| f.expression.len());
    w.add(
        "expression",
        NpyArray::f32(vec![m, e], fits.iter().flat_map(|f| f.expression.iter().copied()).collect()),
    );
    w.write(path).with_context(|| format!("writing {}", path.display()))
}

/// What [`write_checkpoint`] stored, the fits rebuilt on their landmarks; refused when it is
/// another run's.
fn read_checkpoint(path: &Path, run: &TrackRun, fitter: &FaceFitter) -> Result<Done> {
    let npz = Npz::read(path)?;
    check_run(&npz, path, run)?;
    let flags = |key: &str| -> Result<Vec<bool>> {
        let v = npz.require(key)?.to_i64().ok_or_else(|| npz.field_error(key, "0 or 1 per frame"))?;
        Ok(v.into_iter().map(|x| x != 0).collect())
    };
    let read =
        |key: &str, shape: &[Option<usize>]| -> Result<Vec<f64>> { Ok(npz.f64_with_shape(key, shape)?.1) };
    let found = flags("found")?;
    let k = Some(found.iter().filter(|f| **f).count());
    let points = read("points", &[k, Some(NUM_LANDMARKS), Some(3)])?;
    let roi = read("roi", &[k, Some(5)])?;
    let flag = read("flag", &[k])?;
    let mut next = 0;
    let landmarks: Vec<Option<FaceLandmarks>> = found
        .iter()
        .map(|&f| {
            f.then(|| {
                let i = next;
                next += 1;
                let r = &roi[5 * i..5 * i + 5];
                FaceLandmarks {
                    roi: RotatedRect {
                        cx: r[0] as f32,
                        cy: r[1] as f32,
                        width: r[2] as f32,
                        height: r[3] as f32,
                        rotation: r[4] as f32,
                    },
                    flag: flag[i] as f32,
                    points: points[i * 3 * NUM_LANDMARKS..(i + 1) * 3 * NUM_LANDMARKS]
                        .chunks_exact(3)
                        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
                        .collect(),
                }
            })
        })
        .collect();
    let shape: Option<Vec<f32>> = match npz.contains("shape") {
        true => Some(read("shape", &[None])?.into_iter().map(|v| v as f32).collect()),
        false => None,
    };
    let fitted = flags("fitted")?;
    if fitted.len() > landmarks.len() || (!fitted.is_empty() && shape.is_none()) {
        bail!("{}: fitted: more frames fitted than read, or fits without the shape", path.display());
    }
    let m = fitted.iter().filter(|f| **f).count();
    let rotation = read("rotation_vector", &[Some(m), Some(3)])?;
    let translation = read("translation", &[Some(m), Some(3)])?;
    let expression = read("expression", &[Some(m), None])?;
    let e = expression.len() / m.max(1);
    let mut next = 0;
    let mut fits = Vec::with_capacity(fitted.len());
    for (i, &f) in fitted.iter().enumerate() {
        let (Some(face), true) = (&landmarks[i], f) else {
            fits.push(None);
            continue;
        };
        let j = next;
        next += 1;
        let r = &rotation[3 * j..3 * j + 3];
        let t = &translation[3 * j..3 * j + 3];
        let coefficients: Vec<f32> = expression[e * j..e * (j + 1)].iter().map(|&v| v as f32).collect();
        let fit = fitter.at(
            face,
            shape.as_deref().expect("checked above"),
            &coefficients,
            DVec3::new(r[0], r[1], r[2]),
            DVec3::new(t[0], t[1], t[2]),
        )?;
        fits.push(Some(fit));
    }
    Ok(Done { landmarks, shape, fits })
}
