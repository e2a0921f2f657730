//! `mannequin capture --frames DIR | --video clip.mp4 --out DATASET`: a person's own video to a
//! dataset `mannequin train` reads (the PeopleSnapshot layout): frames, the person's masks, one
//! static camera (the person turns in front of it, as in PeopleSnapshot) and the body fitted in
//! every frame (`mannequin_fit::capture`), plus an overlay per frame to check the fit by.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::{DMat3, DMat4, DVec3};
use mannequin_body::BodyModel;
use mannequin_body::rodrigues::axis_angle_quat;
use mannequin_data::layout;
use mannequin_data::maps::read_mask_npy;
use mannequin_data::splits::SplitRange;
use mannequin_data::{Camera, Cameras, DatasetWriter, Frame, Image, Poses, Splits};
use mannequin_fit::body_fit::{Fitter, FramePose};
use mannequin_fit::capture::{ClipFit, ClipProgress, Tracker, resolve_mirrors};
use mannequin_fit::crop::RotatedRect;
use mannequin_fit::pose_landmarker::{NUM_LANDMARKS, PoseLandmarks};
use mannequin_fit::{BodyFit, PersonModels};
use mannequin_io::{NpyArray, Npz, NpzWriter};

use mannequin_body::load_body;
use crate::checkpoint::{CHECKPOINT, add_run, check_run};
use crate::fit::{FitArgs, check_picture, posed_mesh};
use crate::video_input::{Frames, VideoArgs};
use mannequin_io::progress::{JobTimer, bar};

/// The last tenth of the frames (at least one) is held out as the test split.
const TEST_SHARE: usize = 10;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    input: VideoArgs,
    #[command(flatten)]
    fitting: FitArgs,
    /// The dataset folder to write. A capture that was stopped resumes from its checkpoint there.
    #[arg(long)]
    out: PathBuf,
    /// The person stands still and the camera moves: write the body held where the first frame
    /// has it and a camera per frame (the same fit, seen the other way) instead of one static
    /// camera and the body turning in front of it.
    #[arg(long)]
    moving_camera: bool,
    /// Ignore a checkpoint in --out and start over.
    #[arg(long)]
    restart: bool,
}

/// Frames tracked between checkpoints.
const CHECKPOINT_EVERY: usize = 10;

/// What changes a capture's result: a checkpoint of other settings is refused.
#[derive(serde::Serialize, serde::Deserialize, PartialEq)]
struct CaptureRun {
    /// Each source frame's file name and hash, or the video's.
    source: Vec<String>,
    fps: Option<f64>,
    max_frames: Option<usize>,
    body: String,
    focal: Option<f64>,
}

/// Captures, and where the run fails before its first checkpoint, removes the output folder it
/// made: nothing half-made is left to mistake for a dataset. A run with a checkpoint keeps its
/// folder, so that running it again resumes.
pub fn run(args: Args) -> Result<()> {
    let fresh = !args.out.exists();
    let out = args.out.clone();
    let result = capture(args);
    if result.is_err() && fresh && !out.join(CHECKPOINT).exists() {
        let _ = std::fs::remove_dir_all(&out);
    }
    result
}

