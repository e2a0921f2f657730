//! `mannequin face fit --image portrait.jpg --out DIR` and `mannequin face track --video clip.mp4
//! | --frames DIR --out DIR`: the default body's face fitted to a portrait
//! (`mannequin_fit::face_photo`), or followed through a video (`mannequin_fit::face_track`).

use std::path::PathBuf;

use anyhow::Result;
use clap::Subcommand;
use mannequin_fit::face_photo::fit_face_photo;
use mannequin_fit::{FaceTrackSettings, FitSettings};
use mannequin_io::progress::JobTimer;

#[derive(Subcommand)]
pub enum FaceCommand {
    /// Fit the default body's face (shape, expression, head pose) to a portrait: face.obj with
    /// colours, face.glb with the 52 expressions as morph targets, overlay.png and fit.json.
    Fit(FaceFitArgs),
    /// Follow the face through a video: shape fitted once, expression and head pose per frame;
    /// face.glb with the expressions keyed per frame, overlay frames and track.json.
    Track(FaceTrackSettings),
}

#[derive(clap::Args)]
pub struct FaceFitArgs {
    /// The portrait: PNG or JPEG.
    #[arg(long)]
    image: PathBuf,
    #[command(flatten)]
    fitting: FitSettings,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(command: FaceCommand) -> Result<()> {
    match command {
        FaceCommand::Fit(args) => fit(args),
        FaceCommand::Track(settings) => track(settings),
    }
}

fn fit(args: FaceFitArgs) -> Result<()> {
    let done = fit_face_photo(&args.image, &args.fitting, &args.out)?;
    tracing::info!(
        "fitted the face in {}: landmark error {:.2} % of the eyes' distance (mean), {:.2} s; wrote {}",
        args.image.display(),
        100.0 * done.mean_error_iod,
        done.seconds,
        args.out.display()
    );
    Ok(())
}

fn track(settings: FaceTrackSettings) -> Result<()> {
    let _timer = JobTimer::start("face track");
    let done = mannequin_fit::track_face(&settings)?;
    tracing::info!(
        "tracked the face in {} of {} frames: landmark error {:.2} % of the eyes' distance (mean over frames), {:.1} frames per second; wrote {}",
        done.frames_with_face,
        done.frames,
        100.0 * done.mean_error_iod,
        done.frames_per_second,
        settings.out.display()
    );
    Ok(())
}
