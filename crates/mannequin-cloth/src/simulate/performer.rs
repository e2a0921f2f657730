//! The body a simulating run (`cloth simulate`, `dress`) dresses: a body model of some
//! shape playing a motion, with the names the run's record keeps for them.

use std::path::Path;

use mannequin_body::{BodyModel, Motion};

/// `model` (called `body`, of shape `betas`) playing `motion` (read from `motion_path`).
pub struct Performer<'a> {
    pub model: &'a BodyModel,
    pub body: &'a str,
    pub betas: &'a [f32],
    pub motion: &'a Motion,
    pub motion_path: &'a Path,
}
