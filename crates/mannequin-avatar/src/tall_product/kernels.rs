//! CubeCL kernels of `aᵀ·b` over a long shared dimension K, split in chunks of rows: one unit per
//! (chunk, output) sums its chunk, then one unit per output sums the chunks.

// Kernels index their buffers: iterator forms do not exist in CubeCL.
#![allow(clippy::needless_range_loop)]

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// `partials[c, m·N + n] = Σ_{k in chunk c} a[k·a_k + m·a_m]·b[k·N + n]`, where `a` is 1
/// everywhere when `ones` (column sums of `b`).
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn chunk_products(
    a: &[f32],
    b: &[f32],
    partials: &mut [f32],
    k_len: u32,
    m_len: u32,
    n_len: u32,
    a_k: u32,
    a_m: u32,
    chunk: u32,
    #[comptime] ones: bool,
) {
    let outputs = (m_len * n_len) as usize;
    let i = ABSOLUTE_POS;
    let c = i / outputs;
    let o = i % outputs;
    let start = c * chunk as usize;
    if start >= k_len as usize {
        terminate!();
    }
    let (m, n) = (o / n_len as usize, o % n_len as usize);
    let end = min(start + chunk as usize, k_len as usize);
    let mut sum = 0.0f32;
    for k in start..end {
        let x = b[k * n_len as usize + n];
        if ones {
            sum += x;
        } else {
            sum += a[k * a_k as usize + m * a_m as usize] * x;
        }
    }
    partials[i] = sum;
}

/// `out[o] = Σ_c partials[c, o]`, chunks in order.
#[cube(launch)]
pub(crate) fn sum_chunks(partials: &[f32], out: &mut [f32], chunks: u32, outputs: u32) {
    let o = ABSOLUTE_POS;
    if o >= outputs as usize {
        terminate!();
    }
    let mut sum = 0.0f32;
    for c in 0..chunks as usize {
        sum += partials[c * outputs as usize + o];
    }
    out[o] = sum;
}
