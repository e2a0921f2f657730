//! The settings of a training run, each default written once: `mannequin train` embeds them as
//! its flags, and they give the run's avatar ([`AvatarConfig`]) and loss settings
//! ([`TrainOptions`]) and its record.

use serde::{Deserialize, Serialize};

use crate::canonical::MAX_SUBDIVISIONS;
use crate::compute::Compute;
use crate::config::{AVATAR_DILATION, AvatarConfig, Method};
use crate::options::TrainOptions;
use crate::pose_refinement::RefinePoses;
use crate::skirt_layer::SkirtMode;

/// What a training run is asked for, beyond where its data and avatar lie.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, clap::Args)]
#[serde(default)]
pub struct TrainSettings {
    /// Gaussian binding.
    #[arg(long, value_enum, default_value_t = TrainSettings::default().method)]
    pub method: Method,
    // Iterations of the run (one view each); `--iters`.
    #[arg(long = "iters", value_name = "ITERS", default_value_t = TrainSettings::default().iterations)]
    pub iterations: usize,
    // Seed of every random initialisation and of the view order.
    #[arg(long, default_value_t = TrainSettings::default().seed)]
    pub seed: u64,
    /// Body model the dataset's poses drive: default, default-lod1, or an SMPL-family .npz.
    #[arg(long, default_value_t = TrainSettings::default().body)]
    pub body: String,
    /// Midpoint subdivisions of the body template (each quadruples the faces), at most 3.
    #[arg(
        long = "subdivide",
        value_name = "SUBDIVIDE",
        default_value_t = TrainSettings::default().subdivisions,
        value_parser = clap::value_parser!(u64).range(0..=MAX_SUBDIVISIONS as u64)
    )]
    pub subdivisions: u64,
    /// Divide the images' resolution by this factor.
    #[arg(long, default_value_t = TrainSettings::default().downscale)]
    pub downscale: usize,
    /// Save a checkpoint every this many iterations.
    #[arg(long, default_value_t = TrainSettings::default().checkpoint_every)]
    pub checkpoint_every: usize,
    /// Ablation: no face Gaussians (vertex scales become learnable).
    #[arg(long)]
    pub no_face_gaussians: bool,
    /// Ablation: no vertex Gaussians.
    #[arg(long)]
    pub no_vertex_gaussians: bool,
    /// Ablation: no equilateral regulariser.
    #[arg(long)]
    pub no_equilateral: bool,
    /// gsplat's antialiased mode: opacities scaled by the screen filter's compensation, so
    /// silhouettes do not overshoot the mesh (costs novel-view PSNR and normal accuracy).
    #[arg(long)]
    pub antialiased: bool,
    /// Screen-filter variance in px² added to every Gaussian's footprint (3DGS uses 0.3; larger
    /// values widen silhouettes and shrink the fitted mesh).
    #[arg(long, default_value_t = TrainSettings::default().dilation, value_parser = parse_dilation)]
    pub dilation: f64,
    /// Skirt layer over the body: auto (where the masks fill the gap between the legs below
    /// mid-thigh) or off.
    #[arg(long, value_enum, default_value_t = TrainSettings::default().skirt)]
    pub skirt: SkirtMode,
    /// Refine each training frame's pose with the avatar: auto does for datasets whose poses
    /// were estimated (`mannequin capture` writes such), not for ground-truth poses.
    #[arg(long, value_enum, default_value_t = TrainSettings::default().refine_poses)]
    pub refine_poses: RefinePoses,
    /// Where training runs: cpu (Flex) or gpu (wgpu on Vulkan).
    #[arg(long, value_enum, default_value_t = TrainSettings::default().device)]
    pub device: Compute,
    /// Start over even if the model folder holds a checkpoint.
    #[arg(long)]
    pub restart: bool,
}

impl Default for TrainSettings {
    fn default() -> Self {
        Self {
            method: Method::Tavatar,
            iterations: 2000,
            seed: 0,
            body: "default".into(),
            subdivisions: 0,
            downscale: 1,
            checkpoint_every: 200,
            no_face_gaussians: false,
            no_vertex_gaussians: false,
            no_equilateral: false,
            antialiased: false,
            dilation: AVATAR_DILATION,
            skirt: SkirtMode::Auto,
            refine_poses: RefinePoses::Auto,
            device: Compute::Cpu,
            restart: false,
        }
    }
}

impl TrainSettings {
    /// The avatar these settings build: the binding's defaults, with the subdivisions, screen
    /// filter and (Tavatar's) ablations asked for.
    pub fn avatar_config(&self) -> AvatarConfig {
        let mut config = AvatarConfig::new(self.method, self.seed);
        config.subdivisions = self.subdivisions as usize;
        config.antialiased = self.antialiased;
        config.dilation = self.dilation;
        if self.method == Method::Tavatar {
            config.face_gaussians = !self.no_face_gaussians;
            config.vertex_gaussians = !self.no_vertex_gaussians;
        }
        config
    }

    /// The loss settings: the binding's weights for this run's iterations and seed, without the
    /// equilateral term when it is ablated.
    pub fn options(&self) -> TrainOptions {
        let mut options = TrainOptions::new(self.method, self.iterations, self.seed);
        if self.no_equilateral {
            options.lambda_equilateral = 0.0;
        }
        options
    }
}

/// A screen-filter variance: a finite number of px², at least 0.
fn parse_dilation(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(d) if d.is_finite() && d >= 0.0 => Ok(d),
        _ => Err(format!("'{text}': expected a finite variance >= 0 (px²)")),
    }
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Parser)]
    struct Train {
        #[command(flatten)]
        settings: TrainSettings,
    }

    fn parse(flags: &[&str]) -> Result<TrainSettings, clap::Error> {
        Train::try_parse_from(std::iter::once("train").chain(flags.iter().copied())).map(|t| t.settings)
    }

    #[test]
    fn the_flags_default_to_the_settings_defaults() {
        assert_eq!(parse(&[]).unwrap(), TrainSettings::default());
        let s = parse(&["--iters", "7", "--subdivide", "2", "--no-equilateral"]).unwrap();
        assert_eq!((s.iterations, s.subdivisions), (7, 2));
        assert_eq!(s.options().lambda_equilateral, 0.0);
        assert!(parse(&["--subdivide", "4"]).is_err());
        assert!(parse(&["--dilation", "-1"]).is_err());
    }

    #[test]
    fn settings_read_back_from_json_with_missing_ones_at_their_defaults() {
        let s = TrainSettings { iterations: 7, skirt: SkirtMode::Off, ..TrainSettings::default() };
        let text = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<TrainSettings>(&text).unwrap(), s);
        let seeded = serde_json::from_str::<TrainSettings>(r#"{"seed": 3, "device": "cpu"}"#).unwrap();
        assert_eq!(seeded, TrainSettings { seed: 3, ..TrainSettings::default() });
    }
}
