//! The op on Flex: rayon over (level, point) pairs (forward) and over table rows (backward).
//! Each output row is computed by one task and summed in a fixed order, so results are
//! bit-identical from run to run whatever the thread count. The feature count is a compile-time
//! constant so each row's sums stay in registers.

use std::ops::{AddAssign, Mul};

use burn::backend::Flex;
use burn::backend::TensorMetadata;
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::{FloatTensor, IntTensor};
use burn::tensor::{DType, TensorData};
use rayon::prelude::*;

use super::{CORNERS, HashGridBackend};
use crate::host_ops::contiguous;

/// (level, point) pairs per forward task.
const PAIRS_PER_TASK: usize = 1024;

/// Table rows per backward task: large enough to amortise the task and its search of the
/// touched rows, small enough to balance the load.
const ROWS_PER_TASK: usize = 4096;

const LAYOUT: &str = "hash-grid tensors have the dtypes and shapes `encode` checked";

trait Real: Copy + Default + Send + Sync + Mul<Output = Self> + AddAssign {}
impl<T: Copy + Default + Send + Sync + Mul<Output = T> + AddAssign> Real for T {}

fn ints(t: &FlexTensor) -> &[i32] {
    t.as_slice::<i32>().expect(LAYOUT)
}

/// `out[p] = Σ_c weights[p·8 + c] · table[rows[p·8 + c]]` for every (level, point) pair `p`, in
/// order, so each thread walks through one level's table slice at a time.
fn forward<T: Real, const F: usize>(table: &[T], rows: &[i32], weights: &[T]) -> Vec<T> {
    let mut out: Vec<[T; F]> = Vec::new();
    rows.par_chunks(CORNERS)
        .zip(weights.par_chunks(CORNERS))
        .with_min_len(PAIRS_PER_TASK)
        .map(|(rows, weights)| {
            let mut acc = [T::default(); F];
            for (&row, &w) in rows.iter().zip(weights) {
                for (a, &t) in acc.iter_mut().zip(&table[row as usize * F..][..F]) {
                    *a += w * t;
                }
            }
            acc
        })
        .collect_into_vec(&mut out);
    out.into_flattened()
}

/// The lookup's entries grouped by table row (see `lookup.rs`).
struct Groups<'a, T> {
    touched: &'a [i32],
    offsets: &'a [i32],
    pairs: &'a [i32],
    weights: &'a [T],
}

impl<T: Real> Groups<'_, T> {
    /// Row `touched[t]`'s gradient: its entries' `weight · grad[pair]`, in ascending order.
    fn row_sum<const F: usize>(&self, t: usize, grad: &[T]) -> [T; F] {
        let entries = self.offsets[t] as usize..self.offsets[t + 1] as usize;
        let mut acc = [T::default(); F];
        for (&p, &w) in self.pairs[entries.clone()].iter().zip(&self.weights[entries]) {
            for (a, &g) in acc.iter_mut().zip(&grad[p as usize * F..][..F]) {
                *a += w * g;
            }
        }
        acc
    }
}

/// The `[table_rows, F]` table gradient: one zeroed allocation; each task owns a block of rows
/// and writes the touched ones.
fn backward<T: Real, const F: usize>(grad: &[T], groups: &Groups<T>, table_rows: usize) -> Vec<T> {
    let touched = groups.touched;
    let mut d = vec![[T::default(); F]; table_rows];
    d.par_chunks_mut(ROWS_PER_TASK).enumerate().for_each(|(block, d)| {
        let first = block * ROWS_PER_TASK;
        let lo = touched.partition_point(|&r| (r as usize) < first);
        let hi = touched.partition_point(|&r| (r as usize) < first + d.len());
        for t in lo..hi {
            d[touched[t] as usize - first] = groups.row_sum::<F>(t, grad);
        }
    });
    d.into_flattened()
}

/// Evaluates `$body` with `$T` naming the element type of float dtype `$dtype` (f64, else f32:
/// `encode` admits no other) and `$F` the feature count `$f` (1, 2, 4 or 8: the config admits
/// no other).
macro_rules! with_types {
    ($dtype:expr, $f:expr, $T:ident, $F:ident => $body:expr) => {
        match $dtype {
            DType::F64 => {
                type $T = f64;
                with_types!(@features $f, $F => $body)
            }
            _ => {
                type $T = f32;
                with_types!(@features $f, $F => $body)
            }
        }
    };
    (@features $f:expr, $F:ident => $body:expr) => {
        match $f {
            1 => {
                const $F: usize = 1;
                $body
            }
            2 => {
                const $F: usize = 2;
                $body
            }
            4 => {
                const $F: usize = 4;
                $body
            }
            _ => {
                const $F: usize = 8;
                $body
            }
        }
    };
}

impl HashGridBackend for Flex {
    fn hash_grid_forward(
        table: FloatTensor<Self>,
        rows: IntTensor<Self>,
        weights: FloatTensor<Self>,
        _touched: IntTensor<Self>,
        _offsets: IntTensor<Self>,
        _grouped_pairs: IntTensor<Self>,
        _grouped_weights: FloatTensor<Self>,
    ) -> FloatTensor<Self> {
        let [table, rows, weights] = [table, rows, weights].map(contiguous);
        let (pairs, f) = (rows.shape()[0], table.shape()[1]);
        let data = with_types!(table.dtype(), f, T, F => {
            let (table, weights) = (table.as_slice::<T>().expect(LAYOUT), weights.as_slice::<T>().expect(LAYOUT));
            TensorData::new(forward::<T, F>(table, ints(&rows), weights), vec![pairs, f])
        });
        FlexTensor::from_data(data)
    }

    fn hash_grid_backward(
        grad: FloatTensor<Self>,
        touched: IntTensor<Self>,
        offsets: IntTensor<Self>,
        grouped_pairs: IntTensor<Self>,
        grouped_weights: FloatTensor<Self>,
        table_rows: usize,
    ) -> FloatTensor<Self> {
        let [grad, touched, offsets, pairs, weights] =
            [grad, touched, offsets, grouped_pairs, grouped_weights].map(contiguous);
        let f = grad.shape()[1];
        let data = with_types!(grad.dtype(), f, T, F => {
            let groups = Groups {
                touched: ints(&touched),
                offsets: ints(&offsets),
                pairs: ints(&pairs),
                weights: weights.as_slice::<T>().expect(LAYOUT),
            };
            let grad = grad.as_slice::<T>().expect(LAYOUT);
            TensorData::new(backward::<T, F>(grad, &groups, table_rows), vec![table_rows, f])
        });
        FlexTensor::from_data(data)
    }
}
