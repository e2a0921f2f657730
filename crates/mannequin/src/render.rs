//! `mannequin render`: render a trained avatar at any dataset frame, at any frame of a motion
//! file or in a named pose, through the frame's camera, a camera JSON, or a front view; as
//! colour, normals, alpha or depth.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use burn::tensor::Device;
use mannequin_avatar::{Avatar, frame_camera, predict};
use mannequin_data::{Dataset, Image};
use mannequin_splat::Camera;

use crate::pose_choice::PoseChoice;
use crate::splat::read_camera;
use mannequin_io::progress::JobTimer;

/// What a render writes.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum Map {
    /// Colour.
    Rgb,
    /// Camera-space normals.
    Normals,
    /// Coverage, white on black.
    Alpha,
    /// Depth, near bright (or metric values in a `.npy` output).
    Depth,
}

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
    #[arg(long, value_enum, default_value_t = Map::Rgb)]
    what: Map,
    /// Output .png (depth: also .npy for metric values).
    #[arg(short, long)]
    output: PathBuf,
}

/// A 540×540 camera 3.2 m in front of the (posed) body's centre, looking along −Z.
pub fn front_camera(centre: [f32; 3]) -> Camera {
    let c = centre.map(f64::from);
    Camera::look_at([c[0], c[1], c[2] + 3.2], c, [0.0, 1.0, 0.0], 0.65, 540, 540)
}

/// Centre of a mesh's bounding box.
pub fn box_centre(positions: &[[f32; 3]]) -> [f32; 3] {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]))
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

/// Writes the requested map of a prediction.
pub fn write_map(p: &mannequin_avatar::Prediction, what: Map, output: &Path) -> Result<()> {
    let grey = |values: &[f32]| Image {
        width: p.image.width,
        height: p.image.height,
        pixels: values.iter().map(|&v| [v; 3]).collect(),
    };
    match what {
        Map::Rgb => p.image.write_png(output)?,
        Map::Normals => p.normals.write_png(output)?,
        Map::Alpha => grey(&p.mask.values.iter().map(|&m| f32::from(u8::from(m))).collect::<Vec<_>>())
            .write_png(output)?,
        Map::Depth if output.extension().is_some_and(|e| e == "npy") => p.depth.write_npy(output)?,
        Map::Depth => {
            let fg = p.depth.depth.iter().filter(|&&d| d > 0.0);
            let (lo, hi) = fg.fold((f32::INFINITY, 0.0f32), |(lo, hi), &d| (lo.min(d), hi.max(d)));
            let span = (hi - lo).max(1e-6);
            // Near is bright, the background black.
            let v: Vec<f32> = p
                .depth
                .depth
                .iter()
                .map(|&d| if d > 0.0 { 1.0 - 0.8 * (d - lo) / span } else { 0.0 })
                .collect();
            grey(&v).write_png(output)?
        }
    }
    Ok(())
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("render");
    let avatar = Avatar::load(&args.avatar, &Device::flex())?;
    let (pose, transl, camera) = frame_inputs(&args, &avatar)?;
    let p = predict(&avatar, &camera, &pose, transl)?;
    write_map(&p, args.what, &args.output)?;
    tracing::info!("wrote {}", args.output.display());
    Ok(())
}
