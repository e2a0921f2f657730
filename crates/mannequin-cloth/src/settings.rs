//! Solver settings: the small-steps schedule (many substeps, one constraint pass each, Macklin et
//! al. 2019) and the collision distances.

use crate::error::ClothError;

/// Substeps per frame, the one default for every caller (`cloth simulate`, `dress`, draping a
/// panel, the synthetic subjects): tuned at [`SUBSTEPS_TUNED_FPS`] frames per second, where at
/// half of it a T-shirt slides off the shoulders in the walk.
pub const SUBSTEPS: u32 = 20;

/// The frame rate (1/s) [`SUBSTEPS`] was tuned at: 20 substeps per 1/30 s frame are 600 substeps
/// per second.
pub const SUBSTEPS_TUNED_FPS: f32 = 30.0;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Substeps per frame, at the least (a frame where the body moves fast takes more); each
    /// substep predicts, projects and updates velocities.
    pub substeps: u32,
    /// Constraint passes per substep. Small steps want one; more passes reuse the multipliers λ.
    pub iterations: u32,
    /// m/s²; Y is up.
    pub gravity: [f32; 3],
    /// Self-collision thickness h in metres: how far a vertex is kept from another triangle.
    pub thickness: f32,
    /// How far (m) the cloth is kept outside the body surface.
    pub body_margin: f32,
    pub self_collision: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            substeps: SUBSTEPS,
            iterations: 1,
            gravity: [0.0, -9.81, 0.0],
            thickness: 0.005,
            body_margin: 0.005,
            self_collision: true,
        }
    }
}

impl Settings {
    /// Substeps per frame at `fps` frames per second that step as finely in time as
    /// [`SUBSTEPS`] does at [`SUBSTEPS_TUNED_FPS`] (600 per second), for a caller whose frame
    /// rate varies.
    pub fn substeps_at(fps: f32) -> u32 {
        (SUBSTEPS as f32 * SUBSTEPS_TUNED_FPS / fps).ceil() as u32
    }

    pub fn validate(&self) -> Result<(), ClothError> {
        if self.substeps == 0 {
            return Err(ClothError::invalid("settings.substeps", "must be at least 1"));
        }
        if self.iterations == 0 {
            return Err(ClothError::invalid("settings.iterations", "must be at least 1"));
        }
        if !self.gravity.iter().all(|g| g.is_finite()) {
            return Err(ClothError::invalid("settings.gravity", "must be finite"));
        }
        for (field, value) in
            [("settings.thickness", self.thickness), ("settings.body_margin", self.body_margin)]
        {
            if !(value.is_finite() && value > 0.0) {
                return Err(ClothError::invalid(field, format!("{value} is not a positive length")));
            }
        }
        Ok(())
    }
}
