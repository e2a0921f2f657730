//! `mannequin render`: render a trained avatar at any dataset frame, at any frame of a motion
//! file or in a named pose, through the frame's camera, a camera JSON, or a front view; as
//! colour, normals, alpha or depth.

use std::path::PathBuf;

use anyhow::{Context, Result};
use burn::tensor::Device;
use mannequin_avatar::{Avatar, RenderMap, frame_camera, predict};
use mannequin_data::Dataset;
use mannequin_io::progress::JobTimer;
use mannequin_splat::{Camera, box_centre, front_camera, read_camera};

use crate::shared::PoseChoice;

#[derive(clap::Args)]
pub struct Args {
    /// Trained avatar folder (written by `mannequin train`).
    #[arg(long)]
    avatar: PathBuf,
    /// Dataset whose frame --frame (pose and camera) to render.
    #[arg(long, conflicts_with_all = ["motion", "named_pose"])]
    data: Option<PathBuf>,
    /// Split of --data.
    #[arg(long, default_value = "test", requires = "data")]
    split: String,
    /// The pose, when no --data frame is rendered: --motion/--frame or --named-pose (default: rest).
    #[command(flatten)]
    pose: PoseChoice,
    /// Camera JSON (K, extrinsic, width, height), overriding the dataset's camera; without
    /// --data and --camera, a front view of the body.
    #[arg(long)]
    camera: Option<PathBuf>,
    /// What to render.
    #[arg(long, value_enum, default_value_t = RenderMap::Rgb)]
    what: RenderMap,
    /// Output .png (depth: also .npy for metric values).
    #[arg(short, long)]
    output: PathBuf,
}

/// Pose, translation and camera of the requested frame.
fn frame_inputs(args: &Args, avatar: &Avatar) -> Result<(Vec<f32>, [f32; 3], Camera)> {
    let explicit = args.camera.as_deref().map(read_camera).transpose()?.map(|(c, _)| c);
    if let Some(data) = &args.data {
        let frame = args.pose.frame.unwrap_or(0);
        let dataset = Dataset::open(data, 1)?;
        let split = dataset.split(&args.split)?;
        let i = split.frames.iter().position(|&f| f == frame).with_context(|| {
            format!("{}: frame {frame} is not in split '{}' ({:?})", data.display(), args.split, split.frames)
        })?;
        let camera = explicit.unwrap_or_else(|| frame_camera(&dataset, frame));
        return Ok((split.poses.pose72(i), split.poses.transl[i], camera));
    }
    let (pose, transl) = args.pose.resolve(avatar.canonical.num_joints())?;
    let camera = match explicit {
        Some(c) => c,
        None => front_camera(box_centre(&avatar.pose_mesh(&pose, transl)?)),
    };
    Ok((pose, transl, camera))
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("render");
    let avatar = Avatar::load(&args.avatar, &Device::flex())?;
    let (pose, transl, camera) = frame_inputs(&args, &avatar)?;
    let p = predict(&avatar, &camera, &pose, transl)?;
    p.write_map(args.what, &args.output)?;
    tracing::info!("wrote {}", args.output.display());
    Ok(())
}
