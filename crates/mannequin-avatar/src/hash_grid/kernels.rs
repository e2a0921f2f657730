//! CubeCL kernels of the encoding, generic over the float type. Both are gathers: the forward
//! reads the 8 corner rows of a (level, point) cell, the backward reads the entries grouped
//! under one table row (see `lookup.rs`), so no unit writes where another does and the result
//! does not depend on scheduling.
//!
//! The backward loops over one row's entries; Mesa's lavapipe stops any shader loop after 65,535
//! iterations, so there a row must gather fewer entries than that (point sets below 8,192
//! points always do). Real GPUs have no such limit.

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// Corners per cell: pair `p`'s entries are `p·8 .. p·8 + 8`.
const CORNERS: usize = 8;

/// One unit per (level, point) pair `p`: `out[p, k] = Σ_c weights[p, c] · table[rows[p, c], k]`.
#[cube(launch)]
pub(crate) fn encode_forward<F: Float>(
    table: &[F],
    rows: &[i32],
    weights: &[F],
    out: &mut [F],
    pairs: u32,
    #[comptime] features: usize,
    #[define(F)] _dtype: ElemType,
) {
    let p = ABSOLUTE_POS;
    if p >= pairs as usize {
        terminate!();
    }
    let mut acc = Array::<F>::new(features);
    #[unroll]
    for k in 0..features {
        acc[k] = F::new(0.0);
    }
    #[unroll]
    for c in 0..CORNERS {
        let s = p * CORNERS + c;
        let w = weights[s];
        let row = usize::cast_from(rows[s]) * features;
        #[unroll]
        for k in 0..features {
            acc[k] += w * table[row + k];
        }
    }
    #[unroll]
    for k in 0..features {
        out[p * features + k] = acc[k];
    }
}

/// One unit per touched table row `t`: `d_table[row, k] = Σ_e weights[e] · grad[pairs[e], k]`
/// over the row's entries `e`, in ascending order. Rows no entry uses keep their zeros.
#[cube(launch)]
pub(crate) fn encode_backward<F: Float>(
    grad: &[F],
    touched: &[i32],
    offsets: &[i32],
    pairs: &[i32],
    weights: &[F],
    d_table: &mut [F],
    rows: u32,
    #[comptime] features: usize,
    #[define(F)] _dtype: ElemType,
) {
    let t = ABSOLUTE_POS;
    if t >= rows as usize {
        terminate!();
    }
    let mut acc = Array::<F>::new(features);
    #[unroll]
    for k in 0..features {
        acc[k] = F::new(0.0);
    }
    let start = usize::cast_from(offsets[t]);
    let end = usize::cast_from(offsets[t + 1]);
    for e in start..end {
        let w = weights[e];
        let g = usize::cast_from(pairs[e]) * features;
        #[unroll]
        for k in 0..features {
            acc[k] += w * grad[g + k];
        }
    }
    let out = usize::cast_from(touched[t]) * features;
    #[unroll]
    for k in 0..features {
        d_table[out + k] = acc[k];
    }
}
