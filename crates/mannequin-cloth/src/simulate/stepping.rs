//! How a simulating command steps through its clip, shared by `cloth simulate` and `dress`: the
//! solver's substeps per frame and the settling time before the motion. Each default is written
//! here once; the command line reads it from [`Stepping::default`].

use serde::{Deserialize, Serialize};

use crate::settings::SUBSTEPS;
use crate::sim_limits::{MAX_SUBSTEPS, parse_settle};

/// Seconds before the motion by default: half at rest, half blending into its first frame.
pub const SETTLE_SECONDS: f32 = 1.0;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, clap::Args)]
pub struct Stepping {
    /// Simulation substeps per output frame (one constraint iteration each), at most 100; a
    /// frame where the body moves fast takes more.
    #[arg(
        long = "substeps",
        default_value_t = Stepping::default().substeps,
        allow_hyphen_values = true,
        value_parser = clap::value_parser!(u32).range(1..=MAX_SUBSTEPS as i64)
    )]
    pub substeps: u32,
    /// Seconds before the motion: half at rest, half blending into its first frame (at most 10).
    #[arg(
        long = "settle",
        default_value_t = Stepping::default().settle,
        allow_hyphen_values = true,
        value_parser = parse_settle
    )]
    pub settle: f32,
}

impl Default for Stepping {
    fn default() -> Self {
        Self { substeps: SUBSTEPS, settle: SETTLE_SECONDS }
    }
}
