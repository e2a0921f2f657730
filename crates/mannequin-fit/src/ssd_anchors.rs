//! The pose detector's 2,254 SSD anchor centres, as MediaPipe's SsdAnchorsCalculator lays them
//! out for it: 224² input, strides 8, 16, 32, 32, 32 (layers of equal stride merged), two
//! anchors per cell (aspect ratio 1 plus the interpolated scale, also 1), centres at
//! ((x + 0.5) / f, (y + 0.5) / f) for an f×f feature map, fixed unit size.

/// Strides of the detector's five anchor layers.
const STRIDES: [usize; 5] = [8, 16, 32, 32, 32];
const INPUT_SIZE: usize = 224;

/// Anchor centres in [0, 1] of the detector input, in the network's output order.
pub fn anchors() -> Vec<[f32; 2]> {
    let mut out = Vec::new();
    let mut layer = 0;
    while layer < STRIDES.len() {
        let stride = STRIDES[layer];
        let mut per_cell = 0;
        while layer < STRIDES.len() && STRIDES[layer] == stride {
            per_cell += 2;
            layer += 1;
        }
        let f = INPUT_SIZE.div_ceil(stride);
        for y in 0..f {
            for x in 0..f {
                let centre = [(x as f32 + 0.5) / f as f32, (y as f32 + 0.5) / f as f32];
                out.extend(std::iter::repeat_n(centre, per_cell));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_detector_has_2254_anchors() {
        let a = anchors();
        // 28²·2 + 14²·2 + 7²·6, the length of the network's outputs.
        assert_eq!(a.len(), 2254);
        assert_eq!(a[0], [0.5 / 28.0, 0.5 / 28.0]);
        assert_eq!(a[2253], [6.5 / 7.0, 6.5 / 7.0]);
    }
}
