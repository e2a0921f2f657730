//! Per-pixel geometry maps: camera-space normals and depth, with their on-disk encodings.
//!
//! - Normals are unit vectors in OpenCV camera axes (x right, y down, z forward), stored as an
//!   8-bit PNG with `rgb = n * 0.5 + 0.5`; background pixels are black `(0, 0, 0)`, which no unit
//!   normal encodes to, and read back as the zero vector.
//! - Depth is the camera-space z in metres, `float32 (H, W)` `.npy`, 0 on the background.

use std::path::Path;

use mannequin_io::{NpyArray, NpyData};

use crate::error::DataError;
use crate::image::{Image, Mask, quantize};

#[derive(Debug, Clone, PartialEq)]
pub struct NormalMap {
    pub width: usize,
    pub height: usize,
    /// Unit normals, or zero on the background.
    pub normals: Vec<[f32; 3]>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct DepthMap {
    pub width: usize,
    pub height: usize,
    /// Camera-space z, or 0 on the background.
    pub depth: Vec<f32>,
}

fn is_background(n: [f32; 3]) -> bool {
    n == [0.0; 3]
}

/// Averages each `factor × factor` block of normals over its foreground pixels; a block
/// without any is zero.
fn block_mean_normals(n: &NormalMap, factor: usize, out_w: usize, out_h: usize) -> Vec<[f32; 3]> {
    (0..out_w * out_h)
        .map(|p| {
            let (x, y) = (p % out_w, p / out_w);
            let mut acc = [0.0f32; 3];
            let mut count = 0;
            for k in 0..factor * factor {
                let v = n.normals[(y * factor + k / factor) * n.width + x * factor + k % factor];
                if !is_background(v) {
                    (0..3).for_each(|c| acc[c] += v[c]);
                    count += 1;
                }
            }
            if count > 0 { acc.map(|a| a / count as f32) } else { [0.0; 3] }
        })
        .collect()
}

impl NormalMap {
    /// The encoded colour image (background black).
    pub fn to_image(&self) -> Image {
        let pixels = self
            .normals
            .iter()
            .map(|&n| if is_background(n) { [0.0; 3] } else { n.map(|c| c * 0.5 + 0.5) })
            .collect();
        Image { width: self.width, height: self.height, pixels }
    }

    /// Decodes an encoded image: black is background, anything else `2 rgb − 1`. The result is
    /// not renormalised (its length is within 1/255 of one), so a read-write cycle is exact.
    pub fn from_image(img: &Image) -> Self {
        let normals = img
            .pixels
            .iter()
            .map(|&p| if p.iter().all(|&c| quantize(c) == 0) { [0.0; 3] } else { p.map(|c| 2.0 * c - 1.0) })
            .collect();
        Self { width: img.width, height: img.height, normals }
    }

    /// PNG only: JPEG's lossy blocks would bend the encoded directions and bleed colour into the
    /// black background, which would then read as normals.
    pub fn read_png(path: &Path) -> Result<Self, DataError> {
        Ok(Self::from_image(&Image::read_png(path)?))
    }

    pub fn write_png(&self, path: &Path) -> Result<(), DataError> {
        self.to_image().write_png(path)
    }

    /// Foreground-averaged, renormalised normals per block.
    pub fn downscale(&self, factor: usize) -> Self {
        let (w, h) = (self.width / factor, self.height / factor);
        let normals = block_mean_normals(self, factor, w, h)
            .into_iter()
            .map(|n| glam::Vec3::from(n).normalize_or_zero().to_array())
            .collect();
        Self { width: w, height: h, normals }
    }

