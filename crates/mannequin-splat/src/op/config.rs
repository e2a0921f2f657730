//! What the op knows besides its tensors: the camera, the rules and the input forms (host data,
//! not differentiated), and the flat inputs read as the CPU renderer's Gaussians.

use std::sync::{Arc, OnceLock};

use crate::gaussians::{Colors, Gaussians, Rotations};
use crate::{Camera, RenderOptions, SplatError};

/// The five differentiable inputs, flattened row-major.
pub(crate) struct Inputs<'a> {
    pub means: &'a [f32],
    pub rotations: &'a [f32],
    pub scales: &'a [f32],
    pub opacities: &'a [f32],
    pub colors: &'a [f32],
}

/// How the op reads its flat inputs: the camera, the rules, and the input forms. Host data, not
/// differentiated.
#[derive(Clone, Debug)]
pub struct SplatConfig {
    pub camera: Camera,
    pub options: RenderOptions,
    /// Quaternions (4 values per Gaussian) or matrices (9).
    pub matrices: bool,
    /// SH degree, or `None` for features.
    pub sh_degree: Option<usize>,
    /// Values per Gaussian in the colour input.
    pub color_len: usize,
    /// The saved state's header as the CubeCL forward wrote it, kept on the host: the backward
    /// gets a clone of this config and so need not wait for a read-back from the device. Each
    /// config serves one forward ([`super::splat_render`] makes one per call).
    pub(crate) header: Arc<OnceLock<Vec<f32>>>,
}

impl SplatConfig {
    pub(crate) fn gaussians<'a>(&self, x: &Inputs<'a>) -> Gaussians<'a, f32> {
        Gaussians {
            means: x.means,
            rotations: if self.matrices {
                Rotations::Matrices(x.rotations)
            } else {
                Rotations::Quaternions(x.rotations)
            },
            scales: x.scales,
            opacities: x.opacities,
            colors: match self.sh_degree {
                Some(degree) => Colors::Sh { degree, coeffs: x.colors },
                None => Colors::Features { channels: self.color_len, values: x.colors },
            },
        }
    }

    pub(super) fn channels(&self) -> usize {
        if self.sh_degree.is_some() { 3 } else { self.color_len }
    }
}

impl SplatConfig {
    pub(super) fn options_checked(&self) -> Result<(), SplatError> {
        // Validate the options against a zero-Gaussian input of the right form.
        let x = Inputs { means: &[], rotations: &[], scales: &[], opacities: &[], colors: &[] };
        let g = self.gaussians(&x);
        crate::render::validate(&g, &self.camera, &self.options, false)
    }
}
