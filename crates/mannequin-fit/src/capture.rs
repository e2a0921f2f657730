//! A person's own video to a dataset `mannequin train` reads (`mannequin capture`, the
//! PeopleSnapshot layout): frames, the person's masks, one static camera (the person turns in
//! front of it, as in PeopleSnapshot) and the body fitted in every frame ([`crate::clip_fit`]),
//! plus an overlay per frame to check the fit by. A checkpoint every few frames and after each
//! fit pass lets a stopped capture resume; a finished one removes it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use mannequin_body::BodyModel;
use mannequin_data::{DatasetWriter, Frame, Image};
use mannequin_io::progress::bar;

use crate::body_fit::{BodyFit, Fitter};
use crate::capture_checkpoint::{CaptureRun, Saved, read_checkpoint, write_checkpoint};
use crate::capture_dataset::write_dataset;
use crate::clip_fit::{ClipFit, Tracker, resolve_mirrors};
use crate::error::FitError;
use crate::fit_check::{check_picture, posed_mesh};
use crate::fit_settings::FitSettings;
use crate::frame_source::{FrameSource, Frames};
use crate::output::{CHECKPOINT, create_dir, write_report};
use crate::person_models::PersonModels;
use crate::pose_landmarker::PoseLandmarks;

/// Frames tracked between checkpoints.
const CHECKPOINT_EVERY: usize = 10;
/// The fewest frames a dataset can be split from: one to train on and one held out to test
/// (the dataset holds out the last tenth, at least one).
const MIN_FRAMES: usize = 2;
/// A person found in fewer than this share of the clip's frames is lost for most of it: what
/// is left is not their clip (someone else's, or a few stray frames).
const MIN_FOUND_SHARE: f64 = 0.5;

/// Everything a capture reads: its frames, the body and camera, and where it writes.
#[derive(Clone, Debug, Default, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
pub struct CaptureSettings {
    #[command(flatten)]
    pub input: FrameSource,
    #[command(flatten)]
    pub fitting: FitSettings,
    /// The dataset folder to write. A capture that was stopped resumes from its checkpoint there.
    #[arg(long)]
    pub out: PathBuf,
    /// The person stands still and the camera moves: write the body held where the first frame
    /// has it and a camera per frame (the same fit, seen the other way) instead of one static
    /// camera and the body turning in front of it.
    #[arg(long)]
    pub moving_camera: bool,
    /// Which person to capture, counting from 0 in order of size (largest first) in the first
    /// frame anyone is found in; followed from there by where they were in the frame before.
    #[arg(long)]
    pub person: Option<usize>,
    /// Ignore a checkpoint in --out and start over.
    #[arg(long)]
    pub restart: bool,
}

/// How a capture went, for the closing line.
pub struct CaptureSummary {
    pub kept: usize,
    pub left_out: usize,
}

/// Captures, and where the run fails without a checkpoint to resume from, removes the output
/// folder when it is the capture's own (made by it, or holding a capture's checkpoint): nothing
/// half-made is left to mistake for a dataset. A run with a checkpoint keeps its folder, so that
/// running it again resumes; a refusal that resuming cannot mend removes the checkpoint first.
pub fn capture(settings: &CaptureSettings) -> Result<CaptureSummary, FitError> {
    let checkpoint = settings.out.join(CHECKPOINT);
    let ours = !settings.out.exists() || checkpoint.exists();
    let result = capture_into(settings);
    if result.is_err() && ours && !checkpoint.exists() {
        let _ = std::fs::remove_dir_all(&settings.out);
    }
    result
}

