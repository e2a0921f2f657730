//! Exclusive prefix sums of `u32` device buffers, for sizing and placing the tile lists.
//!
//! Each unit scans a chunk of `CHUNK` values one after the other, and the chunk totals are
//! scanned the same way, recursively. Per-unit loops stay `CHUNK` long: Mesa's lavapipe stops any
//! shader loop after 65,535 iterations, so no unit may walk a whole buffer (Burn's own `cumsum`
//! does).

use burn::backend::wgpu::CubeTensor;
use burn_cubecl::cubecl;
use cubecl::prelude::*;

use super::device_buffers::{buffer, u32_of, units_dim, units_grid, zeros};

/// Values one unit scans: long enough that a radix pass's counts take two or three levels.
const CHUNK: u32 = 256;

/// `totals[u]` is the sum of chunk `u`.
#[cube(launch)]
fn chunk_totals(values: &[u32], totals: &mut [u32], len: u32) {
    let u = ABSOLUTE_POS as u32;
    let start = u * CHUNK;
    if start >= len {
        terminate!();
    }
    let end = min(start + CHUNK, len);
    let mut sum = 0u32;
    for k in start..end {
        sum += values[k as usize];
    }
    totals[u as usize] = sum;
}

/// Replaces each chunk by its exclusive prefix sums, starting from the chunk's offset.
#[cube(launch)]
fn chunk_scan(values: &mut [u32], offsets: &[u32], len: u32) {
    let u = ABSOLUTE_POS as u32;
    let start = u * CHUNK;
    if start >= len {
        terminate!();
    }
    let end = min(start + CHUNK, len);
    let mut sum = offsets[u as usize];
    for k in start..end {
        let v = values[k as usize];
        values[k as usize] = sum;
        sum += v;
    }
}

/// Replaces the first `len` values of `values` (`u32`s) by their exclusive prefix sums.
pub(super) fn exclusive_scan(values: &CubeTensor, len: usize) {
    if len == 0 {
        return;
    }
    let chunks = len.div_ceil(CHUNK as usize);
    let client = &values.client;
    let offsets = if chunks == 1 {
        zeros(vec![1], values)
    } else {
        let totals = buffer(chunks, values);
        chunk_totals::launch(
            client,
            units_grid(chunks),
            units_dim(),
            values.clone().into_buffer_arg(),
            totals.clone().into_buffer_arg(),
            u32_of(len),
        );
        exclusive_scan(&totals, chunks);
        totals
    };
    chunk_scan::launch(
        client,
        units_grid(chunks),
        units_dim(),
        values.clone().into_buffer_arg(),
        offsets.into_buffer_arg(),
        u32_of(len),
    );
}

#[cfg(test)]
mod tests {
    use super::super::device_buffers::testing::{device, read_words, words};
    use super::*;

    /// Lengths around the chunk sizes, and one past lavapipe's loop limit.
    #[test]
    fn exclusive_scan_matches_a_running_sum() {
        let device = device();
        for len in [1, 255, 256, 257, 65_536, 65_537, 70_001] {
            let values: Vec<u32> = (0..len as u32).map(|i| (i * 7919) % 13).collect();
            let t = words(&values, &device);
            exclusive_scan(&t, len);
            let mut sum = 0;
            let want: Vec<u32> = values
                .iter()
                .map(|&v| {
                    sum += v;
                    sum - v
                })
                .collect();
            assert_eq!(read_words(t, len), want, "length {len}");
        }
    }
}
