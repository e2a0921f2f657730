//! `mannequin motion walk` and `mannequin motion jog`: a procedural gait written as an AMASS
//! `.npz`, so the animation and cloth pipelines can be tried without a licensed motion download.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};
use mannequin_body::Motion;

#[derive(Subcommand)]
pub enum MotionCommand {
    /// Write a procedural walk cycle (SMPL layout) as an AMASS `.npz`.
    Walk(GaitArgs),
    /// Write a procedural jog (SMPL layout, about twice the walk's speed and cadence, elbows bent)
    /// as an AMASS `.npz`.
    Jog(GaitArgs),
}

#[derive(Args)]
pub struct GaitArgs {
    #[arg(long, default_value_t = 4.0)]
    seconds: f32,
    #[arg(long, default_value_t = 30.0)]
    fps: f32,
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(cmd: MotionCommand) -> Result<()> {
    let (a, gait): (_, fn(f32, f32) -> Motion) = match cmd {
        MotionCommand::Walk(a) => (a, Motion::walk_cycle),
        MotionCommand::Jog(a) => (a, Motion::jog_cycle),
    };
    // Bounded so that a typo (`inf`, `1e9`) is refused instead of filling the memory.
    anyhow::ensure!(
        a.seconds > 0.0 && a.seconds <= 3600.0,
        "--seconds: expected 0 to 3600, got {}",
        a.seconds
    );
    anyhow::ensure!(a.fps > 0.0 && a.fps <= 1000.0, "--fps: expected 0 to 1000, got {}", a.fps);
    let motion = gait(a.seconds, a.fps);
    motion.write_amass(&a.output)?;
    tracing::info!("wrote {} ({} frames at {} fps)", a.output.display(), motion.num_frames(), motion.fps);
    Ok(())
}
