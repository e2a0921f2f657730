//! `mannequin fit --image photo.jpg --out DIR`: the body (and on the default body the face)
//! fitted to a photo, by `mannequin_fit::body_photo`.

use std::path::PathBuf;

use anyhow::Result;
use mannequin_fit::FitSettings;
use mannequin_fit::body_photo::{BodyPhoto, fit_photo};

#[derive(clap::Args)]
pub struct Args {
    /// The photo: PNG or JPEG.
    #[arg(long)]
    image: PathBuf,
    /// Which person to fit, counting from 0 in order of size (largest first).
    #[arg(long)]
    person: Option<usize>,
    #[command(flatten)]
    fitting: FitSettings,
    /// Do not fit the face (by default the default body's face is fitted too when the face is
    /// at least 48 pixels across, adding about half a second).
    #[arg(long)]
    no_face: bool,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let job = BodyPhoto {
        image: &args.image,
        person: args.person,
        fitting: &args.fitting,
        face: !args.no_face,
        out: &args.out,
    };
    let done = fit_photo(&job)?;
    tracing::info!(
        "fitted {}: median landmark error {:.1} px, mask IoU {:.3}, {:.1} s; wrote {}",
        args.image.display(),
        done.median_error_px.map_or(f64::NAN, f64::from),
        done.mask_iou,
        done.seconds,
        args.out.display()
    );
    Ok(())
}
