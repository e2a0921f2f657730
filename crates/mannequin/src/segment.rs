//! `mannequin segment --data DATASET`: garment labels from a dataset's images, person masks and
//! body poses alone (`mannequin_garment::segmentation`), so `garment fit` and
//! `train --garments` work on a person's own video.

use std::path::PathBuf;

use anyhow::Result;
use mannequin_garment::segmentation::{SegmentSettings, segment};
use mannequin_io::progress::JobTimer;

#[derive(clap::Args)]
pub struct Args {
    /// The dataset: images, person masks (`masks/`), cameras and poses, as `capture` writes it.
    #[arg(long)]
    data: PathBuf,
    /// The body model the dataset's poses are for.
    #[arg(long, default_value = "default")]
    body: String,
    #[command(flatten)]
    settings: SegmentSettings,
    /// Overwrite the dataset's label maps (a synthetic subject's true ones, say).
    #[arg(long)]
    replace: bool,
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("segment");
    let done = segment(&args.data, &args.body, &args.settings, args.replace)?;
    report(&done, &args.data);
    Ok(())
}

/// The closing line: what was decided, on what evidence.
pub fn report(done: &mannequin_garment::segmentation::Segmented, data: &std::path::Path) {
    let e = &done.evidence;
    tracing::info!(
        "labelled {} frames in {:.1} s: {} {} (top and bottom colours overlap {:.2}, forearms covered {:.2}, shins covered {:.2}, lower garment joining the legs in {:.2} of the rows across them); wrote {}/labels",
        done.frames,
        done.seconds,
        if done.decided { "decided" } else { "named" },
        done.legend[4..].join(" + "),
        e.colour_overlap,
        e.forearms_covered,
        e.shins_covered,
        e.legs_joined,
        data.display()
    );
}
