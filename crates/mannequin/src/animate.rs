//! `mannequin animate`: drive a body with a motion file and write a skinned, animated `.glb`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args as ClapArgs;
use mannequin_body::{Motion, skeletal_animation, skinned_body};

use crate::body::{BodyArgs, load_model};

#[derive(ClapArgs)]
pub struct Args {
    #[command(flatten)]
    body: BodyArgs,
    /// AMASS or PeopleSnapshot `.npz` motion.
    #[arg(long)]
    motion: PathBuf,
    /// Resample the motion to this frame rate (default: the file's own).
    #[arg(long)]
    fps: Option<f32>,
    /// Output `.glb`.
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let model = load_model(&args.body.model)?;
    let mut motion = Motion::read(&args.motion)?;
    if let Some(fps) = args.fps {
        motion = motion.resample(fps)?;
    }
    let poses = motion.poses_for(&model)?;
    let skinned = skinned_body(&model, &args.body.betas)?;
    let animation = skeletal_animation(&model, &poses, &motion.trans, motion.fps)?;
    mannequin_mesh::gltf::write_glb(&args.output, &skinned, Some(&animation))
        .with_context(|| format!("writing {}", args.output.display()))?;
    tracing::info!(
        "wrote {}: {} frames at {} fps ({:.1} s), {} vertices, {} joints",
        args.output.display(),
        motion.num_frames(),
        motion.fps,
        motion.num_frames().saturating_sub(1) as f32 / motion.fps,
        model.num_vertices(),
        model.num_joints()
    );
    Ok(())
}
