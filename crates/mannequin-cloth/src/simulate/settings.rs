//! `cloth simulate`'s settings: the material, how the solver steps ([`Stepping`]) and the
//! self-contacts (what changes the result), and how often a checkpoint is saved. Each default is
//! written here once; the command line reads it from [`SimulateSettings::default`].

use serde::{Deserialize, Serialize};

use super::stepping::Stepping;
use crate::material::Material;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, clap::Args)]
pub struct SimulateSettings {
    /// The fabric [default: the .garment's own, or cotton for an .obj].
    #[arg(long = "material", value_enum)]
    pub material: Option<Material>,
    #[command(flatten)]
    #[serde(flatten)]
    pub stepping: Stepping,
    /// Turn off the cloth–cloth contacts (vertex–triangle, Eq. 3.22, and edge–edge), which keep
    /// every triangle pair from crossing; off, the cloth runs 2.5–3× faster but its folds may
    /// pass through each other. metrics.json counts the self-intersecting pairs either way.
    #[arg(long = "no-self-collision", action = clap::ArgAction::SetFalse)]
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
            material: None,
            stepping: Stepping::default(),
            self_collision: true,
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
