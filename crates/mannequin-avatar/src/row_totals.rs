//! Totals of consecutive rows of one f32 buffer in one kernel launch on the CubeCL backends: a
//! loss's per-element shares summed into `[1]` tensors. Burn's sum takes two launches a total
//! (a fill and an atomic reduction); here one cube of `UNITS` units sums every row: each unit
//! adds every `UNITS`-th share, then unit 0 adds the units' sums, in order.

use burn::backend::wgpu::CubeTensor;
use burn_cubecl::cubecl;
use cubecl::prelude::*;

use crate::cube_launch::{empty_f32, u32_of};

/// Units of the cube.
const UNITS: u32 = 256;

/// The longest row: each unit walks `len / UNITS` shares, and lavapipe stops loops after 65,535
/// iterations.
pub(crate) const MAX_LEN: usize = UNITS as usize * 65_535;

/// `totals_r[0] = Σ values[r·len .. (r + 1)·len]` for each of the `rows` totals.
#[cube(launch)]
fn row_totals_kernel(values: &[f32], totals: &mut Sequence<Box<[f32]>>, len: u32, #[comptime] rows: usize) {
    let u = UNIT_POS_X;
    let mut parts = Shared::<[f32]>::new_slice(rows * UNITS as usize);
    #[unroll]
    for r in 0..rows {
        let base = r as u32 * len;
        let mut sum = 0.0f32;
        let mut k = u;
        while k < len {
            sum += values[(base + k) as usize];
            k += UNITS;
        }
        parts[r * UNITS as usize + u as usize] = sum;
    }
    sync_cube();
    if u == 0 {
        #[unroll]
        for r in 0..rows {
            let mut total = 0.0f32;
            for p in 0..UNITS {
                total += parts[r * UNITS as usize + p as usize];
            }
            totals.index_mut(r)[0] = total;
        }
    }
}

/// The totals `[1]` of the `rows` consecutive rows of `len` values (`len ≤ MAX_LEN`) that
/// start `values`, a contiguous f32 buffer.
pub(crate) fn row_totals(values: &CubeTensor, len: usize, rows: usize) -> Vec<CubeTensor> {
    assert!(len <= MAX_LEN, "a row of {len} values is past the one-cube sum's {MAX_LEN}");
    let totals: Vec<CubeTensor> = (0..rows).map(|_| empty_f32(vec![1], values)).collect();
    let mut args = SequenceArg::new();
    for t in &totals {
        args.push(t.clone().into_buffer_arg());
    }
    row_totals_kernel::launch(
        &values.client,
        CubeCount::Static(1, 1, 1),
        CubeDim::new_1d(UNITS),
        values.clone().into_buffer_arg(),
        args,
        u32_of(len),
        rows,
    );
    totals
}
