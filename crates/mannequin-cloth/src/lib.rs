//! XPBD cloth (thesis §3.3): a garment mesh's vertices as particles, held by stretch and dihedral
//! bending constraints, kept off itself and off an animated body.

mod attachment;
mod bending;
mod body;
mod body_contacts;
mod box_hash;
mod box_tree;
mod cloth;
mod coloured_sweep;
mod colouring;
mod constraint_graph;
mod dihedral;
mod error;
mod garment_check;
mod layers;
mod material;
mod phase_times;
pub mod quality;
mod rest_shape;
pub mod run_checkpoint;
mod self_contacts;
mod settings;
pub mod sim_limits;
pub mod simulate;
mod simulate_error;
mod simulator;
mod state;
mod stretch;
mod tethers;

pub use attachment::Attachment;
pub use body::Body;
pub use cloth::Cloth;
pub use error::ClothError;
pub use garment_check::{MAX_GARMENT_FACES, MAX_GARMENT_VERTICES, check_garment};
pub use layers::Layers;
pub use material::{MATERIAL_NAMES, Material};
pub use phase_times::PhaseTimes;
pub use settings::{SUBSTEPS, SUBSTEPS_TUNED_FPS, Settings};
pub use simulate::{
    GarmentInput, Performer, Pins, SETTLE_SECONDS, SimulateJob, SimulateSettings, Simulation, Stepping,
    simulate,
};
pub use simulate_error::SimulateError;
pub use simulator::Simulator;
pub use state::{ClothState, MAX_COORDINATE, MAX_SPEED, check_positions};
