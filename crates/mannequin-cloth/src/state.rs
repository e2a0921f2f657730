//! Everything a simulator carries from one frame to the next, so a run can be saved and resumed
//! with the same bits as if it had never stopped: positions and velocities. (Everything else, the
//! contact candidates and the side of each triangle a vertex is on included, is rebuilt from the
//! positions at the start of every frame.)

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClothState {
    pub positions: Vec<[f32; 3]>,
    pub velocities: Vec<[f32; 3]>,
}
