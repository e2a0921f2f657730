//! `mannequin motion walk`: a procedural walk written as an AMASS `.npz`, so the animation
//! pipeline can be tried without a licensed motion download.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};
use mannequin_body::Motion;

#[derive(Subcommand)]
pub enum MotionCommand {
    /// Write a procedural walk cycle (SMPL layout) as an AMASS `.npz`.
    Walk(WalkArgs),
}

#[derive(Args)]
pub struct WalkArgs {
    #[arg(long, default_value_t = 4.0)]
    seconds: f32,
    #[arg(long, default_value_t = 30.0)]
    fps: f32,
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(cmd: MotionCommand) -> Result<()> {
    match cmd {
        MotionCommand::Walk(a) => {
            anyhow::ensure!(a.seconds > 0.0 && a.fps > 0.0, "--seconds and --fps must be positive");
            let walk = Motion::walk_cycle(a.seconds, a.fps);
            walk.write_amass(&a.output)?;
            tracing::info!("wrote {} ({} frames at {} fps)", a.output.display(), walk.num_frames(), walk.fps);
            Ok(())
        }
    }
}
