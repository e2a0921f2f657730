//! A dataset's label legend (`subject.json`'s `labels`): which label marks the garment being
//! reconstructed, and which mark garments worn over it.

use std::path::Path;

use super::error::NgdError;
use crate::category::{CATEGORY_NAMES, Category};
use crate::segmentation::BODY_LABELS;

/// The dataset's label names (`subject.json`'s `labels`), by index: the body's labels
/// (background, skin, hair, shoes) and garment categories, each once; any other name is refused.
pub(crate) fn label_legend(root: &Path) -> Result<Vec<String>, NgdError> {
    let path = root.join("subject.json");
    let text =
        std::fs::read_to_string(&path).map_err(|source| NgdError::NoLegend { path: path.clone(), source })?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|source| NgdError::NotJson { path: path.clone(), source })?;
    let Some(items) = json["labels"].as_array() else {
        return Err(NgdError::file(&path, "labels: expected a list of label names"));
    };
    let mut legend: Vec<String> = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let name = item
            .as_str()
            .ok_or_else(|| NgdError::file(&path, format!("labels[{i}]: expected a name, found {item}")))?;
        if !BODY_LABELS.contains(&name) && Category::named(name).is_err() {
            return Err(NgdError::file(
                &path,
                format!(
                    "labels[{i}]: '{name}' is neither a body label ({}) nor a garment category ({})",
                    BODY_LABELS.join(", "),
                    CATEGORY_NAMES.join(", ")
                ),
            ));
        }
        if legend.iter().any(|n| n == name) {
            return Err(NgdError::file(&path, format!("labels[{i}]: '{name}' is named twice")));
        }
        legend.push(name.to_string());
    }
    Ok(legend)
}

/// The index of the label `name` in the legend of the dataset at `root`.
pub(crate) fn label_index(root: &Path, legend: &[String], name: &str) -> Result<u8, NgdError> {
    match legend.iter().position(|n| n == name) {
        Some(i) => Ok(i as u8),
        None => {
            Err(NgdError::file(root.join("subject.json"), format!("labels: no '{name}' among {legend:?}")))
        }
    }
}

/// The labels of garments worn over one of `category`: upper-body garments over a lower-body one.
/// Where they show, the garment may be behind them, so those pixels say nothing about it.
pub(crate) fn outer_labels(legend: &[String], category: &str) -> Result<Vec<u8>, NgdError> {
    if !Category::named(category)?.is_lower_body() {
        return Ok(Vec::new());
    }
    Ok(legend
        .iter()
        .enumerate()
        .filter(|(_, name)| Category::named(name).is_ok_and(|c| !c.is_lower_body()))
        .map(|(i, _)| i as u8)
        .collect())
}
