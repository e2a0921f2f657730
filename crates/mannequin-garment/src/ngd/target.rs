//! One training frame's targets, read from the dataset: the garment's share of each pixel from
//! the label map, which pixels count (hands left out, NGD Eq. 13: a hand in front of the garment
//! is an occlusion the rendered mesh does not have), and the camera-space normals of the normal
//! map where the dataset has one.

use std::path::Path;

use mannequin_data::labels::LabelMap;
use mannequin_data::maps::read_mask_npy;
use mannequin_data::{Camera, NormalMap, layout};

use crate::error::GarmentError;

pub struct Target {
    pub frame: usize,
    /// Per pixel, the share of its samples labelled as the garment.
    pub mask: Vec<f64>,
    /// Whether the pixel counts (not a hand, nor a garment worn over this one).
    pub counts: Vec<bool>,
    /// Per pixel, the normal in the camera's axes (zero on the background), if the dataset has
    /// normal maps.
    pub normals: Option<Vec<[f64; 3]>>,
}

impl Target {
    /// Frame `frame` of the dataset at `root`, at the resolution of `camera` (the label map's size
    /// divided by a whole factor). Pixels of the labels `outer` (garments worn over this one,
    /// which may hide it) do not count, as hands do not. Every label must be one of the `legend`
    /// the dataset names.
    pub fn read(
        root: &Path,
        camera: &Camera,
        frame: usize,
        label: u8,
        legend: usize,
        outer: &[u8],
    ) -> Result<Self, GarmentError> {
        let path = layout::label(root, frame);
        let labels = LabelMap::read_png_with_legend(&path, legend)?;
        let factor = labels.width / camera.width.max(1);
        if factor == 0 || labels.width != factor * camera.width || labels.height != factor * camera.height {
            return Err(GarmentError::File {
                path: path.display().to_string(),
                reason: format!(
                    "{}×{}, not a whole multiple of the camera's {}×{}",
                    labels.width, labels.height, camera.width, camera.height
                ),
            });
        }
        // Hand masks are optional, but one that is there must read.
        let hand_path = layout::hand_mask(root, frame);
        let hands = if hand_path.exists() { Some(read_mask_npy(&hand_path)?) } else { None };
        let (w, h) = (camera.width, camera.height);
        let mut mask = vec![0.0; w * h];
        let mut counts = vec![true; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut share = 0.0;
                let mut hand = false;
                for dy in 0..factor {
                    for dx in 0..factor {
                        let i = (y * factor + dy) * labels.width + x * factor + dx;
                        share += f64::from(u8::from(labels.labels[i] == label));
                        hand |= hands.as_ref().is_some_and(|m| m.values.get(i).copied().unwrap_or(false))
                            || outer.contains(&labels.labels[i]);
                    }
                }
                mask[y * w + x] = share / (factor * factor) as f64;
                counts[y * w + x] = !hand;
            }
        }
        let normal_path = layout::normal(root, frame);
        let normals = if normal_path.exists() {
            let map = NormalMap::read_png(&normal_path)?;
            if (map.width, map.height) != (labels.width, labels.height) {
                return Err(GarmentError::File {
                    path: normal_path.display().to_string(),
                    reason: format!(
                        "{}×{}, but the label map is {}×{}",
                        map.width, map.height, labels.width, labels.height
                    ),
                });
            }
            let map = if factor > 1 { map.downscale(factor) } else { map };
            Some(map.normals.iter().map(|n| n.map(f64::from)).collect())
        } else {
            None
        };
        Ok(Self { frame, mask, counts, normals })
    }

    /// Intersection over union of the garment in `rendered` (channel 0 over ½) and in the label
    /// map, over the pixels that count.
    pub fn iou<const C: usize>(&self, rendered: &[[f64; C]]) -> f64 {
        let (mut inter, mut union) = (0.0, 0.0);
        for ((r, m), &c) in rendered.iter().zip(&self.mask).zip(&self.counts) {
            if c {
                let (a, b) = (r[0] > 0.5, *m > 0.5);
                inter += f64::from(u8::from(a && b));
                union += f64::from(u8::from(a || b));
            }
        }
        if union == 0.0 { 1.0 } else { inter / union }
    }
}
