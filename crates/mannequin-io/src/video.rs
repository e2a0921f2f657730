//! Numbered PNG frames encoded as an `.mp4` by ffmpeg, where it is installed.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Why a video was not written (a missing ffmpeg is not an error: the frames stay).
#[derive(Debug, thiserror::Error)]
pub enum VideoError {
    #[error("running ffmpeg for {}", video.display())]
    Run { video: PathBuf, source: std::io::Error },
    #[error("{}: ffmpeg failed: {message}", video.display())]
    Failed { video: PathBuf, message: String },
    #[error("writing {}", video.display())]
    Write { video: PathBuf, source: std::io::Error },
}

/// Encodes `dir/frame_%04d.png` as `video` (H.264, yuv420p: what players accept) where ffmpeg is
/// installed, writing to a temporary name and renaming so a failed run leaves no partial video.
/// Only the `frames` frames of this run are read, not stale ones from a longer earlier run.
/// Without ffmpeg it says so and writes nothing.
pub fn write_video(dir: &Path, video: &Path, frames: usize, fps: f32) -> Result<(), VideoError> {
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
        Err(source) => return Err(VideoError::Run { video: video.to_path_buf(), source }),
    };
    if !output.status.success() {
        let _ = std::fs::remove_file(&partial);
        let stderr = String::from_utf8_lossy(&output.stderr);
        let message = stderr.lines().last().unwrap_or("no message").trim().to_string();
        return Err(VideoError::Failed { video: video.to_path_buf(), message });
    }
    std::fs::rename(&partial, video)
        .map_err(|source| VideoError::Write { video: video.to_path_buf(), source })?;
    tracing::info!("wrote {} ({fps} fps)", video.display());
    Ok(())
}
