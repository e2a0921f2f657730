//! Frame ranges of dataset splits: `start`–`end` inclusive with a `step`, as the peers
//! (Anim-NeRF, InstantAvatar, GART, 3DGS-Avatar) use them on PeopleSnapshot.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::DataError;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SplitRange {
    pub start: usize,
    /// Inclusive.
    pub end: usize,
    pub step: usize,
}

impl SplitRange {
    pub fn new(start: usize, end: usize, step: usize) -> Self {
        Self { start, end, step }
    }

    /// The split's last frame, found without listing them (a file may claim `end` 2⁶⁴ − 1).
    pub fn last(&self) -> usize {
        self.start + (self.end.saturating_sub(self.start) / self.step.max(1)) * self.step.max(1)
    }

    /// The frame numbers of the split, in order; check [`SplitRange::last`] against the frames
    /// there are first.
    pub fn frames(&self) -> Vec<usize> {
        (self.start..=self.end).step_by(self.step.max(1)).collect()
    }
}

/// Named splits of one dataset (`train`, `val`, `test`, ...).
pub type Splits = BTreeMap<String, SplitRange>;

/// The splits the peers use for the four PeopleSnapshot subjects, keyed by the subject's folder
/// name. `val` is the first test frame, as in InstantAvatar's configurations.
pub fn standard_splits(subject: &str) -> Option<Splits> {
    let (train, test) = match subject {
        "male-3-casual" => (SplitRange::new(0, 455, 4), SplitRange::new(456, 675, 4)),
        "male-4-casual" => (SplitRange::new(0, 659, 6), SplitRange::new(660, 872, 6)),
        "female-3-casual" => (SplitRange::new(0, 445, 4), SplitRange::new(446, 647, 4)),
        "female-4-casual" => (SplitRange::new(0, 335, 4), SplitRange::new(335, 523, 4)),
        _ => return None,
    };
    let val = SplitRange::new(test.start, test.start, test.step);
    Some(
        [("train", train), ("val", val), ("test", test)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
    )
}

/// Reads `splits.json`: `{"train": {"start": 0, "end": 99, "step": 1}, ...}`.
pub fn read_splits_json(path: &Path) -> Result<Splits, DataError> {
    let text = std::fs::read_to_string(path).map_err(|e| DataError::os(path, e))?;
    let splits: Splits = serde_json::from_str(&text).map_err(|e| {
        DataError::file(path, format!("expected {{\"name\": {{\"start\", \"end\", \"step\"}}}}: {e}"))
    })?;
    if let Some((name, _)) = splits.iter().find(|(_, r)| r.step == 0 || r.end < r.start) {
        return Err(DataError::file(path, format!("split '{name}' needs step ≥ 1 and end ≥ start")));
    }
    Ok(splits)
}

pub fn write_splits_json(path: &Path, splits: &Splits) -> Result<(), DataError> {
    let text = serde_json::to_string_pretty(splits).map_err(|e| DataError::file(path, e.to_string()))?;
    mannequin_io::write_atomic(path, text.as_bytes()).map_err(|e| DataError::os(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frame counts the peers report for these splits (e.g. 114 training frames for male-3).
    #[test]
    fn standard_split_sizes() {
        let count = |s: &str, k: &str| standard_splits(s).unwrap()[k].frames().len();
        assert_eq!(count("male-3-casual", "train"), 114);
        assert_eq!(count("male-3-casual", "test"), 55);
        assert_eq!(count("male-4-casual", "train"), 110);
        assert_eq!(count("female-3-casual", "train"), 112);
        assert_eq!(count("female-4-casual", "train"), 84);
        assert_eq!(count("female-4-casual", "val"), 1);
        assert_eq!(standard_splits("female-4-casual").unwrap()["test"].frames()[..2], [335, 339]);
        assert!(standard_splits("someone-else").is_none());
    }
}
