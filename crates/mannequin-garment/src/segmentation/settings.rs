//! How a dataset is segmented, as a user asks for it (`mannequin segment`, and `capture`, which
//! runs it). Each default is written once, here.

use serde::{Deserialize, Serialize};

use super::outfit::Outfit;
use crate::ngd::NgdError;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, clap::Args)]
#[serde(deny_unknown_fields)]
pub struct SegmentSettings {
    /// The garments worn: `auto` decides them from the images (sleeve length, whether the lower
    /// garment reaches the ankles or spans the legs, one dress where top and bottom are alike and join the legs);
    /// or name them: `dress`, or `upper:tshirt,lower:pants`.
    #[arg(long = "garments", default_value_t = SegmentSettings::default().garments)]
    pub garments: String,
}

impl Default for SegmentSettings {
    fn default() -> Self {
        Self { garments: "auto".into() }
    }
}

impl SegmentSettings {
    /// Refuses a `--garments` that names no outfit, before any work.
    pub fn check(&self) -> Result<(), NgdError> {
        if self.garments != "auto" {
            Outfit::named(&self.garments)?;
        }
        Ok(())
    }
}
