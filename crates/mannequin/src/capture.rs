//! `mannequin capture --frames DIR | --video clip.mp4 --out DATASET`: a person's own video to a
//! dataset `mannequin train` reads (the PeopleSnapshot layout): frames, the person's masks, one
//! static camera (the person turns in front of it, as in PeopleSnapshot) and the body fitted in
//! every frame (`mannequin_fit::capture`), plus an overlay per frame to check the fit by.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use mannequin_body::BodyModel;
use mannequin_data::layout::IMAGE_EXTENSIONS;
use mannequin_data::splits::SplitRange;
use mannequin_data::{Cameras, DatasetWriter, Frame, Image, Poses, Splits};
use mannequin_fit::body_fit::Fitter;
use mannequin_fit::capture::{Tracker, fit_clip, fit_clip_steps};
use mannequin_fit::pose_landmarker::PoseLandmarks;
use mannequin_fit::{BodyFit, PersonModels};

use crate::body::load_body;
use crate::fit::{FitArgs, check_picture, posed_mesh};
use crate::progress::{JobTimer, bar};

/// The last tenth of the frames (at least one) is held out as the test split.
const TEST_SHARE: usize = 10;

#[derive(clap::Args)]
pub struct Args {
    /// A folder of frames (PNG or JPEG), taken in file-name order.
    #[arg(long, conflicts_with = "video", required_unless_present = "video")]
    frames: Option<PathBuf>,
    /// A video file, decoded by the ffmpeg program.
    #[arg(long)]
    video: Option<PathBuf>,
    /// Frames per second taken from the video (default: every frame).
    #[arg(long)]
    fps: Option<f64>,
    /// Use at most this many frames, from the start.
    #[arg(long)]
    max_frames: Option<usize>,
    #[command(flatten)]
    fitting: FitArgs,
    /// The dataset folder to write.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("capture");
    let start = Instant::now();
    args.fitting.check()?;
    let decoded = match &args.video {
        Some(video) => Some(decode_video(video, args.fps, &args.out)?),
        None => None,
    };
    let dir = decoded.as_deref().or(args.frames.as_deref()).context("give --frames DIR or --video FILE")?;
    let mut files = frame_files(dir)?;
    if let Some(n) = args.max_frames {
        files.truncate(n);
    }
    if files.len() < 2 {
        bail!("{}: {} frame(s); a capture needs at least 2", dir.display(), files.len());
    }
    let model = load_body(&args.fitting.body)?;
    let models = PersonModels::load()?;
    let (kept, people, skipped) = track(&models, &files)?;
    let (width, height) = (kept[0].1.width, kept[0].1.height);
    let focal = args.fitting.focal(width, height);
    let fitter = Fitter::new(&model, width, height, focal)?;
    let progress = bar(fit_clip_steps(people.len()) as u64, "body fit");
    let fits = fit_clip(&fitter, &people, &mut || progress.inc(1))?;
    progress.finish();
    write_dataset(&args.out, &kept, &people, &fits)?;
    let ious = write_overlays(&args.out, &model, &kept, &people, &fits)?;
    if decoded.is_some() {
        std::fs::remove_dir_all(dir).with_context(|| format!("removing {}", dir.display()))?;
    }
    let report = report(&kept, &fits, &ious, &skipped, focal, start.elapsed().as_secs_f64());
    mannequin_io::write_atomic(
        &args.out.join("capture.json"),
        serde_json::to_string_pretty(&report)?.as_bytes(),
    )
    .with_context(|| format!("writing {}", args.out.join("capture.json").display()))?;
    tracing::info!(
        "captured {} frames ({} without the person left out) into {}",
        kept.len(),
        skipped.len(),
        args.out.display()
    );
    Ok(())
}

/// Decodes `video` into PNG frames under `out/.frames` with ffmpeg.
fn decode_video(video: &Path, fps: Option<f64>, out: &Path) -> Result<PathBuf> {
    if !video.is_file() {
        bail!("{}: no such video file", video.display());
    }
    let dir = out.join(".frames");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut cmd = Command::new("ffmpeg");
    cmd.args(["-loglevel", "error", "-i"]).arg(video);
    if let Some(f) = fps {
        cmd.args(["-vf", &format!("fps={f}")]);
    }
    let status = match cmd.arg(dir.join("%06d.png")).status() {
        Ok(s) => s,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => bail!(
            "--video needs the ffmpeg program, which is not on PATH: install it (Debian/Ubuntu: \
             sudo apt-get install ffmpeg; macOS: brew install ffmpeg), or pass --frames DIR with the frames as images"
        ),
        Err(e) => bail!("running ffmpeg: {e}"),
    };
    if !status.success() {
        bail!("{}: ffmpeg could not decode it ({status})", video.display());
    }
    Ok(dir)
}

/// The image files of a folder, in name order.
fn frame_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| IMAGE_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        })
        .collect();
    files.sort();
    Ok(files)
}

/// Each frame's image and the person's landmarks; frames where nobody is found are left out and
/// named.
#[allow(clippy::type_complexity)]
fn track(
    models: &PersonModels,
    files: &[PathBuf],
) -> Result<(Vec<(PathBuf, Image)>, Vec<PoseLandmarks>, Vec<PathBuf>)> {
    let progress = bar(files.len() as u64, "landmarks");
    let mut tracker = Tracker::new(models);
    let (mut kept, mut people, mut skipped) = (Vec::<(PathBuf, Image)>::new(), Vec::new(), Vec::new());
    for file in files {
        let image = Image::read(file)?;
        if let Some((_, first)) = kept.first()
            && (image.width, image.height) != (first.width, first.height)
        {
            bail!(
                "{}: {}×{}, but the clip's frames are {}×{}",
                file.display(),
                image.width,
                image.height,
                first.width,
                first.height
            );
        }
        match tracker.next(&image).with_context(|| file.display().to_string())? {
            Some(l) => {
                people.push(l);
                kept.push((file.clone(), image));
            }
            None => skipped.push(file.clone()),
        }
        progress.inc(1);
    }
    progress.finish();
    if kept.len() < 2 {
        bail!("the person was found in {} of {} frames; a capture needs at least 2", kept.len(), files.len());
    }
    Ok((kept, people, skipped))
}

fn write_dataset(
    out: &Path,
    kept: &[(PathBuf, Image)],
    people: &[PoseLandmarks],
    fits: &[BodyFit],
) -> Result<()> {
    let writer = DatasetWriter::new(out);
    for sub in ["images", "masks", "poses"] {
        std::fs::create_dir_all(out.join(sub))
            .with_context(|| format!("creating {}", out.join(sub).display()))?;
    }
    let progress = bar(kept.len() as u64, "writing");
    for (index, ((_, image), person)) in kept.iter().zip(people).enumerate() {
        let mask = person.person_mask(image.width, image.height);
        writer.write_frame(&Frame { index, image: image.clone(), mask, normals: None, depth: None })?;
        progress.inc(1);
    }
    progress.finish();
    writer.write_cameras(&Cameras::Static(fits[0].camera.clone()))?;
    let all = Poses {
        betas: fits[0].betas.clone(),
        global_orient: fits.iter().map(|f| [f.pose[0], f.pose[1], f.pose[2]]).collect(),
        body_pose: fits.iter().flat_map(|f| f.pose[3..].iter().copied()).collect(),
        transl: fits.iter().map(|f| f.transl).collect(),
    };
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
        "betas": fits[0].betas,
        "focal_px": focal,
        "seconds": seconds,
    })
}
