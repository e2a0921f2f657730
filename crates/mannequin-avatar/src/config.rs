//! What an avatar is made of, saved next to its parameters as `avatar.json`.

use mannequin_io::limits::MAX_ARRAY_ELEMENTS;
use serde::{Deserialize, Serialize};

use crate::hash_grid::HashGridConfig;

/// The screen filter the avatar renders with (px², the renderer's `dilation`). 3DGS's 0.3 widens
/// an edge-on opaque disk to alpha ½ at ≈0.65 px past the surface; fitting masks and colour then
/// shrinks the mesh by that much (≈3.6 mm at 540×540 on a standing subject). 0.1 keeps the
/// overshoot near 0.37 px while every disk stays wider than a pixel's spacing to sample. On
/// synthetic subject 0 (2,000 iterations) Chamfer went 0.507 → 0.352 cm and novel-view PSNR
/// 32.3 → 33.1 dB.
pub const AVATAR_DILATION: f64 = 0.1;

/// Most hash-grid levels an avatar may have: instant-ngp and both papers use 16, and every level
/// costs a table lookup per point.
pub const MAX_HASH_LEVELS: usize = 32;

/// Widest hidden layer of an avatar's MLPs: the papers use 64, and a layer's activations cost
/// this many floats per canonical vertex.
pub const MAX_HIDDEN_WIDTH: usize = 1024;

/// What models saved before the setting existed were trained with: the renderer's default.
fn legacy_dilation() -> f64 {
    mannequin_splat::DILATION
}

/// How Gaussians are bound to the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Tavatar: attributes derived analytically from the posed mesh; only colour is learned.
    Tavatar,
    /// iHuman: face-centroid Gaussians with learned in-plane rotation and scales, a hash-grid
    /// colour encoder and learned joints.
    Ihuman,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AvatarConfig {
    pub method: Method,
    /// Tavatar's face Gaussians (Eqs. 5–8); off for the "w/o FG" ablation.
    pub face_gaussians: bool,
    /// Tavatar's vertex Gaussians (Eqs. 9–11); off for the "w/o VG" ablation.
    pub vertex_gaussians: bool,
    /// Midpoint subdivisions of the body template.
    pub subdivisions: usize,
    /// SH degree of Tavatar's per-Gaussian colour.
    pub sh_degree: usize,
    /// Hash-grid levels, log2 table size, base resolution, growth, features per level.
    pub hash_levels: usize,
    pub hash_log2_table: u32,
    pub hash_base_resolution: u32,
    pub hash_growth: f64,
    pub hash_features: usize,
    /// Width of the MLPs' two hidden layers.
    pub hidden: usize,
    /// gsplat's antialiased mode: opacities scaled by the screen filter's compensation
    /// ([`crate::antialias`]), so silhouettes do not overshoot the mesh. Off by default (the
    /// papers render with the plain 3DGS rule); models saved before it existed load without it.
    #[serde(default)]
    pub antialiased: bool,
    /// Screen-filter variance in px² ([`AVATAR_DILATION`] for new avatars).
    #[serde(default = "legacy_dilation")]
    pub dilation: f64,
    /// A skirt layer ([`crate::skirt_layer`]) over the body; models saved before it existed
    /// have none.
    #[serde(default)]
    pub skirt_layer: bool,
    /// Seed of every random initialisation.
    pub seed: u64,
}

impl AvatarConfig {
    /// The hash grid of the avatar's fields.
    pub fn hash_grid(&self) -> HashGridConfig {
        HashGridConfig {
            levels: self.hash_levels,
            log2_table_size: self.hash_log2_table,
            base_resolution: self.hash_base_resolution,
            growth: self.hash_growth,
            features_per_level: self.hash_features,
        }
    }

    /// Refuses settings no avatar can be built with, and sizes past the limits: read from a
    /// model file, they are checked before anything is allocated for them.
    pub fn validate(&self) -> Result<(), String> {
        if self.sh_degree > 2 {
            return Err(format!("SH degree {} (0 to 2 supported)", self.sh_degree));
        }
        if !(self.dilation.is_finite() && self.dilation >= 0.0) {
            return Err(format!(
                "screen-filter dilation {} px² (expected a finite value >= 0)",
                self.dilation
            ));
        }
        if self.method == Method::Tavatar && !self.face_gaussians && !self.vertex_gaussians {
            return Err("face and vertex Gaussians are both off: nothing to render".into());
        }
        if !(1..=MAX_HIDDEN_WIDTH).contains(&self.hidden) {
            return Err(format!("hidden width {} (expected 1 to {MAX_HIDDEN_WIDTH})", self.hidden));
        }
        if self.hash_levels > MAX_HASH_LEVELS {
            return Err(format!(
                "{} hash-grid levels (expected at most {MAX_HASH_LEVELS})",
                self.hash_levels
            ));
        }
        let grid = self.hash_grid();
        grid.validate().map_err(|e| format!("hash grid: {e}"))?;
        let entries = grid.table_rows() * grid.features_per_level;
        if entries > MAX_ARRAY_ELEMENTS {
            return Err(format!(
                "a hash-grid table of {entries} values (expected at most {MAX_ARRAY_ELEMENTS}, what one stored array may hold)"
            ));
        }
        Ok(())
    }

    /// The seeds' settings for `method`.
    pub fn new(method: Method, seed: u64) -> Self {
        Self {
            method,
            face_gaussians: true,
            vertex_gaussians: method == Method::Tavatar,
            subdivisions: 0,
            sh_degree: 2,
            hash_levels: 16,
            // iHuman's supplement §1.1 gives 2^17 rows per level; Tavatar gives none. Its 13k
            // canonical vertices touch at most 107k corners per level, and on synthetic subject 0
            // 2^15 scores as 2^17 does (novel-view PSNR 32.30 vs 32.31 dB, Chamfer 0.511 cm both)
            // while Adam and the encoder's gather move a quarter of the memory.
            hash_log2_table: if method == Method::Ihuman { 17 } else { 15 },
            hash_base_resolution: 4,
            hash_growth: 1.5,
            // iHuman supplement §1.1: 4 features per entry; instant-ngp's default of 2 otherwise.
            hash_features: if method == Method::Ihuman { 4 } else { 2 },
            hidden: 64,
            antialiased: false,
            dilation: AVATAR_DILATION,
            skirt_layer: false,
            seed,
        }
    }
}