    /// The pixels that carry a normal.
    pub fn mask(&self) -> Mask {
        Mask {
            width: self.width,
            height: self.height,
            values: self.normals.iter().map(|&n| !is_background(n)).collect(),
        }
    }
}

impl DepthMap {
    pub fn read_npy(path: &Path) -> Result<Self, DataError> {
        let bytes = std::fs::read(path).map_err(|e| DataError::os(path, e))?;
        let a = mannequin_io::npy::parse_npy(&bytes).map_err(|e| DataError::file(path, e.to_string()))?;
        let [h, w] = a.shape[..] else {
            return Err(DataError::file(
                path,
                format!("expected a (height, width) array, found shape {:?}", a.shape),
            ));
        };
        let depth = a
            .to_f32()
            .ok_or_else(|| DataError::file(path, format!("expected numbers, found {}", a.dtype_name())))?;
        if let Some(i) = depth.iter().position(|d| !(d.is_finite() && *d >= 0.0)) {
            return Err(DataError::file(
                path,
                format!(
                    "pixel {i} has depth {}: expected a finite distance ≥ 0 (0 for background)",
                    depth[i]
                ),
            ));
        }
        Ok(Self { width: w, height: h, depth })
    }

    pub fn write_npy(&self, path: &Path) -> Result<(), DataError> {
        let bytes =
            mannequin_io::npy::write_npy(&NpyArray::f32(vec![self.height, self.width], self.depth.clone()));
        mannequin_io::write_atomic(path, &bytes).map_err(|e| DataError::os(path, e))
    }

    /// The nearest foreground depth of each block: a depth of a surface that is really there,
    /// where an average across a depth edge would float between two surfaces.
    pub fn downscale(&self, factor: usize) -> Self {
        let (w, h) = (self.width / factor, self.height / factor);
        let depth = (0..w * h)
            .map(|p| {
                let (x, y) = (p % w, p / w);
                (0..factor * factor)
                    .map(|k| self.depth[(y * factor + k / factor) * self.width + x * factor + k % factor])
                    .filter(|&d| d > 0.0)
                    .fold(0.0f32, |m, d| if m == 0.0 { d } else { m.min(d) })
            })
            .collect();
        Self { width: w, height: h, depth }
    }
}

/// Reads a `(H, W)` mask `.npy`; values ≥ 0.5 are foreground, so 0/1 and 0/255 both work.
/// Floating-point masks must lie in [0, 1] and whole-number ones in [0, 255]: anything else
/// (a NaN, a negative) is not a mask.
pub fn read_mask_npy(path: &Path) -> Result<Mask, DataError> {
    let bytes = std::fs::read(path).map_err(|e| DataError::os(path, e))?;
    let a = mannequin_io::npy::parse_npy(&bytes).map_err(|e| DataError::file(path, e.to_string()))?;
    let (h, w) = match a.shape[..] {
        [h, w] | [h, w, 1] => (h, w),
        _ => {
            return Err(DataError::file(
                path,
                format!("expected a (height, width) mask, found shape {:?}", a.shape),
            ));
        }
    };
    let v = a
        .to_f64()
        .ok_or_else(|| DataError::file(path, format!("expected numbers, found {}", a.dtype_name())))?;
    let top = if matches!(a.data, NpyData::F32(_) | NpyData::F64(_)) { 1.0 } else { 255.0 };
    if let Some(i) = v.iter().position(|x| !(0.0..=top).contains(x)) {
        return Err(DataError::file(
            path,
            format!("pixel {i} is {}: expected a mask value in [0, {top}]", v[i]),
        ));
    }
    Ok(Mask { width: w, height: h, values: v.into_iter().map(|x| x >= 0.5).collect() })
}

/// Writes a mask as a `(H, W)` array of 0/1 (NumPy `bool`, one byte per pixel).
pub fn write_mask_npy(path: &Path, mask: &Mask) -> Result<(), DataError> {
    let a = NpyArray {
        shape: vec![mask.height, mask.width],
        data: NpyData::U8(mask.values.iter().map(|&m| m as u8).collect()),
    };
    mannequin_io::write_atomic(path, &mannequin_io::npy::write_npy(&a)).map_err(|e| DataError::os(path, e))
}
