//! A motion to play whole: a motion file cut to its first frames and resampled to a frame rate,
//! reading and resampling only the source frames that are played.

use std::num::NonZeroUsize;
use std::path::Path;

use crate::error::BodyError;
use crate::motion::Motion;

impl Motion {
    /// The motion in `path`, resampled to `fps` (default: the file's own) and cut to its first
    /// `max_frames` (default: all). The cut is made before resampling too, so a long motion at a
    /// high frame rate costs only the frames played.
    pub fn read_clip(
        path: &Path,
        fps: Option<f32>,
        max_frames: Option<NonZeroUsize>,
    ) -> Result<Self, BodyError> {
        let mut motion = Self::read(path)?;
        if let Some(n) = max_frames.map(NonZeroUsize::get) {
            // The source frames the first n resampled ones interpolate between, and one spare.
            let source = match fps {
                Some(fps) if fps.is_finite() && fps > 0.0 => {
                    (((n - 1) as f64 * f64::from(motion.fps) / f64::from(fps)).ceil() as usize)
                        .saturating_add(2)
                }
                _ => n,
            };
            motion.keep_first(source);
        }
        if let Some(fps) = fps {
            motion = motion.resample(fps)?;
        }
        if let Some(n) = max_frames {
            motion.keep_first(n.get());
        }
        Ok(motion)
    }

    /// Keeps the first `n` frames (all, if there are fewer).
    fn keep_first(&mut self, n: usize) {
        let n = n.min(self.num_frames());
        self.poses.truncate(n * 3 * self.joints);
        self.trans.truncate(3 * n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clip_is_cut_after_resampling_and_reads_only_what_it_plays() {
        let dir = std::env::temp_dir().join(format!("mq-body-clip-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("walk.npz");
        Motion::walk_cycle(4.0, 30.0).write_amass(&path).unwrap();
        let all = Motion::read_clip(&path, None, None).unwrap();
        assert_eq!(all.num_frames(), Motion::read(&path).unwrap().num_frames());
        let three = Motion::read_clip(&path, Some(60.0), NonZeroUsize::new(3)).unwrap();
        assert_eq!((three.num_frames(), three.fps), (3, 60.0));
        assert_eq!(three.trans.len(), 9);
        let resampled = Motion::read(&path).unwrap().resample(60.0).unwrap();
        assert_eq!(three.poses[..], resampled.poses[..three.poses.len()]);
        std::fs::remove_dir_all(dir).unwrap();
    }
}
