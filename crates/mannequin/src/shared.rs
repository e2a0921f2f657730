//! The argument groups several verbs share, with one meaning everywhere: the body model and its
//! shape (`--body --betas`), one pose (`--motion --frame` or `--named-pose`, else the rest pose)
//! and a whole motion to play (`--motion --fps --max-frames`). Verb modules import only this
//! module of the CLI crate.

use std::num::NonZeroUsize;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::builder::PossibleValuesParser;
use mannequin_body::{BodyModel, Motion, POSE_NAMES, named_pose};
use mannequin_cloth::Performer;
use mannequin_io::limits::MAX_BETA;

/// The body model and its shape.
#[derive(clap::Args)]
pub struct BodyArgs {
    /// Body model: `default`, `default-lod1`, or a SMPL / SMPL-H / SMPL-X `.npz` or released `.pkl`.
    #[arg(long, default_value = "default")]
    pub body: String,
    /// Shape coefficients, comma-separated (missing ones are 0), each within ±10.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = parse_beta)]
    pub betas: Vec<f32>,
}

impl BodyArgs {
    /// This body (its loaded `model`) playing `clip` (loaded as `motion`): what `cloth simulate`
    /// and `dress` move their garments on.
    pub fn performer<'a>(
        &'a self,
        model: &'a BodyModel,
        clip: &'a Clip,
        motion: &'a Motion,
    ) -> Performer<'a> {
        Performer { model, body: &self.body, betas: &self.betas, motion, motion_path: &clip.motion }
    }
}

/// One shape coefficient: finite and within [`MAX_BETA`] standard deviations, refused at parse
/// time (`--betas 1e6` once grew a garment to 5 GB).
fn parse_beta(text: &str) -> Result<f32, String> {
    let b: f32 = text.parse().map_err(|e| format!("{e}"))?;
    if f64::from(b.abs()) <= MAX_BETA {
        Ok(b)
    } else {
        Err(format!("{b}: expected a finite shape coefficient within ±{MAX_BETA}"))
    }
}

/// One pose: a frame of an AMASS or PeopleSnapshot motion, a built-in SMPL pose, or neither (the
/// rest pose: zero pose, zero translation).
#[derive(clap::Args)]
pub struct PoseChoice {
    /// AMASS or PeopleSnapshot motion `.npz`; --frame picks its frame.
    #[arg(long, conflicts_with = "named_pose")]
    pub motion: Option<PathBuf>,
    /// Frame of --motion (default 0).
    #[arg(long)]
    pub frame: Option<usize>,
    /// A built-in SMPL (24-joint) pose.
    #[arg(long, value_parser = PossibleValuesParser::new(POSE_NAMES))]
    pub named_pose: Option<String>,
}

impl PoseChoice {
    /// Whether the choice is the rest pose at the origin (nothing given, or `t-pose`).
    pub fn is_rest(&self) -> bool {
        self.motion.is_none() && self.named_pose.as_deref().is_none_or(|n| n == "t-pose")
    }

    /// Pose (3·`joints` values) and translation.
    pub fn resolve(&self, joints: usize) -> Result<(Vec<f32>, [f32; 3])> {
        if let Some(path) = &self.motion {
            return Ok(Motion::read(path)?.frame_pose(self.frame.unwrap_or(0), joints)?);
        }
        if let Some(frame) = self.frame {
            bail!("--frame {frame} picks a frame of --motion, and no --motion is given");
        }
        let Some(name) = &self.named_pose else { return Ok((vec![0.0; 3 * joints], [0.0; 3])) };
        let pose = named_pose(name)?;
        if 3 * joints != pose.len() {
            bail!(
                "--named-pose {name}: named poses are SMPL (24-joint) poses, but this body has {joints} joints"
            );
        }
        Ok((pose.to_vec(), [0.0; 3]))
    }
}

/// A whole motion to play: the file, resampled and cut as asked.
#[derive(clap::Args)]
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

impl Clip {
    /// The clip ([`Motion::read_clip`]).
    pub fn load(&self) -> Result<Motion> {
        let max_frames = self
            .max_frames
            .map(|n| NonZeroUsize::new(n).context("--max-frames must be at least 1"))
            .transpose()?;
        Ok(Motion::read_clip(&self.motion, self.fps, max_frames)?)
    }
}
