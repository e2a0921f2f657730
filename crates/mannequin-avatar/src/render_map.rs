//! The picture a render of an avatar is written as: colour, normals, coverage or depth.

use std::path::Path;

use mannequin_data::Image;

use crate::error::AvatarError;
use crate::predict::Prediction;

/// What a render writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RenderMap {
    /// Colour.
    Rgb,
    /// Camera-space normals.
    Normals,
    /// Coverage, white on black.
    Alpha,
    /// Depth, near bright (or metric values in a `.npy` output).
    Depth,
}

impl Prediction {
    /// Writes the `map` of this prediction to `path` as a PNG (depth: metric values where `path`
    /// ends in `.npy`).
    pub fn write_map(&self, map: RenderMap, path: &Path) -> Result<(), AvatarError> {
        let grey = |values: &[f32]| Image {
            width: self.image.width,
            height: self.image.height,
            pixels: values.iter().map(|&v| [v; 3]).collect(),
        };
        match map {
            RenderMap::Rgb => self.image.write_png(path)?,
            RenderMap::Normals => self.normals.write_png(path)?,
            RenderMap::Alpha => {
                grey(&self.mask.values.iter().map(|&m| f32::from(u8::from(m))).collect::<Vec<_>>())
                    .write_png(path)?
            }
            RenderMap::Depth if path.extension().is_some_and(|e| e == "npy") => self.depth.write_npy(path)?,
            RenderMap::Depth => {
                let fg = self.depth.depth.iter().filter(|&&d| d > 0.0);
                let (lo, hi) = fg.fold((f32::INFINITY, 0.0f32), |(lo, hi), &d| (lo.min(d), hi.max(d)));
                let span = (hi - lo).max(1e-6);
                // Near is bright, the background black.
                let v: Vec<f32> = self
                    .depth
                    .depth
                    .iter()
                    .map(|&d| if d > 0.0 { 1.0 - 0.8 * (d - lo) / span } else { 0.0 })
                    .collect();
                grey(&v).write_png(path)?
            }
        }
        Ok(())
    }
}
