//! The blur on the CPU, shared by the Flex blur op and the fused SSIM. Each rayon task takes a
//! band of output rows of one group of planes and streams through it: every new source row is
//! filtered horizontally into a ring of the last 11, then the columns are filtered from the
//! ring, so the working set stays in cache. Both filters accumulate blocks of outputs in
//! registers, all 11 taps before a store.

use std::ops::{Add, AddAssign, Div, Mul, Sub};

use burn::tensor::Element;
use rayon::prelude::*;

use super::{TAPS, gaussian_window};

/// Output rows per task.
const BAND: usize = 64;

/// Outputs computed together, in registers: 16 f32 lanes fill an AVX-512 register.
const LANES: usize = 16;

/// The float types the host code runs in.
pub(crate) trait Sample:
    Element
    + Default
    + AddAssign
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
{
    fn of(v: f64) -> Self;
}

impl Sample for f32 {
    fn of(v: f64) -> Self {
        v as f32
    }
}

impl Sample for f64 {
    fn of(v: f64) -> Self {
        v
    }
}

/// `out[x] = Σ_k g[k] · taps[k][x]`, with every `taps[k]` at least `out.len()` long: one row
/// filtered horizontally (the taps are shifted views of the row) or one output row filtered
/// vertically (the taps are 11 rows).
fn weighted_sum<T: Sample>(g: &[T; TAPS], taps: &[&[T]; TAPS], out: &mut [T]) {
    let taps: [&[T]; TAPS] = std::array::from_fn(|k| &taps[k][..out.len()]);
    let blocks = out.len() / LANES;
    for (b, block) in out[..blocks * LANES].chunks_exact_mut(LANES).enumerate() {
        let mut acc = [T::default(); LANES];
        for (gk, tap) in g.iter().zip(&taps) {
            for (a, &v) in acc.iter_mut().zip(&tap[b * LANES..(b + 1) * LANES]) {
                *a += *gk * v;
            }
        }
        block.copy_from_slice(&acc);
    }
    for x in blocks * LANES..out.len() {
        out[x] = g.iter().zip(&taps).fold(T::default(), |a, (&gk, tap)| a + gk * tap[x]);
    }
}

/// A batch of planes to blur: `groups` groups of `k` planes of `h × w`, read with zero padding
/// `p` (0 for the 'valid' blur, 10 for its transpose).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Planes {
    pub groups: usize,
    pub k: usize,
    pub h: usize,
    pub w: usize,
    pub p: usize,
}

impl Planes {
    /// Output rows, `h + 2p − 10`.
    pub fn out_h(&self) -> usize {
        self.h + 2 * self.p + 1 - TAPS
    }

    /// Output columns, `w + 2p − 10`.
    pub fn out_w(&self) -> usize {
        self.w + 2 * self.p + 1 - TAPS
    }
}

/// Blurs the planes and hands the results over row by row:
/// - `source(group, y, rows)` writes source row `y` of the group's `k` planes into `rows`
///   (`k × w`), so callers can blur products or functions of images without storing them;
/// - `finish(group, y, blurred, out_row)` receives output row `y` of the group's `k` blurred
///   planes (`k × out_w`) and writes row `y` of the group's output, `out_width` wide.
///
/// Returns the output, `[groups, out_h, out_width]`.
pub(crate) fn blur_rows<T: Sample>(
    s: Planes,
    out_width: usize,
    source: impl Fn(usize, usize, &mut [T]) + Sync,
    finish: impl Fn(usize, usize, &[T], &mut [T]) + Sync,
) -> Vec<T> {
    let g = gaussian_window().map(T::of);
    let (oh, ow, w, k) = (s.out_h(), s.out_w(), s.w, s.k);
    let mut out = vec![T::default(); s.groups * oh * out_width];
    out.par_chunks_mut(oh * out_width).enumerate().for_each(|(group, group_out)| {
        group_out.par_chunks_mut(BAND * out_width).enumerate().for_each(|(band, band_out)| {
            // Padded row r is source row r − p, zero outside the image; the ring holds the
            // last 11 filtered rows of each plane, padded row r in slot r % 11.
            let mut src = vec![T::default(); k * w];
            let mut padded = vec![T::default(); w + 2 * s.p];
            let mut filter_row = |r: usize, ring: &mut [T]| {
                let slot = r % TAPS;
                match r.checked_sub(s.p).filter(|&y| y < s.h) {
                    Some(y) => {
                        source(group, y, &mut src);
                        for (j, row) in src.chunks_exact(w).enumerate() {
                            let out = &mut ring[(j * TAPS + slot) * ow..][..ow];
                            let row = if s.p == 0 {
                                row
                            } else {
                                padded[s.p..s.p + w].copy_from_slice(row);
                                &padded
                            };
                            weighted_sum(&g, &std::array::from_fn(|t| &row[t..]), out);
                        }
                    }
                    None => (0..k).for_each(|j| ring[(j * TAPS + slot) * ow..][..ow].fill(T::default())),
                }
            };
            let mut ring = vec![T::default(); k * TAPS * ow];
            let mut blurred = vec![T::default(); k * ow];
            let y0 = band * BAND;
            for r in y0..y0 + TAPS - 1 {
                filter_row(r, &mut ring);
            }
            for (i, out_row) in band_out.chunks_exact_mut(out_width).enumerate() {
                let y = y0 + i;
                filter_row(y + TAPS - 1, &mut ring);
                for (j, b) in blurred.chunks_exact_mut(ow).enumerate() {
                    let plane = &ring[j * TAPS * ow..][..TAPS * ow];
                    weighted_sum(&g, &std::array::from_fn(|t| &plane[((y + t) % TAPS) * ow..][..ow]), b);
                }
                finish(group, y, &blurred, out_row);
            }
        });
    });
    out
}
