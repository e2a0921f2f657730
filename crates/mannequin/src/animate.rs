//! `mannequin animate`: render a trained avatar at every frame of a motion to PNGs (and an
//! `.mp4` where ffmpeg is installed). A skinned `.glb` of a bare body is `mannequin body animate`.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use burn::tensor::Device;
use clap::Args as ClapArgs;
use mannequin_avatar::{Avatar, predict};
use mannequin_body::Motion;
use mannequin_splat::Camera;

use crate::motion::Clip;
use crate::render::{Map, box_centre, front_camera, write_map};
use crate::splat::read_camera;
use mannequin_io::progress::{JobTimer, bar};

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
    #[arg(long, value_enum, default_value_t = Map::Rgb)]
    what: Map,
    /// Output folder of frames.
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let motion = args.clip.load()?;
    animate_avatar(&args, &motion)
}

/// `render`'s front camera on the centre of the clip's bounding box `lo`–`hi`, moved back until
/// the whole box fits, so the view stays fixed while the body moves through it.
pub fn clip_camera(lo: [f32; 3], hi: [f32; 3]) -> Camera {
    /// Room around the box, as a fraction of its half-size.
    const MARGIN: f64 = 1.1;
    let centre = box_centre(&[lo, hi]);
    let camera = front_camera(centre);
    let c = centre.map(f64::from);
    let distance = camera.centre()[2] - c[2];
    let tan_half = 0.5 * camera.width as f64 / camera.intrinsic[0][0];
    let half = |k: usize| 0.5 * f64::from(hi[k] - lo[k]);
    let needed = MARGIN * half(0).max(half(1)) / tan_half + half(2);
    if needed <= distance {
        return camera;
    }
    let eye = [c[0], c[1], c[2] + needed];
    Camera::look_at(eye, c, [0.0, 1.0, 0.0], 2.0 * tan_half.atan(), camera.width, camera.height)
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
        write_map(&p, args.what, &frame_path(f))?;
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
    write_video(&args.output, &args.output.join("animation.mp4"), frames, motion.fps)
}

/// Encodes `dir/frame_%04d.png` as `video` (H.264, yuv420p: what players accept) where ffmpeg is
/// installed, writing to a temporary name and renaming so a failed run leaves no partial video.
/// Only the `frames` frames of this run are read, not stale ones from a longer earlier run.
pub fn write_video(dir: &Path, video: &Path, frames: usize, fps: f32) -> Result<()> {
    let partial = video.with_extension("mp4.partial");
    let result = Command::new("ffmpeg")
        .args(["-y", "-loglevel", "error", "-framerate", &fps.to_string(), "-i"])
        .arg(dir.join("frame_%04d.png"))
        .args(["-frames:v", &frames.to_string()])
        // yuv420p needs even sides.
        .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p", "-f", "mp4"])
        .arg(&partial)
        .output();
    let output = match result {
        Ok(o) => o,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            tracing::info!(
                "no video written: ffmpeg is not on PATH (the PNG frames are in {})",
                dir.display()
            );
            return Ok(());
        }
        Err(e) => return Err(e).with_context(|| format!("running ffmpeg for {}", video.display())),
    };
    if !output.status.success() {
        let _ = std::fs::remove_file(&partial);
        let stderr = String::from_utf8_lossy(&output.stderr);
        bail!("{}: ffmpeg failed: {}", video.display(), stderr.lines().last().unwrap_or("no message").trim());
    }
    std::fs::rename(&partial, video).with_context(|| format!("writing {}", video.display()))?;
    tracing::info!("wrote {} ({fps} fps)", video.display());
    Ok(())
}
