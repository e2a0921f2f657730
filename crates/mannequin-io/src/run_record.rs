//! The record of a run stored in its checkpoint: every setting that changes what the run
//! produces, as JSON text. Resuming compares it leaf by leaf, so a checkpoint of another run is
//! refused naming each setting that differs, instead of silently mixing two runs. Every
//! checkpoint (training, cloth, dressing, capture, face tracking) keeps its record this way.

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;
use serde_json::Value;

use crate::{IoError, NpyArray, Npz, NpzWriter};

/// The checkpoint member that holds the record.
pub const RUN_MEMBER: &str = "run";

/// The way out a refused checkpoint offers, in every command that resumes one.
pub const START_OVER: &str = "use --restart to start over, or another --out";

/// Stores `run` (everything that changes the result) as the checkpoint's record.
pub fn write_run<T: Serialize>(w: &mut NpzWriter, run: &T) {
    w.add(RUN_MEMBER, NpyArray::text(&to_json(run)));
}

/// Refuses `checkpoint` unless its record matches `run` in every setting but `undecided` (dotted
/// paths of settings the caller cannot know yet), naming each difference with both values. Both
/// sides are read back from JSON text, so floats compare exactly as stored.
pub fn check_run<T: Serialize>(checkpoint: &Npz, run: &T, undecided: &[&str]) -> Result<(), IoError> {
    let path = checkpoint.path.clone();
    if !checkpoint.contains(RUN_MEMBER) {
        let reason = "holds no record of its run (written by an older mannequin)".to_string();
        return Err(IoError::Checkpoint { path, reason });
    }
    let recorded = parse_leaves(checkpoint.text(RUN_MEMBER)?)
        .ok_or_else(|| checkpoint.field_error(RUN_MEMBER, "expected the run's settings as JSON"))?;
    let now = parse_leaves(&to_json(run)).expect("a record serialises to JSON");
    let names: BTreeSet<&String> = recorded.keys().chain(now.keys()).collect();
    let text = |m: &BTreeMap<String, String>, k: &str| m.get(k).map_or("(none)", String::as_str).to_string();
    let differences: Vec<String> = names
        .into_iter()
        .filter(|k| !undecided.contains(&k.as_str()) && recorded.get(*k) != now.get(*k))
        .map(|k| format!("{k} was {}, now {}", text(&recorded, k), text(&now, k)))
        .collect();
    if differences.is_empty() {
        return Ok(());
    }
    let reason = format!("a checkpoint of another run: {}", differences.join(", "));
    Err(IoError::Checkpoint { path, reason })
}

fn to_json<T: Serialize>(run: &T) -> String {
    serde_json::to_string(run).expect("a run record serialises")
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

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    struct Options {
        iters: usize,
        dilation: f64,
    }

    #[derive(Serialize)]
    struct Run {
        body: String,
        skirt_layer: bool,
        options: Options,
    }

    fn run() -> Run {
        Run { body: "default".into(), skirt_layer: false, options: Options { iters: 100, dilation: 0.1 } }
    }

    fn checkpoint(run: &Run) -> Npz {
        let mut w = NpzWriter::new();
        write_run(&mut w, run);
        Npz::from_bytes("checkpoint.npz".into(), &w.to_bytes()).unwrap()
    }

    #[test]
    fn every_differing_setting_is_named_with_both_values() {
        let saved = checkpoint(&run());
        check_run(&saved, &run(), &[]).unwrap();
        let mut other = run();
        other.options.iters = 200;
        other.options.dilation = 0.3;
        other.body = "smpl.npz".into();
        other.skirt_layer = true;
        let e = check_run(&saved, &other, &["skirt_layer"]).unwrap_err().to_string();
        assert_eq!(
            e,
            "checkpoint.npz: a checkpoint of another run: body was default, now smpl.npz, \
             options.dilation was 0.1, now 0.3, options.iters was 100, now 200"
        );
    }

    #[test]
    fn a_checkpoint_without_a_record_is_refused() {
        let npz = Npz::from_bytes("old.npz".into(), &NpzWriter::new().to_bytes()).unwrap();
        let e = check_run(&npz, &run(), &[]).unwrap_err().to_string();
        assert!(e.starts_with("old.npz: holds no record of its run"), "{e}");
    }
}
