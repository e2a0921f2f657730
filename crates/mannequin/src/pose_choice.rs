//! The pose options every verb shares, with one meaning everywhere: `--motion FILE --frame N` is
//! a frame of an AMASS or PeopleSnapshot motion, `--named-pose NAME` a built-in SMPL pose, and
//! neither is the rest pose (zero pose, zero translation).

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::builder::PossibleValuesParser;
use mannequin_body::{Motion, POSE_NAMES, named_pose};

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
