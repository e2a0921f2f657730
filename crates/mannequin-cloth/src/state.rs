//! Everything a simulator carries from one frame to the next, so a run can be saved and resumed
//! with the same bits as if it had never stopped: positions and velocities. (Everything else, the
//! contact candidates and the side of each triangle a vertex is on included, is rebuilt from the
//! positions at the start of every frame.) A state read back from a file is held to physical
//! bounds, as a cloth on a body never leaves them and the solver's grids are sized by them.

use serde::{Deserialize, Serialize};

use crate::error::ClothError;

/// Farthest a cloth particle may be from the origin along any axis (m): a body moves within a
/// room or a stage, not kilometres away.
pub const MAX_COORDINATE: f32 = 1000.0;

/// Fastest a cloth particle may move (m/s): the speed of sound in air, which no garment on a
/// moving body approaches (a thrown hand moves at about 25 m/s).
pub const MAX_SPEED: f32 = 343.0;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClothState {
    pub positions: Vec<[f32; 3]>,
    pub velocities: Vec<[f32; 3]>,
}

impl ClothState {
    /// Refuses a state that is not of `particles` particles, or that holds a position past
    /// [`MAX_COORDINATE`] or a velocity past [`MAX_SPEED`] (NaN and infinities included).
    pub fn check(&self, particles: usize) -> Result<(), ClothError> {
        for (field, values) in [("state.positions", &self.positions), ("state.velocities", &self.velocities)]
        {
            if values.len() != particles {
                return Err(ClothError::invalid(
                    field,
                    format!("{} entries for {particles} particles", values.len()),
                ));
            }
        }
        check_positions("state.positions", &self.positions)?;
        let too_fast = |v: &[f32; 3]| {
            let squared = v.iter().map(|c| c * c).sum::<f32>();
            squared.is_nan() || squared > MAX_SPEED * MAX_SPEED
        };
        match self.velocities.iter().position(too_fast) {
            Some(i) => Err(ClothError::invalid(
                "state.velocities",
                format!(
                    "entry {i} is {:?} m/s; expected a speed of at most {MAX_SPEED} m/s",
                    self.velocities[i]
                ),
            )),
            None => Ok(()),
        }
    }
}

/// Refuses a point with a coordinate past ±[`MAX_COORDINATE`] (NaN and infinities included),
/// naming `field` and the entry.
pub fn check_positions(field: &str, positions: &[[f32; 3]]) -> Result<(), ClothError> {
    match positions.iter().position(|p| !p.iter().all(|c| c.abs() <= MAX_COORDINATE)) {
        Some(i) => Err(ClothError::invalid(
            field,
            format!("entry {i} is {:?}; expected coordinates within ±{MAX_COORDINATE} m", positions[i]),
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 42: velocities of 1e30 in a checkpoint hung the run; they, a NaN and a far point
    /// are refused naming the field and entry.
    #[test]
    fn states_past_the_physical_bounds_are_refused() {
        let good = ClothState { positions: vec![[0.0, 1.0, 0.0]; 2], velocities: vec![[0.0, -3.0, 0.0]; 2] };
        good.check(2).unwrap();
        assert_eq!(good.check(3).unwrap_err().to_string(), "state.positions: 2 entries for 3 particles");
        let mut fast = good.clone();
        fast.velocities[1] = [1e30, 0.0, 0.0];
        let e = fast.check(2).unwrap_err().to_string();
        assert!(e.starts_with("state.velocities: entry 1 is") && e.contains("at most 343 m/s"), "{e}");
        let mut far = good.clone();
        far.positions[0] = [0.0, f32::NAN, 0.0];
        let e = far.check(2).unwrap_err().to_string();
        assert!(e.starts_with("state.positions: entry 0 is [0.0, NaN, 0.0]") && e.contains("±1000 m"), "{e}");
        far.positions[0] = [2000.0, 0.0, 0.0];
        assert!(far.check(2).is_err());
    }
}
