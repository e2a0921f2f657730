//! What the pipelines write into their output folder alike: the folder itself, a JSON report,
//! and the checkpoint's name; failures name the path.

use std::path::Path;

use crate::error::FitError;

/// The checkpoint's file name in a pipeline's output folder.
pub const CHECKPOINT: &str = "checkpoint.npz";

/// Writes `report` to `path` atomically, pretty-printed.
pub(crate) fn write_report(path: &Path, report: &serde_json::Value) -> Result<(), FitError> {
    let text = serde_json::to_string_pretty(report).expect("a JSON value serialises");
    mannequin_io::write_atomic(path, text.as_bytes()).map_err(FitError::file("writing", path))
}

/// Makes the folder `dir` and its parents.
pub(crate) fn create_dir(dir: &Path) -> Result<(), FitError> {
    std::fs::create_dir_all(dir).map_err(FitError::file("creating", dir))
}
