//! CubeCL kernels of several products `aᵀ·b` over long shared dimensions K, split in chunks of
//! rows: one unit per (product, chunk, output) sums its chunk, then one unit per (product,
//! output) sums the chunks. Product `p`'s sizes are `table[FIELDS·p ..]`: K, M, N, a's strides
//! along K and M, and whether `a` is a column of ones (as `u32` bit patterns).

// Kernels index their buffers: iterator forms do not exist in CubeCL; nor does `div_ceil`.
#![allow(clippy::needless_range_loop, clippy::manual_div_ceil)]

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// Words per product in the table.
pub(crate) const FIELDS: usize = 6;

#[cube]
fn field(table: &[f32], p: usize, f: usize) -> usize {
    u32::reinterpret(table[FIELDS * p + f]) as usize
}

/// `partials[P_p + c·MN + m·N + n] = Σ_{k in chunk c} a[k·a_k + m·a_m]·b[k·N + n]` for product
/// `p` (partials laid out product after product from `P_p`), with `a` 1 everywhere for a
/// column of ones.
#[cube(launch)]
pub(crate) fn chunk_products(
    a: &Sequence<Box<[f32]>>,
    b: &Sequence<Box<[f32]>>,
    table: &[f32],
    partials: &mut [f32],
    chunk: u32,
) {
    let i = ABSOLUTE_POS;
    let chunk = chunk as usize;
    let mut start = 0usize;
    #[unroll]
    for p in 0..b.len() {
        let (k_len, m_len, n_len) = (field(table, p, 0), field(table, p, 1), field(table, p, 2));
        let outputs = m_len * n_len;
        // At least one chunk, so that K = 0 gives zeros.
        let units = outputs * max((k_len + chunk - 1) / chunk, 1);
        if i >= start && i < start + units {
            let local = i - start;
            let (c, o) = (local / outputs, local % outputs);
            let (m, n) = (o / n_len, o % n_len);
            let (a_k, a_m, ones) = (field(table, p, 3), field(table, p, 4), field(table, p, 5) == 1);
            let first = c * chunk;
            let end = min(first + chunk, k_len);
            let mut sum = 0.0f32;
            for k in first..end {
                let x = b.index(p)[k * n_len + n];
                if ones {
                    sum += x;
                } else {
                    sum += a.index(p)[k * a_k + m * a_m] * x;
                }
            }
            partials[i] = sum;
        }
        start += units;
    }
}

/// `out_p[o] = Σ_c partials[P_p + c·MN + o]`, chunks in order.
#[cube(launch)]
pub(crate) fn sum_chunks(partials: &[f32], table: &[f32], out: &mut Sequence<Box<[f32]>>, chunk: u32) {
    let i = ABSOLUTE_POS;
    let chunk = chunk as usize;
    // Two `let`s: a tuple of mutable bindings fails CubeCL's IR verification.
    let mut start = 0usize;
    let mut partial_start = 0usize;
    #[unroll]
    for p in 0..out.len() {
        let (k_len, outputs) = (field(table, p, 0), field(table, p, 1) * field(table, p, 2));
        let chunks = max((k_len + chunk - 1) / chunk, 1);
        if i >= start && i < start + outputs {
            let o = i - start;
            let mut sum = 0.0f32;
            for c in 0..chunks {
                sum += partials[partial_start + c * outputs + o];
            }
            out.index_mut(p)[o] = sum;
        }
        start += outputs;
        partial_start += outputs * chunks;
    }
}
