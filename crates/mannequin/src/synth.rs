//! `mannequin synth`: write a synthetic subject with full ground truth in the dataset layout.

use std::path::PathBuf;

use mannequin_body::BodyModel;
use mannequin_synth::{Step, SynthOptions, generate};

use mannequin_io::progress::{JobTimer, bar};

#[derive(clap::Args)]
pub struct Args {
    /// Seed of every random choice (shape, outfit, prints, motion).
    #[arg(long, default_value_t = SynthOptions::default().seed)]
    seed: u64,
    /// Output folder (created); the capture goes at its root, test sets under test/.
    #[arg(long)]
    out: PathBuf,
    /// Body model: `default`, `default-lod1`, or a SMPL-family .npz.
    #[arg(long, default_value = "default")]
    body: String,
    /// Image width and height in pixels.
    #[arg(long, default_value_t = SynthOptions::default().size)]
    size: usize,
    /// Render at this multiple of the size and box-filter down (anti-aliasing).
    #[arg(long, default_value_t = SynthOptions::default().supersample)]
    supersample: usize,
    /// Frames of the turning capture, 1/30 s apart (fewer than 60 are further apart: the
    /// subject turns at most 7.5° in 1/30 s, for the cloth to follow).
    #[arg(long, default_value_t = SynthOptions::default().capture_frames)]
    frames: usize,
    /// Of those, the first N form the training split; the rest are the test split.
    #[arg(long, default_value_t = SynthOptions::default().train_frames)]
    train: usize,
    /// Simulate the garments without cloth–cloth contacts: about 2.5× faster, but folds and
    /// layers may pass through each other.
    #[arg(long)]
    no_self_collision: bool,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let _timer = JobTimer::start("synth");
    let model = BodyModel::from_spec(&args.body, None)?;
    let options = SynthOptions {
        seed: args.seed,
        size: args.size,
        supersample: args.supersample,
        capture_frames: args.frames,
        train_frames: args.train,
        // Novel views re-render training poses: no more than there are.
        view_poses: SynthOptions::default().view_poses.min(args.train),
        self_collision: !args.no_self_collision,
        ..SynthOptions::default()
    };
    // Simulated cloth frames and written frames, the length growing as each part is planned.
    let progress = bar(0, "synth");
    let summary = generate(&model, &args.out, &options, &|step| match step {
        Step::Planned(steps) => progress.inc_length(steps as u64),
        Step::Simulated | Step::Written => progress.inc(1),
    })?;
    progress.finish_and_clear();
    tracing::info!(
        "wrote {} ({:?}, {} vertices): {} capture frames, {} novel-view and {} novel-pose frames",
        args.out.display(),
        summary.subject.outfit,
        summary.vertices,
        options.capture_frames,
        options.view_poses * summary.novel_view_cameras.len(),
        options.motion_frames * summary.novel_pose_motions.len()
    );
    Ok(())
}