fn capture_into(settings: &CaptureSettings) -> Result<CaptureSummary, FitError> {
    let start = Instant::now();
    let out = &settings.out;
    settings.fitting.check()?;
    let Frames { dir, files, decoded } = settings.input.frames(out)?;
    if files.len() < MIN_FRAMES {
        let what = match &settings.input.video {
            Some(video) => video.display().to_string(),
            None => dir.display().to_string(),
        };
        return Err(FitError::input(
            what,
            format!(
                "{} frame(s); a capture needs at least {MIN_FRAMES} (one to train on, one held out to test)",
                files.len()
            ),
        ));
    }
    same_size(&files)?;
    let run = CaptureRun {
        source: settings.input.fingerprint(&files)?,
        fps: settings.input.fps,
        max_frames: settings.input.max_frames,
        body: settings.fitting.body.clone(),
        focal: settings.fitting.focal,
        person: settings.person,
    };
    create_dir(out)?;
    let checkpoint = out.join(CHECKPOINT);
    let mut saved = if !settings.restart && checkpoint.exists() {
        let saved = read_checkpoint(&checkpoint, &run, out)?;
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
    let model = settings.fitting.body_model()?;
    let models = PersonModels::load()?;
    track(&models, &files, out, &checkpoint, &run, &mut saved)?;
    let (width, height) = (saved.kept[0].1.width, saved.kept[0].1.height);
    let focal = settings.fitting.focal(width, height)?;
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
    write_dataset(out, &model, &fits, settings.moving_camera)?;
    let ious = write_overlays(out, &model, kept, &people_read, &fits)?;
    if decoded {
        std::fs::remove_dir_all(&dir).map_err(FitError::file("removing", &dir))?;
    }
    let report = report(kept, &fits, &ious, skipped, &mirrored, focal, start.elapsed().as_secs_f64());
    write_report(&out.join("capture.json"), &report)?;
    std::fs::remove_file(&checkpoint).map_err(FitError::file("removing", &checkpoint))?;
    Ok(CaptureSummary { kept: kept.len(), left_out: skipped.len() })
}

/// Refuses a clip whose frames differ in size, from their headers, before any work.
fn same_size(files: &[PathBuf]) -> Result<(), FitError> {
    let first = Image::read_size(&files[0])?;
    for file in &files[1..] {
        let size = Image::read_size(file)?;
        if size != first {
            return Err(FitError::input(
                file.display().to_string(),
                format!(
                    "{}×{}, but the clip's first frame ({}) is {}×{}",
                    size.0,
                    size.1,
                    files[0].display(),
                    first.0,
                    first.1
                ),
            ));
        }
    }
    Ok(())
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
) -> Result<(), FitError> {
    let writer = DatasetWriter::new(out);
    for sub in ["images", "masks", "poses"] {
        create_dir(&out.join(sub))?;
    }
    let progress = bar(files.len() as u64, "landmarks");
    progress.set_position(saved.tracked as u64);
    let last_kept = saved.kept.last().map(|(f, _)| f);
    let in_last_frame = saved.tracked > 0 && last_kept == Some(&files[saved.tracked - 1]);
    let mut tracker = Tracker::resume(models, run.person, saved.people.last(), in_last_frame);
    for (i, file) in files.iter().enumerate().skip(saved.tracked) {
        let image = Image::read(file)?;
        match tracker.next(&image).map_err(|e| FitError::within(file.display().to_string(), e))? {
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
    let needed = MIN_FRAMES.max((MIN_FOUND_SHARE * files.len() as f64).ceil() as usize);
    if saved.kept.len() < needed {
        // Resuming would refuse the same frames again: the checkpoint goes, and with it the folder.
        let _ = std::fs::remove_file(checkpoint);
        let first_lost = saved.skipped.first().unwrap_or(&files[0]);
        return Err(FitError::input(
            first_lost.display().to_string(),
            format!(
                "the first of {} frames without the person (found in {} of {}, a capture needs them \
                 in at least {needed}); cut the clip to where they are, or choose who to follow with \
                 --person N",
                saved.skipped.len(),
                saved.kept.len(),
                files.len()
            ),
        ));
    }
    write_checkpoint(checkpoint, run, saved)
}

/// `overlay/frame_%04d.png` for checking each frame's fit; the IoU of each body silhouette with
/// the person's mask.
fn write_overlays(
    out: &Path,
    model: &BodyModel,
    kept: &[(PathBuf, Image)],
    people: &[PoseLandmarks],
    fits: &[BodyFit],
) -> Result<Vec<f64>, FitError> {
    let dir = out.join("overlay");
    create_dir(&dir)?;
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
