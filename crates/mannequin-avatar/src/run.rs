//! The record of a training run: every setting that changes what it produces, kept in the
//! checkpoint as every run's record is ([`mannequin_io::run_record`]).

use mannequin_io::fingerprint::Fingerprint;
use mannequin_io::run_record::{check_run, write_run};
use mannequin_io::{Npz, NpzWriter};
use serde::Serialize;

use crate::config::AvatarConfig;
use crate::error::AvatarError;
use crate::options::TrainOptions;
use crate::skirt_layer::SkirtMode;

/// What `mannequin train` was asked for, beyond the avatar and the loss settings: the body, the
/// data and how they are read.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrainingRun {
    /// The body model the poses drive, as given (`default`, `default-lod1` or an .npz).
    pub body: String,
    /// Factor dividing the images' resolution.
    pub downscale: usize,
    /// Whether a skirt layer may be added; `avatar.skirt_layer` says whether one was.
    pub skirt: SkirtMode,
    /// The garments reconstructed as layers of their own (none: no such field, so checkpoints
    /// from before garment layers still resume).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub garments: Option<GarmentRecord>,
    pub data: Fingerprint,
    pub avatar: AvatarConfig,
    pub options: TrainOptions,
}

/// The garment layers asked for: their categories and each reconstruction's steps.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GarmentRecord {
    pub categories: Vec<String>,
    pub steps: usize,
}

impl TrainingRun {
    /// Stores the record in a checkpoint being written.
    pub fn write(&self, w: &mut NpzWriter) {
        write_run(w, self);
    }

    /// Refuses `checkpoint` unless its record matches `self` in every setting but `undecided`
    /// (ones the caller cannot know yet), naming each differing setting with both values.
    pub fn check(&self, checkpoint: &Npz, undecided: &[&str]) -> Result<(), AvatarError> {
        Ok(check_run(checkpoint, self, undecided)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Method;

    fn record() -> TrainingRun {
        let hash = "0123456789abcdef".to_string();
        TrainingRun {
            body: "default".into(),
            downscale: 2,
            skirt: SkirtMode::Auto,
            garments: None,
            data: Fingerprint {
                files: 3,
                bytes: 1000,
                listing: hash.clone(),
                cameras: hash.clone(),
                poses: hash,
            },
            avatar: AvatarConfig::new(Method::Tavatar, 0),
            options: TrainOptions::new(Method::Tavatar, 100, 0),
        }
    }

    fn checkpoint(run: &TrainingRun) -> Npz {
        let mut w = NpzWriter::new();
        run.write(&mut w);
        Npz::from_bytes("checkpoint.npz".into(), &w.to_bytes()).unwrap()
    }

    #[test]
    fn every_differing_setting_is_named_with_both_values() {
        let saved = checkpoint(&record());
        record().check(&saved, &[]).unwrap();
        let mut other = record();
        other.options.iterations = 200;
        other.avatar.dilation = 0.3;
        other.body = "smpl.npz".into();
        other.avatar.skirt_layer = true;
        let e = other.check(&saved, &["avatar.skirt_layer"]).unwrap_err().to_string();
        assert_eq!(
            e,
            "checkpoint.npz: a checkpoint of another run: avatar.dilation was 0.1, now 0.3, \
             body was default, now smpl.npz, options.iters was 100, now 200"
        );
    }

    #[test]
    fn a_checkpoint_without_a_record_is_refused() {
        let npz = Npz::from_bytes("old.npz".into(), &NpzWriter::new().to_bytes()).unwrap();
        let e = record().check(&npz, &[]).unwrap_err().to_string();
        assert!(e.starts_with("old.npz: holds no record of its run"), "{e}");
    }
}