fn capture(args: Args) -> Result<()> {
    let _timer = JobTimer::start("capture");
    let start = Instant::now();
    args.fitting.check()?;
    let Frames { dir, files, decoded } = args.input.frames(&args.out)?;
    if files.len() < 2 {
        bail!("{}: {} frame(s); a capture needs at least 2", dir.display(), files.len());
    }
    same_size(&files)?;
    let run = CaptureRun {
        source: args.input.source(&files)?,
        fps: args.input.fps,
        max_frames: args.input.max_frames,
        body: args.fitting.body.clone(),
        focal: args.fitting.focal,
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let checkpoint = args.out.join(CHECKPOINT);
    let mut saved = if !args.restart && checkpoint.exists() {
        let saved = read_checkpoint(&checkpoint, &run, &args.out)?;
        tracing::info!(
            "resuming {} ({} of {} frames tracked, {} fit passes done)",
            checkpoint.display(),
            saved.tracked,
            files.len(),
            saved.fit.passes
        );
        saved
    } else {
        Saved::default()
    };
    let model = load_body(&args.fitting.body)?;
    let models = PersonModels::load()?;
    track(&models, &files, &args.out, &checkpoint, &run, &mut saved)?;
    let (width, height) = (saved.kept[0].1.width, saved.kept[0].1.height);
    let focal = args.fitting.focal(width, height)?;
    let fitter = Fitter::new(&model, width, height, focal)?;
    // The fit reads the landmarks with the mirrors undone; the checkpoint keeps them as read.
    let mut people_read = saved.people.clone();
    let mirrored = resolve_mirrors(&fitter, &mut people_read);
    let mut clip = ClipFit::new(&fitter, &people_read, std::mem::take(&mut saved.fit))?;
    let progress = bar(ClipFit::steps(people_read.len()) as u64, "body fit");
    progress.set_position(clip.steps_done() as u64);
    while clip.next_pass(&mut || progress.inc(1))? {
        saved.fit = clip.progress.clone();
        write_checkpoint(&checkpoint, &run, &saved)?;
    }
    progress.finish();
    let fits = clip.fits()?;
    let Saved { kept, skipped, .. } = &saved;
    write_dataset(&args.out, &model, &fits, args.moving_camera)?;
    let ious = write_overlays(&args.out, &model, kept, &people_read, &fits)?;
    if decoded {
        std::fs::remove_dir_all(&dir).with_context(|| format!("removing {}", dir.display()))?;
    }
    let report = report(kept, &fits, &ious, skipped, &mirrored, focal, start.elapsed().as_secs_f64());
    mannequin_io::write_atomic(
        &args.out.join("capture.json"),
        serde_json::to_string_pretty(&report)?.as_bytes(),
    )
    .with_context(|| format!("writing {}", args.out.join("capture.json").display()))?;
    std::fs::remove_file(&checkpoint).with_context(|| format!("removing {}", checkpoint.display()))?;
    tracing::info!(
        "captured {} frames ({} without the person left out) into {}",
        kept.len(),
        skipped.len(),
        args.out.display()
    );
    Ok(())
}

/// Refuses a clip whose frames differ in size, from their headers, before any work.
fn same_size(files: &[PathBuf]) -> Result<()> {
    let first = Image::read_size(&files[0])?;
    for file in &files[1..] {
        let size = Image::read_size(file)?;
        if size != first {
            bail!(
                "{}: {}×{}, but the clip's first frame ({}) is {}×{}",
                file.display(),
                size.0,
                size.1,
                files[0].display(),
                first.0,
                first.1
            );
        }
    }
    Ok(())
}

/// What a capture has done so far: frames tracked (the kept ones written to the dataset as they
/// come), and the fit's passes.
#[derive(Default)]
struct Saved {
    /// Source frames looked at, kept or not.
    tracked: usize,
    kept: Vec<(PathBuf, Image)>,
    people: Vec<PoseLandmarks>,
    skipped: Vec<PathBuf>,
    fit: ClipProgress,
}

/// Each frame's image and the person's landmarks, from where `saved` left off; frames where nobody
/// is found are left out and named. Each kept frame's image and mask go into the dataset as it
/// comes, and a checkpoint every few frames.
fn track(
    models: &PersonModels,
    files: &[PathBuf],
    out: &Path,
    checkpoint: &Path,
    run: &CaptureRun,
    saved: &mut Saved,
) -> Result<()> {
    let writer = DatasetWriter::new(out);
    for sub in ["images", "masks", "poses"] {
        std::fs::create_dir_all(out.join(sub))
            .with_context(|| format!("creating {}", out.join(sub).display()))?;
    }
    let progress = bar(files.len() as u64, "landmarks");
    progress.set_position(saved.tracked as u64);
    let last_kept = saved.kept.last().map(|(f, _)| f);
    let followed = (saved.tracked > 0 && last_kept == Some(&files[saved.tracked - 1]))
        .then(|| saved.people.last().map(|l| l.next_roi))
        .flatten();
    let mut tracker = Tracker::resume(models, followed);
    for (i, file) in files.iter().enumerate().skip(saved.tracked) {
        let image = Image::read(file)?;
        match tracker.next(&image).with_context(|| file.display().to_string())? {
            Some(l) => {
                let mask = l.person_mask(image.width, image.height);
                let frame = Frame { index: saved.kept.len(), image, mask, normals: None, depth: None };
                writer.write_frame(&frame)?;
                saved.people.push(l);
                saved.kept.push((file.clone(), frame.image));
            }
            None => saved.skipped.push(file.clone()),
        }
        saved.tracked = i + 1;
        if saved.tracked.is_multiple_of(CHECKPOINT_EVERY) && saved.tracked < files.len() {
            write_checkpoint(checkpoint, run, saved)?;
        }
        progress.inc(1);
    }
    progress.finish();
    if saved.kept.len() < 2 {
        bail!(
            "the person was found in {} of {} frames; a capture needs at least 2",
            saved.kept.len(),
            files.len()
        );
    }
    write_checkpoint(checkpoint, run, saved)
}

/// Stores what `saved` holds but the dataset already has (each kept frame's image and mask).
fn write_checkpoint(path: &Path, run: &CaptureRun, saved: &Saved) -> Result<()> {
    let mut w = NpzWriter::new();
    add_run(&mut w, run)?;
    let k = saved.people.len();
    let names = |files: &mut dyn Iterator<Item = &PathBuf>| -> Result<String> {
        Ok(serde_json::to_string(&files.map(|f| f.display().to_string()).collect::<Vec<_>>())?)
    };
    w.add("tracked", NpyArray::i64(vec![1], vec![saved.tracked as i64]));
    w.add("kept", NpyArray::text(&names(&mut saved.kept.iter().map(|(f, _)| f))?));
    w.add("skipped", NpyArray::text(&names(&mut saved.skipped.iter())?));
    let per_landmark = |f: &dyn Fn(&PoseLandmarks) -> Vec<f32>, width: usize| {
        NpyArray::f32(vec![k, NUM_LANDMARKS, width], saved.people.iter().flat_map(f).collect())
    };
    w.add("points", per_landmark(&|l| l.points.iter().flatten().copied().collect(), 3));
    w.add("world", per_landmark(&|l| l.world.iter().flatten().copied().collect(), 3));
    w.add("visibility", per_landmark(&|l| l.visibility.clone(), 1));
    w.add("presence", per_landmark(&|l| l.presence.clone(), 1));
    let rect = |r: &RotatedRect| [r.cx, r.cy, r.width, r.height, r.rotation];
    w.add("roi", NpyArray::f32(vec![k, 5], saved.people.iter().flat_map(|l| rect(&l.roi)).collect()));
    w.add(
        "next_roi",
        NpyArray::f32(vec![k, 5], saved.people.iter().flat_map(|l| rect(&l.next_roi)).collect()),
    );
    w.add("flag", NpyArray::f32(vec![k], saved.people.iter().map(|l| l.flag).collect()));
    let fit = &saved.fit;
    w.add("passes", NpyArray::i64(vec![1], vec![fit.passes as i64]));
    w.add("betas", NpyArray::f32(vec![fit.betas.len()], fit.betas.clone()));
    let poses = fit.frames.iter().flat_map(|f| f.pose.iter().copied()).collect();
    w.add("poses", NpyArray::f32(vec![fit.frames.len(), 72], poses));
    w.add(
        "transl",
        NpyArray::f32(vec![fit.frames.len(), 3], fit.frames.iter().flat_map(|f| f.transl).collect()),
    );
    w.write(path)?;
    Ok(())
}

/// What [`write_checkpoint`] stored, with the kept frames' images and masks read back from the
/// dataset; refused when it is another run's.
fn read_checkpoint(path: &Path, run: &CaptureRun, out: &Path) -> Result<Saved> {
    let npz = Npz::read(path)?;
    check_run(&npz, path, run)?;
    let count = |key: &str| -> Result<usize> {
        let v = npz.require(key)?.to_i64().and_then(|n| n.first().copied()).unwrap_or(-1);
        Ok(usize::try_from(v).map_err(|_| npz.field_error(key, "a count"))?)
    };
    let names = |key: &str| -> Result<Vec<PathBuf>> {
        let names: Vec<String> = serde_json::from_str(npz.text(key)?)
            .with_context(|| format!("{}: {key}: expected a JSON list of file names", path.display()))?;
        Ok(names.into_iter().map(PathBuf::from).collect())
    };
    let kept_files = names("kept")?;
    let k = kept_files.len();
    let read = |key: &str, shape: &[Option<usize>]| -> Result<Vec<f32>> {
        Ok(npz.f64_with_shape(key, shape)?.1.into_iter().map(|v| v as f32).collect())
    };
    let (n, k3) = (Some(NUM_LANDMARKS), Some(k));
    let points = read("points", &[k3, n, Some(3)])?;
    let world = read("world", &[k3, n, Some(3)])?;
    let visibility = read("visibility", &[k3, n, Some(1)])?;
    let presence = read("presence", &[k3, n, Some(1)])?;
    let roi = read("roi", &[k3, Some(5)])?;
    let next_roi = read("next_roi", &[k3, Some(5)])?;
    let flag = read("flag", &[k3])?;
    let rect = |r: &[f32]| RotatedRect { cx: r[0], cy: r[1], width: r[2], height: r[3], rotation: r[4] };
    let mut kept = Vec::with_capacity(k);
    let mut people = Vec::with_capacity(k);
    for (i, file) in kept_files.into_iter().enumerate() {
        let image = Image::read(&layout::image(out, i))?;
        let mask = read_mask_npy(&layout::mask(out, i))?;
        let triples = |v: &[f32]| {
            v[i * 3 * NUM_LANDMARKS..(i + 1) * 3 * NUM_LANDMARKS]
                .chunks_exact(3)
                .map(|p| [p[0], p[1], p[2]])
                .collect()
        };
        let singles = |v: &[f32]| v[i * NUM_LANDMARKS..(i + 1) * NUM_LANDMARKS].to_vec();
        people.push(PoseLandmarks {
            roi: rect(&roi[5 * i..5 * i + 5]),
            flag: flag[i],
            points: triples(&points),
            visibility: singles(&visibility),
            presence: singles(&presence),
            world: triples(&world),
            next_roi: rect(&next_roi[5 * i..5 * i + 5]),
            // The mask as the fit reads it: the person where the probability passed one half.
            mask: mask.values.iter().map(|&b| if b { 1.0 } else { 0.0 }).collect(),
        });
        kept.push((file, image));
    }
    let passes = count("passes")?;
    let betas = read("betas", &[None])?;
    let frames = if passes > 0 {
        let poses = read("poses", &[k3, Some(72)])?;
        let transl = read("transl", &[k3, Some(3)])?;
        (0..k)
            .map(|i| FramePose {
                pose: poses[72 * i..72 * i + 72].to_vec(),
                transl: [transl[3 * i], transl[3 * i + 1], transl[3 * i + 2]],
            })
            .collect()
    } else {
        Vec::new()
    };
    Ok(Saved {
        tracked: count("tracked")?,
        kept,
        people,
        skipped: names("skipped")?,
        fit: ClipProgress { passes, betas, frames },
    })
}

/// The dataset's cameras, poses and splits (its frames are written as they are tracked): one
/// static camera, or with `moving_camera` the body held still and a camera per frame.
fn write_dataset(out: &Path, model: &BodyModel, fits: &[BodyFit], moving_camera: bool) -> Result<()> {
    let writer = DatasetWriter::new(out);
    let mut all = Poses {
        betas: fits[0].betas.clone(),
        global_orient: fits.iter().map(|f| [f.pose[0], f.pose[1], f.pose[2]]).collect(),
        body_pose: fits.iter().flat_map(|f| f.pose[3..].iter().copied()).collect(),
        transl: fits.iter().map(|f| f.transl).collect(),
    };
    if moving_camera {
        writer.write_cameras(&Cameras::PerFrame(moving_cameras(model, fits)?))?;
        let (orient, transl) = (all.global_orient[0], all.transl[0]);
        all.global_orient.fill(orient);
        all.transl.fill(transl);
    } else {
        writer.write_cameras(&Cameras::Static(fits[0].camera.clone()))?;
    }
    let n = fits.len();
    let test = (n / TEST_SHARE).max(1);
    let mut splits = Splits::new();
    splits.insert("train".into(), SplitRange::new(0, n - test - 1, 1));
    splits.insert("test".into(), SplitRange::new(n - test, n - 1, 1));
    splits.insert("val".into(), SplitRange::new(n - test, n - test, 1));
    for (name, range) in &splits {
        writer.write_poses(name, &all.select(&range.frames()))?;
    }
    writer.write_splits(&splits)?;
    Ok(())
}

/// The clip seen the other way, for a person standing still while the camera moves: the body
/// held where frame 0 has it, and a camera per frame. Frame i's body is its root-relative pose
/// moved by Mᵢ (its orientation about the rest root joint, then its translation), so the camera
/// E·Mᵢ·M₀⁻¹ sees frame 0's placement exactly as E sees frame i's.
fn moving_cameras(model: &BodyModel, fits: &[BodyFit]) -> Result<Vec<Camera>> {
    let rest = mannequin_body::forward(model, &fits[0].betas, &[0.0; 72], &[0.0; 3])?;
    let root = DVec3::new(rest.joints[0] as f64, rest.joints[1] as f64, rest.joints[2] as f64);
    let placement = |f: &BodyFit| {
        let turn = DMat3::from_quat(axis_angle_quat([f.pose[0], f.pose[1], f.pose[2]]).as_dquat());
        let t = DVec3::new(f.transl[0] as f64, f.transl[1] as f64, f.transl[2] as f64);
        DMat4::from_mat3_translation(turn, root + t - turn * root)
    };
    let first = placement(&fits[0]).inverse();
    Ok(fits
        .iter()
        .map(|f| {
            let seen = DMat4::from_cols_array_2d(&f.camera.extrinsic).transpose() * placement(f) * first;
            Camera { extrinsic: seen.transpose().to_cols_array_2d(), ..f.camera.clone() }
        })
        .collect())
}

/// `overlay/frame_%04d.png` for checking each frame's fit; the IoU of each body silhouette with
/// the person's mask.
fn write_overlays(
    out: &Path,
    model: &BodyModel,
    kept: &[(PathBuf, Image)],
    people: &[PoseLandmarks],
    fits: &[BodyFit],
) -> Result<Vec<f64>> {
    let dir = out.join("overlay");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let progress = bar(kept.len() as u64, "overlays");
    let mut ious = Vec::with_capacity(kept.len());
    for (i, (((_, image), person), fit)) in kept.iter().zip(people).zip(fits).enumerate() {
        let (picture, iou) = check_picture(image, &posed_mesh(model, fit)?, person, fit);
        picture.write_png(&dir.join(format!("frame_{i:04}.png")))?;
        ious.push(iou);
        progress.inc(1);
    }
    progress.finish();
    Ok(ious)
}

fn report(
    kept: &[(PathBuf, Image)],
    fits: &[BodyFit],
    ious: &[f64],
    skipped: &[PathBuf],
    mirrored: &[usize],
    focal: f64,
    seconds: f64,
) -> serde_json::Value {
    serde_json::json!({
        "frames": kept.iter().zip(fits).zip(ious).map(|(((file, _), f), iou)| serde_json::json!({
            "source": file.display().to_string(),
            "median_landmark_error_px": f.median_error_px(),
            "mask_iou": iou,
        })).collect::<Vec<_>>(),
        "mean_mask_iou": ious.iter().sum::<f64>() / ious.len() as f64,
        "left_out": skipped.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        "read_mirrored": mirrored.iter().map(|&i| kept[i].0.display().to_string()).collect::<Vec<_>>(),
        "betas": fits[0].betas,
        "focal_px": focal,
        "seconds": seconds,
    })
}
