//! Where the video pipelines (capture, face tracking) take their frames from: a folder of
//! images, or a video file decoded by the ffmpeg program.

use std::path::{Path, PathBuf};
use std::process::Command;

use mannequin_data::layout::IMAGE_EXTENSIONS;

use crate::error::FitError;

/// A clip's frames: a folder of images or a video, and how many of them to take.
#[derive(Clone, Debug, Default, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
pub struct FrameSource {
    /// A folder of frames (PNG or JPEG), taken in file-name order.
    #[arg(long, conflicts_with = "video", required_unless_present = "video")]
    pub frames: Option<PathBuf>,
    /// A video file, decoded by the ffmpeg program.
    #[arg(long)]
    pub video: Option<PathBuf>,
    /// Frames per second taken from the video (default: every frame); `face track` also keys its
    /// animation at this rate (by default 30 for a folder of frames).
    #[arg(long)]
    pub fps: Option<f64>,
    /// Use at most this many frames, from the start.
    #[arg(long)]
    pub max_frames: Option<usize>,
}

/// A pipeline's frames, and the folder they are in.
pub struct Frames {
    pub dir: PathBuf,
    pub files: Vec<PathBuf>,
    /// Whether `dir` was decoded from the video (and is the pipeline's to remove).
    pub decoded: bool,
}

impl FrameSource {
    /// The frames, the video first decoded into `scratch/.frames`; at most `--max-frames`.
    pub fn frames(&self, scratch: &Path) -> Result<Frames, FitError> {
        if let Some(fps) = self.fps
            && !(fps.is_finite() && fps > 0.0)
        {
            return Err(FitError::Setting(format!("--fps {fps}: expected a positive frame rate")));
        }
        let (dir, decoded) = match (&self.video, &self.frames) {
            (Some(video), _) => (self.decode(video, scratch)?, true),
            (None, Some(dir)) => (dir.clone(), false),
            (None, None) => return Err(FitError::Setting("give --frames DIR or --video FILE".into())),
        };
        let mut files = image_files(&dir)?;
        // ffmpeg decoded no more than these already; a folder's extra files are left unread.
        if let Some(n) = self.max_frames {
            files.truncate(n);
        }
        Ok(Frames { dir, files, decoded })
    }

    /// The video's name and hash, or each frame file's: a checkpoint resumes only on the same
    /// input.
    pub fn fingerprint(&self, files: &[PathBuf]) -> Result<Vec<String>, FitError> {
        match &self.video {
            Some(video) => Ok(vec![format!("{} {}", video.display(), file_hash(video)?)]),
            None => files.iter().map(|f| Ok(format!("{} {}", f.display(), file_hash(f)?))).collect(),
        }
    }

    /// Decodes the frames used of `video` (at `--fps`, at most `--max-frames` of them) into PNG
    /// frames under `out/.frames` with ffmpeg: a long video is not decoded whole to use its start.
    fn decode(&self, video: &Path, out: &Path) -> Result<PathBuf, FitError> {
        if !video.is_file() {
            return Err(FitError::input(video.display().to_string(), "no such video file"));
        }
        let dir = out.join(".frames");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).map_err(FitError::file("creating", &dir))?;
        let mut cmd = Command::new("ffmpeg");
        cmd.args(["-loglevel", "error", "-i"]).arg(video);
        if let Some(f) = self.fps {
            cmd.args(["-vf", &format!("fps={f}")]);
        }
        if let Some(n) = self.max_frames {
            cmd.args(["-frames:v", &n.to_string()]);
        }
        let status = match cmd.arg(dir.join("%06d.png")).status() {
            Ok(s) => s,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(FitError::Setting(
                    "--video needs the ffmpeg program, which is not on PATH: install it (Debian/Ubuntu: \
                     sudo apt-get install ffmpeg; macOS: brew install ffmpeg), or pass --frames DIR with the frames as images"
                        .into(),
                ));
            }
            Err(e) => return Err(FitError::file("running", "ffmpeg")(e)),
        };
        if !status.success() {
            return Err(FitError::input(
                video.display().to_string(),
                format!("ffmpeg could not decode it ({status})"),
            ));
        }
        Ok(dir)
    }
}

/// The hash of a file's bytes: tells an edited input from the one a checkpoint ran.
fn file_hash(path: &Path) -> Result<String, FitError> {
    let bytes = std::fs::read(path).map_err(FitError::file("reading", path))?;
    Ok(mannequin_io::fingerprint::hash_bytes(&bytes))
}

/// The image files of a folder, in name order.
fn image_files(dir: &Path) -> Result<Vec<PathBuf>, FitError> {
    let entries = std::fs::read_dir(dir).map_err(FitError::file("reading", dir))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| IMAGE_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        })
        .collect();
    files.sort();
    Ok(files)
}
