//! Solver settings: the small-steps schedule (many substeps, one constraint pass each, Macklin et
//! al. 2019) and the collision distances.

use crate::error::ClothError;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Substeps per frame; each substep predicts, projects and updates velocities.
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
            substeps: 10,
            iterations: 1,
            gravity: [0.0, -9.81, 0.0],
            thickness: 0.005,
            body_margin: 0.005,
            self_collision: true,
        }
    }
}

impl Settings {
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
