//! `mannequin capture --frames DIR | --video clip.mp4 --out DATASET`: a person's own video to a
//! dataset `mannequin train` reads (the PeopleSnapshot layout), by `mannequin_fit::capture`, with
//! garment labels made from it (`mannequin segment`).

use anyhow::Result;
use mannequin_fit::CaptureSettings;
use mannequin_garment::segmentation::{SegmentSettings, segment};
use mannequin_io::progress::JobTimer;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    settings: CaptureSettings,
    /// The garment labels capture makes of the captured frames (`mannequin segment`).
    #[command(flatten)]
    segment: SegmentSettings,
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("capture");
    args.segment.check()?;
    let done = mannequin_fit::capture(&args.settings)?;
    tracing::info!(
        "captured {} frames ({} without the person left out) into {}",
        done.kept,
        done.left_out,
        args.settings.out.display()
    );
    // The labels are the capture's own output: a rerun replaces them.
    let out = &args.settings.out;
    let labelled = segment(out, &args.settings.fitting.body, &args.segment, true)?;
    crate::segment::report(&labelled, out);
    Ok(())
}
