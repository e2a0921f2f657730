//! The forward pass's state for the backward pass (packed Gaussians, tile lists, per-pixel
//! replay lengths), flattened into one `f32` tensor so that Burn can keep it between the passes.
//! Integers travel as their bit patterns, so nothing is rounded.

use crate::composite::Packed;
use crate::render::{Prepared, RenderOutput, Saved};
use crate::tiles::Tiles;

/// Eight sizes (as bit patterns), then the count of Gaussians skipped for a NaN or infinite
/// parameter, as an `f32` value (exact up to 2²⁴) so that callers can read it as a number.
pub(crate) const HEADER: usize = 9;
pub(crate) const SKIPPED: usize = 8;

fn bits(v: usize) -> f32 {
    f32::from_bits(v as u32)
}

fn int(v: f32) -> usize {
    v.to_bits() as usize
}

/// Where each part of the flattened state starts, in words.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WordLayout {
    pub stride: usize,
    pub tiles_x: usize,
    pub offsets: usize,
    pub ids: usize,
    pub rows: usize,
    pub last: usize,
}

impl WordLayout {
    /// Reads the sizes at the start of the header.
    pub fn parse(words: &[f32]) -> Option<Self> {
        let h: Vec<usize> = words.get(..SKIPPED)?.iter().map(|&v| int(v)).collect();
        let [stride, tiles_x, _tiles_y, n_order, n_offsets, n_ids, _n_last, n_rows] = h[..] else {
            return None;
        };
        let offsets = HEADER + n_order;
        let ids = offsets + n_offsets;
        let rows = ids + n_ids;
        Some(WordLayout { stride, tiles_x, offsets, ids, rows, last: rows + n_rows })
    }
}

/// The sizes in the header: stride, tiles across and down, then the lengths of the depth order,
/// the tile offsets, the tile lists, the replay lengths and the packed rows. They are followed by
/// the skipped count (the caller's), then the parts in that order, the replay lengths last.
pub(crate) fn size_words(sizes: [usize; 8]) -> Vec<f32> {
    sizes.map(bits).to_vec()
}

/// Flattens the binning and packing (everything but the per-pixel replay lengths, which come
/// last and are `npx` words long).
fn encode_prepared(prep: &Prepared<f32>, npx: usize, skipped: usize) -> Vec<f32> {
    let Prepared { packed, tiles } = prep;
    let sizes = [
        packed.stride,
        tiles.tiles_x,
        tiles.tiles_y,
        tiles.order.len(),
        tiles.offsets.len(),
        tiles.ids.len(),
        npx,
        packed.rows.len(),
    ];
    let mut w = size_words(sizes);
    w.push(skipped as f32);
    w.extend(tiles.order.iter().map(|&v| bits(v as usize)));
    w.extend(tiles.offsets.iter().map(|&v| bits(v)));
    w.extend(tiles.ids.iter().map(|&v| bits(v as usize)));
    w.extend_from_slice(&packed.rows);
    w
}

/// Flattens what [`crate::backward`] needs besides the images.
pub(crate) fn encode(out: &RenderOutput<f32>) -> Vec<f32> {
    let mut w = encode_prepared(&out.saved.prep, out.saved.last.len(), out.skipped);
    w.extend(out.saved.last.iter().map(|&v| bits(v as usize)));
    w
}

/// Rebuilds a forward output from its images (`[C + 2, H, W]`: colour, alpha, depth) and the
/// words [`encode`] wrote. Returns `None` if the words are not such a state.
pub(crate) fn decode(
    rendered: &[f32],
    words: &[f32],
    width: usize,
    height: usize,
) -> Option<RenderOutput<f32>> {
    let npx = width * height;
    let channels = (rendered.len() / npx.max(1)).checked_sub(2)?;
    let header: Vec<usize> = words.get(..SKIPPED)?.iter().map(|&v| int(v)).collect();
    let [stride, tiles_x, tiles_y, n_order, n_offsets, n_ids, n_last, n_rows] = header[..] else {
        return None;
    };
    let skipped = *words.get(SKIPPED)? as usize;
    let mut at = HEADER;
    let mut take = |n: usize| -> Option<&[f32]> {
        let s = words.get(at..at + n)?;
        at += n;
        Some(s)
    };
    let order = take(n_order)?.iter().map(|&v| int(v) as u32).collect();
    let offsets = take(n_offsets)?.iter().map(|&v| int(v)).collect();
    let ids = take(n_ids)?.iter().map(|&v| int(v) as u32).collect();
    let rows = take(n_rows)?.to_vec();
    let last: Vec<u32> = take(n_last)?.iter().map(|&v| int(v) as u32).collect();
    if last.len() != npx || rendered.len() != (channels + 2) * npx {
        return None;
    }
    let tiles = Tiles { tiles_x, tiles_y, order, offsets, ids };
    Some(RenderOutput {
        width,
        height,
        channels,
        image: rendered[..channels * npx].to_vec(),
        alpha: rendered[channels * npx..(channels + 1) * npx].to_vec(),
        depth: rendered[(channels + 1) * npx..].to_vec(),
        count: None,
        skipped,
        saved: Saved { prep: Prepared { packed: Packed { stride, rows }, tiles }, last },
    })
}
