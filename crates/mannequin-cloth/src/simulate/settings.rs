//! `cloth simulate`'s settings: the material, the solver's substeps, the settling time and the
//! self-contacts (what changes the result), and how often a checkpoint is saved. Each default is
//! written here once; the command line reads it from [`SimulateSettings::default`].

use serde::{Deserialize, Serialize};

use crate::material::Material;
use crate::settings::SUBSTEPS;
use crate::sim_limits::{MAX_SUBSTEPS, parse_settle};

/// Seconds before the motion by default: half at rest, half blending into its first frame.
pub const SETTLE_SECONDS: f32 = 1.0;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, clap::Args)]
pub struct SimulateSettings {
    #[arg(long = "material", value_enum, default_value_t = SimulateSettings::default().material)]
    pub material: Material,
    /// Simulation substeps per output frame (one constraint iteration each), at most 100.
    #[arg(
        long = "substeps",
        default_value_t = SimulateSettings::default().substeps,
        allow_hyphen_values = true,
        value_parser = clap::value_parser!(u32).range(1..=MAX_SUBSTEPS as i64)
    )]
    pub substeps: u32,
    /// Seconds before the motion: half at rest, half blending into its first frame (at most 10).
    #[arg(
        long = "settle",
        default_value_t = SimulateSettings::default().settle,
        allow_hyphen_values = true,
        value_parser = parse_settle
    )]
    pub settle: f32,
    /// Cloth–cloth contacts (vertex–triangle, Eq. 3.22). Experimental: cloth piling onto itself
    /// still tangles in places and they cost about 4× the time, so they are off unless asked
    /// for; metrics.json counts the self-intersecting pairs either way.
    #[arg(long = "self-collision")]
    pub self_collision: bool,
    /// Save a checkpoint every this many frames.
    #[arg(long = "checkpoint-every", default_value_t = SimulateSettings::default().checkpoint_every)]
    pub checkpoint_every: usize,
    /// Start over even if the folder holds a checkpoint.
    #[arg(long = "restart")]
    pub restart: bool,
}

impl Default for SimulateSettings {
    fn default() -> Self {
        Self {
            material: Material::default(),
            substeps: SUBSTEPS,
            settle: SETTLE_SECONDS,
            self_collision: false,
            checkpoint_every: 30,
            restart: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        settings: SimulateSettings,
    }

    #[test]
    fn the_command_line_defaults_are_the_settings_defaults() {
        assert_eq!(Cli::parse_from(["mannequin"]).settings, SimulateSettings::default());
    }
}
