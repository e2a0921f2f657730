//! `mannequin motion walk`: a procedural walk written as an AMASS `.npz`, so the animation
//! pipeline can be tried without a licensed motion download; and the options of the verbs that
//! play a whole motion.

use std::path::PathBuf;

use anyhow::{Result, bail};
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

/// A whole motion to play: the file, resampled and cut as asked.
#[derive(Args)]
pub struct Clip {
    /// AMASS or PeopleSnapshot motion `.npz`.
    #[arg(long)]
    pub motion: PathBuf,
    /// Resample the motion to this frame rate (default: the file's own).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_fps)]
    pub fps: Option<f32>,
    /// Use only the first N frames (after resampling).
    #[arg(long)]
    pub max_frames: Option<usize>,
}

/// A frame rate: a positive, finite number, refused by the parser naming `--fps` (a negative
/// one was taken for a flag).
fn parse_fps(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(fps) if fps.is_finite() && fps > 0.0 => Ok(fps),
        Ok(fps) => Err(format!("{fps}: expected a positive number of frames per second")),
        Err(e) => Err(e.to_string()),
    }
}

/// Keeps the first `n` frames of `motion` (all, if it has fewer).
fn first_frames(motion: &mut Motion, n: usize) {
    let n = n.min(motion.num_frames());
    motion.poses.truncate(n * 3 * motion.joints);
    motion.trans.truncate(3 * n);
}

impl Clip {
    /// The clip, cut to --max-frames before it is resampled, so a long motion at a high --fps
    /// costs only the frames played.
    pub fn load(&self) -> Result<Motion> {
        let mut motion = Motion::read(&self.motion)?;
        if let Some(n) = self.max_frames {
            if n == 0 {
                bail!("--max-frames must be at least 1");
            }
            // The source frames the first n resampled ones interpolate between, and one spare.
            let source = match self.fps {
                Some(fps) if fps.is_finite() && fps > 0.0 => {
                    (((n - 1) as f64 * f64::from(motion.fps) / f64::from(fps)).ceil() as usize)
                        .saturating_add(2)
                }
                _ => n,
            };
            first_frames(&mut motion, source);
        }
        if let Some(fps) = self.fps {
            motion = motion.resample(fps)?;
        }
        if let Some(n) = self.max_frames {
            first_frames(&mut motion, n);
        }
        Ok(motion)
    }
}
