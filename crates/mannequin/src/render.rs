//! `mannequin render`: render a trained avatar at any dataset frame, or at any frame of a motion
//! file, through the frame's camera, a camera JSON, or a front view; as colour, normals, alpha or
//! depth.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use burn::tensor::Device;
use mannequin_avatar::{Avatar, frame_camera, predict};
use mannequin_body::Motion;
use mannequin_data::{Dataset, Image};
use mannequin_splat::Camera;

use crate::progress::JobTimer;
use crate::splat::read_camera;

#[derive(clap::Args)]
pub struct Args {
    /// Model folder written by `mannequin train`.
    #[arg(long)]
    model: PathBuf,
    /// Dataset whose frame (pose and camera) to render.
    #[arg(long, conflicts_with = "motion")]
    data: Option<PathBuf>,
    /// Split of --data.
    #[arg(long, default_value = "test")]
    split: String,
    /// AMASS or PeopleSnapshot motion file whose frame to render.
    #[arg(long)]
    motion: Option<PathBuf>,
    /// Frame number (dataset frame index, or motion frame).
    #[arg(long, default_value_t = 0)]
    frame: usize,
    /// Camera JSON (K, extrinsic, width, height), overriding the dataset's camera; with --motion
    /// and no camera, a front view of the body.
    #[arg(long)]
    camera: Option<PathBuf>,
    /// What to render: rgb, normals, alpha or depth.
    #[arg(long, default_value = "rgb")]
    what: String,
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
        let dataset = Dataset::open(data, 1)?;
        let split = dataset.split(&args.split)?;
        let i = split.frames.iter().position(|&f| f == args.frame).with_context(|| {
            format!(
                "{}: frame {} is not in split '{}' ({:?})",
                data.display(),
                args.frame,
                args.split,
                split.frames
            )
        })?;
        let camera = explicit.unwrap_or_else(|| frame_camera(&dataset, args.frame));
        return Ok((split.poses.pose72(i), split.poses.transl[i], camera));
    }
    let Some(path) = &args.motion else { bail!("give --data or --motion") };
    let (pose, transl) = Motion::read(path)?.frame_pose(args.frame, avatar.canonical.num_joints())?;
    let camera = match explicit {
        Some(c) => c,
        None => front_camera(box_centre(&avatar.pose_mesh(&pose, transl)?)),
    };
    Ok((pose, transl, camera))
}

/// Writes the requested map of a prediction.
pub fn write_map(p: &mannequin_avatar::Prediction, what: &str, output: &Path) -> Result<()> {
    let grey = |values: &[f32]| Image {
        width: p.image.width,
        height: p.image.height,
        pixels: values.iter().map(|&v| [v; 3]).collect(),
    };
    match what {
        "rgb" => p.image.write_png(output)?,
        "normals" => p.normals.write_png(output)?,
        "alpha" => grey(&p.mask.values.iter().map(|&m| f32::from(u8::from(m))).collect::<Vec<_>>())
            .write_png(output)?,
        "depth" if output.extension().is_some_and(|e| e == "npy") => p.depth.write_npy(output)?,
        "depth" => {
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
        other => bail!("--what {other}: expected rgb, normals, alpha or depth"),
    }
    Ok(())
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("render");
    let avatar = Avatar::load(&args.model, &Device::flex())?;
    let (pose, transl, camera) = frame_inputs(&args, &avatar)?;
    let p = predict(&avatar, &camera, &pose, transl)?;
    write_map(&p, &args.what, &args.output)?;
    println!("wrote {}", args.output.display());
    Ok(())
}
