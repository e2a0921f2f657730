//! A stable sort of `(key, value)` pairs of `u32`s on the device: least-significant-digit radix
//! sort, 8 bits a pass (four passes for a depth key: each pass is three to five launches, and
//! launches, not bandwidth, are what a training step's sorts cost). Stability is what makes the tile lists come out exactly as the CPU
//! binning's: equal keys keep their input order (ties by Gaussian index, then by depth rank).
//!
//! Each unit owns a run of `CHUNK` consecutive pairs. A pass counts the digits of every run, lays
//! the counts out digit-major (`counts[d · units + u]`), so that their exclusive prefix sum is
//! where run `u`'s first pair with digit `d` goes, and then each run scatters its pairs in order.
//! Loops stay `CHUNK` long (lavapipe's 65,535-iteration limit).

use burn::backend::wgpu::CubeTensor;
use burn_cubecl::cubecl;
use cubecl::prelude::*;

use super::device_buffers::{buffer, u32_of, units_dim, units_grid};
use super::scan::exclusive_scan;

/// Bits sorted per pass, and the digit values.
const DIGIT_BITS: u32 = 8;
const DIGITS: usize = 1 << DIGIT_BITS;

/// Pairs one unit owns: as many as digit values, so a pass's counts are about as many as its
/// pairs and their scan takes two levels.
const CHUNK: u32 = 256;

#[cube(launch)]
fn digit_counts(keys: &[u32], counts: &mut [u32], len: u32, shift: u32, units: u32) {
    let u = ABSOLUTE_POS as u32;
    if u >= units {
        terminate!();
    }
    let mut c = Array::<u32>::new(DIGITS);
    #[unroll]
    for d in 0..DIGITS {
        c[d] = 0u32;
    }
    let start = u * CHUNK;
    let end = min(start + CHUNK, len);
    for k in start..end {
        let d = (keys[k as usize] >> shift) & (DIGITS as u32 - 1);
        c[d as usize] += 1u32;
    }
    #[unroll]
    for d in 0..DIGITS {
        counts[d * units as usize + u as usize] = c[d];
    }
}

#[cube(launch)]
#[allow(clippy::too_many_arguments)]
fn digit_scatter(
    keys: &[u32],
    values: &[u32],
    starts: &[u32],
    keys_out: &mut [u32],
    values_out: &mut [u32],
    len: u32,
    shift: u32,
    units: u32,
) {
    let u = ABSOLUTE_POS as u32;
    if u >= units {
        terminate!();
    }
    let mut at = Array::<u32>::new(DIGITS);
    #[unroll]
    for d in 0..DIGITS {
        at[d] = starts[d * units as usize + u as usize];
    }
    let start = u * CHUNK;
    let end = min(start + CHUNK, len);
    for k in start..end {
        let key = keys[k as usize];
        let d = ((key >> shift) & (DIGITS as u32 - 1)) as usize;
        let to = at[d];
        keys_out[to as usize] = key;
        values_out[to as usize] = values[k as usize];
        at[d] = to + 1u32;
    }
}

/// Sorts the first `len` pairs by the low `bits` bits of their keys, stably. Returns the sorted
/// keys and values (`u32` buffers of `len` words, or the inputs when there is nothing to do).
pub(super) fn sort_pairs(
    mut keys: CubeTensor,
    mut values: CubeTensor,
    len: usize,
    bits: u32,
) -> (CubeTensor, CubeTensor) {
    if len < 2 {
        return (keys, values);
    }
    let units = len.div_ceil(CHUNK as usize);
    let counts = buffer(DIGITS * units, &keys);
    let mut spare = (buffer(len, &keys), buffer(len, &keys));
    let client = keys.client.clone();
    for shift in (0..bits).step_by(DIGIT_BITS as usize) {
        digit_counts::launch(
            &client,
            units_grid(units),
            units_dim(),
            keys.clone().into_buffer_arg(),
            counts.clone().into_buffer_arg(),
            u32_of(len),
            shift,
            u32_of(units),
        );
        exclusive_scan(&counts, DIGITS * units);
        digit_scatter::launch(
            &client,
            units_grid(units),
            units_dim(),
            keys.clone().into_buffer_arg(),
            values.clone().into_buffer_arg(),
            counts.clone().into_buffer_arg(),
            spare.0.clone().into_buffer_arg(),
            spare.1.clone().into_buffer_arg(),
            u32_of(len),
            shift,
            u32_of(units),
        );
        (keys, values, spare) = (spare.0, spare.1, (keys, values));
    }
    (keys, values)
}

#[cfg(test)]
mod tests {
    use super::super::device_buffers::testing::{device, read_words, words};
    use super::*;

    /// Few distinct keys (many ties, so stability shows), spread over every digit, on more pairs
    /// than one unit or one cube handles.
    #[test]
    fn sort_pairs_is_a_stable_sort() {
        let device = device();
        let mut state = 11u64;
        for (len, bits) in [(1usize, 32), (200, 7), (100_000, 32)] {
            let keys: Vec<u32> = (0..len)
                .map(|_| {
                    state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    let k = (state >> 59) as u32;
                    (k * 0x0842_1084) & ((1u64 << bits) - 1) as u32
                })
                .collect();
            let values: Vec<u32> = (0..len as u32).collect();
            let (k, v) = sort_pairs(words(&keys, &device), words(&values, &device), len, bits);
            let mut want: Vec<(u32, u32)> = keys.iter().copied().zip(values).collect();
            want.sort_by_key(|&(k, _)| k);
            let got: Vec<(u32, u32)> = read_words(k, len).into_iter().zip(read_words(v, len)).collect();
            assert!(got == want, "{len} pairs on {bits} bits");
        }
    }
}
