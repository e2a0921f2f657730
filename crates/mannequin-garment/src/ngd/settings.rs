//! How a garment is reconstructed, as a user asks for it: the `garment fit` options, which
//! `mannequin train --garments` takes at their defaults but its seed and steps. Each default is
//! written once, here or in the setting it becomes ([`DynamicSettings`], [`RemeshSchedule`]);
//! the command line reads it.

use std::path::Path;

use mannequin_data::layout;
use serde::{Deserialize, Serialize};

use super::error::NgdError;
use super::reconstruction::{DynamicSettings, Settings};
use super::remesh::RemeshSchedule;

/// The normal loss's weight where the dataset has normal maps.
const DEFAULT_NORMAL_WEIGHT: f64 = 2.0;
/// The vertex noise γ (metres) of a fit to the label maps alone.
const MASKS_ALONE_NOISE: f64 = 0.01;

/// How a garment is reconstructed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, clap::Args)]
#[serde(deny_unknown_fields)]
pub struct NgdSettings {
    /// The base template's size.
    #[arg(long = "size", default_value_t = NgdSettings::default().size)]
    pub size: String,
    /// Optimisation steps (one training frame each).
    #[arg(long = "iters", value_name = "ITERS", default_value_t = NgdSettings::default().steps)]
    pub steps: usize,
    /// Adam's step size on the static Jacobian field.
    #[arg(long = "rate", default_value_t = NgdSettings::default().rate)]
    pub rate: f64,
    /// The Jacobian regulariser's weight λ in λ Σ ‖M_t − I‖² (toward the base shape); 0 by
    /// default, since 1e-4 made every garment but the pants worse (docs/ngd.md).
    #[arg(long = "regulariser", default_value_t = NgdSettings::default().regulariser)]
    pub regulariser: f64,
    /// NGD's vertex noise (Eqs. 11–12): each step's posed vertices move by γ N(0, 1) (1 − e/T)
    /// at step e of T, so early steps see the garment's overall shape; γ in metres (0: none).
    /// Without it: none where the normal loss is on, 1 cm where the fit reads the label maps
    /// alone (docs/ngd.md).
    #[arg(long = "noise")]
    pub noise: Option<f64>,
    /// The weight of the normal-map loss (Huber, on the garment's pixels) against the mask loss;
    /// 0 fits the masks alone. Without it: 2 where the dataset has normal maps, else 0.
    #[arg(long = "normal-weight")]
    pub normal_weight: Option<f64>,
    /// The weight of 1 − SSIM between the rendered and the dataset's normal maps on the
    /// garment's pixels (with the normal loss); 0 by default, since it made the fit worse
    /// (docs/ngd.md).
    #[arg(long = "ssim-weight", default_value_t = NgdSettings::default().ssim_weight)]
    pub ssim_weight: f64,
    /// NGD's dynamic field (§3.1): an MLP on the pose's first principal components adds a
    /// pose-dependent part to the Jacobians; 0 components: the static field alone.
    #[arg(long = "pose-components", default_value_t = NgdSettings::default().pose_components)]
    pub pose_components: usize,
    /// Adam's step size on the dynamic field's network.
    #[arg(long = "network-rate", default_value_t = NgdSettings::default().network_rate)]
    pub network_rate: f64,
    /// Steps between NGD's adaptive remeshings (§3.2: the faces with the largest gradients are
    /// split, finer as the fit goes); 0: none. Without it: every 100 steps where the normal loss
    /// is on, none where the fit reads the label maps alone (docs/ngd.md).
    #[arg(long = "remesh-every")]
    pub remesh_every: Option<usize>,
    /// Images are read at 1/N of their size.
    #[arg(long = "downscale", default_value_t = NgdSettings::default().downscale)]
    pub downscale: usize,
    /// Seeds the order the frames are visited in.
    #[arg(long = "seed", default_value_t = NgdSettings::default().seed)]
    pub seed: u64,
}

impl Default for NgdSettings {
    fn default() -> Self {
        let dynamic = DynamicSettings::default();
        Self {
            size: "M".to_string(),
            steps: 400,
            rate: 0.01,
            regulariser: 0.0,
            noise: None,
            normal_weight: None,
            ssim_weight: 0.0,
            pose_components: dynamic.components,
            network_rate: dynamic.rate,
            remesh_every: None,
            downscale: 2,
            seed: 0,
        }
    }
}

impl NgdSettings {
    /// The reconstruction's settings for the dataset at `data`, which has normal maps for every
    /// training frame or not (`has_normals`): the normal loss weighs 2 where it has them, unless
    /// told otherwise, and cannot be asked for where it has none.
    pub fn reconstruction(&self, data: &Path, has_normals: bool) -> Result<Settings, NgdError> {
        let normal_weight = match self.normal_weight {
            Some(w) if w > 0.0 && !has_normals => {
                return Err(NgdError::file(
                    data,
                    format!(
                        "--normal-weight {w} needs normal maps ({}/normal_%04d.png) for every training frame",
                        layout::NORMALS
                    ),
                ));
            }
            Some(w) => w,
            None if has_normals => DEFAULT_NORMAL_WEIGHT,
            None => {
                tracing::info!(
                    "{}: no normal maps for every training frame ({}/normal_%04d.png): fitting the label maps alone",
                    data.display(),
                    layout::NORMALS
                );
                0.0
            }
        };
        // Fitted to silhouettes alone, remeshing splits faces where the label maps' edges pull,
        // which roughens the surface, and early noise keeps the fit to the garment's overall
        // shape: both measured on a tuning subject (docs/ngd.md).
        let masks_alone = normal_weight == 0.0;
        let noise = self.noise.unwrap_or(if masks_alone { MASKS_ALONE_NOISE } else { 0.0 });
        let remesh_every =
            self.remesh_every.unwrap_or(if masks_alone { 0 } else { RemeshSchedule::default().every });
        Ok(Settings {
            steps: self.steps,
            rate: self.rate,
            regulariser: self.regulariser,
            noise,
            normal_weight,
            ssim_weight: if normal_weight > 0.0 { self.ssim_weight } else { 0.0 },
            dynamic: (self.pose_components > 0)
                .then_some(DynamicSettings { components: self.pose_components, rate: self.network_rate }),
            remesh: (remesh_every > 0).then(|| RemeshSchedule { every: remesh_every, ..Default::default() }),
            seed: self.seed,
        })
    }
}

#[cfg(test)]
mod tests {
    use clap::{Args, FromArgMatches};

    use super::*;

    #[test]
    fn the_command_line_defaults_are_the_settings_defaults() {
        let matches = NgdSettings::augment_args(clap::Command::new("ngd")).get_matches_from(["ngd"]);
        assert_eq!(NgdSettings::from_arg_matches(&matches).unwrap(), NgdSettings::default());
    }
}
