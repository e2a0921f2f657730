//! Exclusive prefix sums of `u32` device buffers, for sizing and placing the tile lists.
//!
//! Up to `CHUNK²` values (a radix pass's counts for 65,536 pairs) are scanned by one cube in one
//! launch: each of its `CHUNK` units sums a run, the run totals are scanned in shared memory, and
//! each unit rewrites its run. Longer buffers are cut into chunks of `CHUNK` values whose totals
//! are scanned the same way, recursively (three launches up to 16.7 M values). Launches, not
//! bandwidth, are what a training step's scans cost. Per-unit loops stay `CHUNK` long: Mesa's
//! lavapipe stops any shader loop after 65,535 iterations, so no unit may walk a whole buffer
//! (Burn's own `cumsum` does).

use burn::backend::wgpu::CubeTensor;
use burn_cubecl::cubecl;
use cubecl::prelude::*;

use super::device_buffers::{buffer, u32_of, units_dim, units_grid};

/// Values one unit scans, and units in the one-cube scan.
const CHUNK: u32 = 256;

/// The exclusive prefix sums of `len ≤ CHUNK²` values, in place, by one cube of `CHUNK` units,
/// each owning a run of `run` consecutive values.
#[cube(launch)]
fn scan_in_one_cube(values: &mut [u32], len: u32, run: u32) {
    let u = UNIT_POS_X;
    let end = min(u * run + run, len);
    let start = min(u * run, end);
    let mut sum = 0u32;
    for k in start..end {
        sum += values[k as usize];
    }
    let mut starts = Shared::<[u32]>::new_slice(CHUNK as usize);
    starts[u as usize] = sum;
    sync_cube();
    if u == 0 {
        let mut total = 0u32;
        for r in 0..CHUNK {
            let t = starts[r as usize];
            starts[r as usize] = total;
            total += t;
        }
    }
    sync_cube();
    let mut at = starts[u as usize];
    for k in start..end {
        let v = values[k as usize];
        values[k as usize] = at;
        at += v;
    }
}

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
    let client = &values.client;
    let chunks = len.div_ceil(CHUNK as usize);
    if chunks <= CHUNK as usize {
        scan_in_one_cube::launch(
            client,
            CubeCount::Static(1, 1, 1),
            CubeDim::new_1d(CHUNK),
            values.clone().into_buffer_arg(),
            u32_of(len),
            u32_of(len.div_ceil(CHUNK as usize)),
        );
        return;
    }
    let offsets = buffer(chunks, values);
    chunk_totals::launch(
        client,
        units_grid(chunks),
        units_dim(),
        values.clone().into_buffer_arg(),
        offsets.clone().into_buffer_arg(),
        u32_of(len),
    );
    exclusive_scan(&offsets, chunks);
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

    /// Lengths around the one-cube limit (`CHUNK²`), the chunk sizes, lavapipe's loop limit and
    /// the two-level limit (`CHUNK³`).
    #[test]
    fn exclusive_scan_matches_a_running_sum() {
        let device = device();
        for len in [1, 2, 255, 256, 257, 65_535, 65_536, 65_537, 70_001, 16_777_216, 16_777_217] {
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
