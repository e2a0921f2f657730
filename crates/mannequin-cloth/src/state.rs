//! Everything a simulator carries from one frame to the next, so a run can be saved and resumed
//! with the same bits as if it had never stopped.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClothState {
    /// Frames stepped so far.
    pub frame: u64,
    pub positions: Vec<[f32; 3]>,
    pub velocities: Vec<[f32; 3]>,
}
