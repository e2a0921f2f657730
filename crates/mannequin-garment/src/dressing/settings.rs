//! `dress`'s settings: the size garments given by category are made at, how the solver steps
//! ([`Stepping`]), whether the cloth is simulated at all and with self-contacts (what changes
//! the result), and how often a checkpoint is saved. Each default is written here once; the
//! command line reads it from [`DressSettings::default`].

use mannequin_cloth::Stepping;
use serde::{Deserialize, Serialize};

use crate::ease::SIZE_NAMES;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, clap::Args)]
pub struct DressSettings {
    /// The size of garments given by category name.
    #[arg(
        long = "size",
        default_value_t = DressSettings::default().size,
        value_parser = clap::builder::PossibleValuesParser::new(SIZE_NAMES)
    )]
    pub size: String,
    #[command(flatten)]
    #[serde(flatten)]
    pub stepping: Stepping,
    /// Skin the garments only (Eqs. 3.2–3.3), without the cloth simulator.
    #[arg(long = "no-simulation")]
    pub no_simulation: bool,
    /// Turn off the cloth–cloth contacts (vertex–triangle and edge–edge), which keep every
    /// garment from crossing itself and the layers under it; off, each layer is pushed out of
    /// those under it as out of the body, which runs about 2.5× faster but lets the layers cross.
    /// metrics.json counts the crossings either way.
    #[arg(long = "no-self-collision", action = clap::ArgAction::SetFalse)]
    pub self_collision: bool,
    /// Save a checkpoint every this many simulated frames (0: never); a re-run of the same
    /// command goes on from it.
    #[arg(long = "checkpoint-every", default_value_t = DressSettings::default().checkpoint_every)]
    pub checkpoint_every: usize,
    /// Start over even if the folder holds a checkpoint.
    #[arg(long = "restart")]
    pub restart: bool,
}

impl Default for DressSettings {
    fn default() -> Self {
        Self {
            size: "M".into(),
            stepping: Stepping::default(),
            no_simulation: false,
            self_collision: true,
            checkpoint_every: 60,
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
        settings: DressSettings,
    }

    #[test]
    fn the_command_line_defaults_are_the_settings_defaults() {
        assert_eq!(Cli::parse_from(["mannequin"]).settings, DressSettings::default());
    }
}
