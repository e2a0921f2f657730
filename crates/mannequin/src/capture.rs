//! `mannequin capture --frames DIR | --video clip.mp4 --out DATASET`: a person's own video to a
//! dataset `mannequin train` reads (the PeopleSnapshot layout), by `mannequin_fit::capture`.

use anyhow::Result;
use mannequin_fit::CaptureSettings;
use mannequin_io::progress::JobTimer;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    settings: CaptureSettings,
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("capture");
    let done = mannequin_fit::capture(&args.settings)?;
    tracing::info!(
        "captured {} frames ({} without the person left out) into {}",
        done.kept,
        done.left_out,
        args.settings.out.display()
    );
    Ok(())
}
