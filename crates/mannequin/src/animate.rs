//! `mannequin animate`: render a trained avatar at every frame of a motion to PNGs (and an
//! `.mp4` where ffmpeg is installed). A skinned `.glb` of a bare body is `mannequin body animate`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use burn::tensor::Device;
use clap::Args as ClapArgs;
use mannequin_avatar::{Avatar, RenderMap, predict};
use mannequin_body::Motion;
use mannequin_io::progress::{JobTimer, bar};
use mannequin_io::write_video;
use mannequin_splat::{clip_camera, read_camera};

use crate::shared::Clip;

#[derive(ClapArgs)]
#[command(
    after_help = "Writes OUT_DIR/frame_0000.png, ... through --camera or a fixed front camera framing the \
whole clip, and OUT_DIR/animation.mp4 when ffmpeg is on PATH."
)]
pub struct Args {
    /// Trained avatar folder (written by `mannequin train`).
    #[arg(long)]
    avatar: PathBuf,
    #[command(flatten)]
    clip: Clip,
    /// Camera JSON (K, extrinsic, width, height); default: a fixed front view.
    #[arg(long)]
    camera: Option<PathBuf>,
    /// What to render.
    #[arg(long, value_enum, default_value_t = RenderMap::Rgb)]
    what: RenderMap,
    /// Output folder of frames.
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let motion = args.clip.load()?;
    animate_avatar(&args, &motion)
}

fn animate_avatar(args: &Args, motion: &Motion) -> Result<()> {
    let _timer = JobTimer::start("animate");
    let avatar = Avatar::load(&args.avatar, &Device::flex())?;
    let joints = avatar.canonical.num_joints();
    let poses = motion.poses_for_joints(joints)?;
    let frames = motion.num_frames();
    let pose = |f: usize| &poses[f * 3 * joints..(f + 1) * 3 * joints];
    let transl = |f: usize| [0, 1, 2].map(|k| motion.trans[3 * f + k]);
    let camera = match &args.camera {
        Some(path) => read_camera(path)?.0,
        None => {
            // The personalised mesh does not depend on the pose: compute it once.
            let personalised = avatar.personalised(avatar.offsets()?);
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for f in 0..frames {
                let posed = avatar.skin(personalised.clone(), pose(f), transl(f))?;
                for (k, v) in posed.into_data().iter::<f32>().enumerate() {
                    lo[k % 3] = lo[k % 3].min(v);
                    hi[k % 3] = hi[k % 3].max(v);
                }
            }
            clip_camera(lo, hi)
        }
    };
    let created = !args.output.exists();
    std::fs::create_dir_all(&args.output).with_context(|| format!("creating {}", args.output.display()))?;
    let frame_path = |f: usize| args.output.join(format!("frame_{f:04}.png"));
    let progress = bar(frames as u64, "rendering");
    let rendered = (0..frames).try_for_each(|f| {
        let p = predict(&avatar, &camera, pose(f), transl(f))?;
        p.write_map(args.what, &frame_path(f))?;
        progress.inc(1);
        anyhow::Ok(())
    });
    if rendered.is_err() {
        // Half a clip is no result: the frames written go, and the folder if this run made it.
        (0..frames).for_each(|f| drop(std::fs::remove_file(frame_path(f))));
        if created {
            let _ = std::fs::remove_dir(&args.output);
        }
    }
    rendered?;
    progress.finish_and_clear();
    tracing::info!(
        "wrote {} frames ({}×{}) to {}",
        frames,
        camera.width,
        camera.height,
        args.output.display()
    );
    Ok(write_video(&args.output, &args.output.join("animation.mp4"), frames, motion.fps)?)
}
