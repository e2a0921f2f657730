//! The record of a training run: every setting that changes what it produces. A checkpoint
//! stores it (as JSON text), and resuming compares it leaf by leaf, so a resume with different
//! settings or data is refused naming the setting instead of silently mixing two runs.

use std::collections::{BTreeMap, BTreeSet};

use mannequin_data::fingerprint::Fingerprint;
use mannequin_io::{NpyArray, Npz, NpzWriter};
use serde::Serialize;
use serde_json::Value;

use crate::config::AvatarConfig;
use crate::error::AvatarError;
use crate::skirt_layer::SkirtMode;
use crate::trainer::TrainOptions;

/// Checkpoint member that holds the record.
const MEMBER: &str = "run";

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

/// Every leaf of `value` by its dotted path, as text (strings unquoted).
fn leaves(path: &str, value: &Value, out: &mut BTreeMap<String, String>) {
    match value {
        Value::Object(map) => {
            for (key, v) in map {
                let child = if path.is_empty() { key.clone() } else { format!("{path}.{key}") };
                leaves(&child, v, out);
            }
        }
        Value::String(s) => {
            out.insert(path.to_string(), s.clone());
        }
        _ => {
            out.insert(path.to_string(), value.to_string());
        }
    }
}

/// The leaves of a JSON text; text that is not JSON has none.
fn parse_leaves(json: &str) -> Option<BTreeMap<String, String>> {
    let mut out = BTreeMap::new();
    leaves("", &serde_json::from_str(json).ok()?, &mut out);
    Some(out)
}

impl TrainingRun {
    fn to_json(&self) -> String {
        serde_json::to_string(self).expect("the record serialises")
    }

    /// Stores the record in a checkpoint being written.
    pub fn write(&self, w: &mut NpzWriter) {
        w.add(MEMBER, NpyArray::text(&self.to_json()));
    }

    /// Refuses `checkpoint` unless its record matches `self` in every setting but `undecided`
    /// (ones the caller cannot know yet), naming each differing setting with both values. Both
    /// sides are read back from JSON text, so floats compare exactly as stored.
    pub fn check(&self, checkpoint: &Npz, undecided: &[&str]) -> Result<(), AvatarError> {
        if !checkpoint.contains(MEMBER) {
            let reason = "holds no record of its run (written by an older mannequin)";
            return Err(AvatarError::file(&checkpoint.path, reason));
        }
        let recorded = parse_leaves(checkpoint.text(MEMBER)?)
            .ok_or_else(|| checkpoint.field_error(MEMBER, "expected the run's settings as JSON"))?;
        let now = parse_leaves(&self.to_json()).expect("the record is JSON");
        let names: BTreeSet<&String> = recorded.keys().chain(now.keys()).collect();
        let text =
            |m: &BTreeMap<String, String>, k: &str| m.get(k).map_or("(none)", String::as_str).to_string();
        let differences: Vec<String> = names
            .into_iter()
            .filter(|k| !undecided.contains(&k.as_str()) && recorded.get(*k) != now.get(*k))
            .map(|k| format!("{k} was {}, now {}", text(&recorded, k), text(&now, k)))
            .collect();
        if differences.is_empty() {
            return Ok(());
        }
        let reason = format!("a checkpoint of another run: {}", differences.join(", "));
        Err(AvatarError::file(&checkpoint.path, reason))
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
