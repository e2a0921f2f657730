//! The pins file of `cloth simulate --pin`: garment vertices fixed in place or bound to the body
//! surface nearest them at rest.

use std::path::Path;

use crate::simulate_error::SimulateError;

/// The vertices a pins file names: fixed in place, or attached to the body surface nearest them
/// at rest.
#[derive(Debug, Clone, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pins {
    #[serde(default)]
    pub fixed: Vec<u32>,
    #[serde(default)]
    pub attached: Vec<u32>,
}

/// The pins at `path` for a garment of `vertices` vertices: each vertex in range and in one list.
pub fn read_pins(path: &Path, vertices: usize) -> Result<Pins, SimulateError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| SimulateError::Read { path: path.display().to_string(), reason: e.to_string() })?;
    let pins: Pins = serde_json::from_str(&text).map_err(|e| {
        SimulateError::invalid(
            path.display().to_string(),
            format!("expected {{\"fixed\": [vertex, ...], \"attached\": [vertex, ...]}}: {e}"),
        )
    })?;
    for (field, list) in [("fixed", &pins.fixed), ("attached", &pins.attached)] {
        if let Some(&v) = list.iter().find(|&&v| v as usize >= vertices) {
            return Err(SimulateError::invalid(
                path.display().to_string(),
                format!("{field}: vertex {v} is out of range (the garment has {vertices} vertices)"),
            ));
        }
    }
    if let Some(v) = pins.attached.iter().find(|v| pins.fixed.contains(v)) {
        return Err(SimulateError::invalid(
            path.display().to_string(),
            format!("attached: vertex {v} is also fixed; expected each vertex in one list"),
        ));
    }
    Ok(pins)
}
