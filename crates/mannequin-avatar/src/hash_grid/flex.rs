//! The op on Flex: rayon over points (forward) and over blocks of table rows (backward). Every
//! output element is written by one task and summed in a fixed order, so results are
//! bit-identical from run to run whatever the thread count.

use std::ops::{AddAssign, Mul};

use burn::backend::Flex;
use burn::backend::TensorMetadata;
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::{FloatTensor, IntTensor};
use burn::tensor::{DType, TensorData};
use rayon::prelude::*;

use super::{CORNERS, HashGridBackend};

/// Table rows per backward task: large enough to amortise the task, small enough to balance.
const ROWS_PER_TASK: usize = 4096;

/// Points per forward task.
const POINTS_PER_TASK: usize = 64;

const LAYOUT: &str = "hash-grid tensors have the dtypes `encode` checked";

trait Real: Copy + Default + Send + Sync + Mul<Output = Self> + AddAssign {}
impl<T: Copy + Default + Send + Sync + Mul<Output = T> + AddAssign> Real for T {}

fn contiguous(t: FlexTensor) -> FlexTensor {
    if t.is_contiguous() { t } else { t.to_contiguous() }
}

fn ints(t: &FlexTensor) -> &[i32] {
    t.as_slice::<i32>().expect(LAYOUT)
}

/// The lookup's entries grouped by table row (see `lookup.rs`).
#[derive(Clone, Copy)]
struct Groups<'a> {
    touched: &'a [i32],
    offsets: &'a [i32],
    sources: &'a [i32],
}

/// `out[p·F + k] = Σ_c weights[p·8 + c] · table[rows[p·8 + c]·F + k]` for every (point, level)
/// pair `p`.
fn forward<T: Real>(table: &[T], rows: &[i32], weights: &[T], slots: usize, f: usize) -> Vec<T> {
    let pairs = rows.len() / CORNERS;
    let mut out = vec![T::default(); pairs * f];
    let per_point = slots / CORNERS * f;
    out.par_chunks_mut(per_point)
        .zip(rows.par_chunks(slots).zip(weights.par_chunks(slots)))
        .with_min_len(POINTS_PER_TASK)
        .for_each(|(out, (rows, weights))| {
            for (s, (&row, &w)) in rows.iter().zip(weights).enumerate() {
                let o = &mut out[s / CORNERS * f..][..f];
                for (o, &t) in o.iter_mut().zip(&table[row as usize * f..][..f]) {
                    *o += w * t;
                }
            }
        });
    out
}

/// The table gradient: one zeroed allocation; each task owns a block of rows and fills the
/// touched ones from their entries in ascending order.
fn backward<T: Real>(grad: &[T], weights: &[T], groups: &Groups, table_rows: usize, f: usize) -> Vec<T> {
    let Groups { touched, offsets, sources } = *groups;
    let mut d = vec![T::default(); table_rows * f];
    d.par_chunks_mut(ROWS_PER_TASK * f).enumerate().for_each(|(block, d)| {
        let first = block * ROWS_PER_TASK;
        let lo = touched.partition_point(|&r| (r as usize) < first);
        let hi = touched.partition_point(|&r| (r as usize) < first + d.len() / f);
        for t in lo..hi {
            let out = &mut d[(touched[t] as usize - first) * f..][..f];
            for &s in &sources[offsets[t] as usize..offsets[t + 1] as usize] {
                let s = s as usize;
                let w = weights[s];
                for (o, &g) in out.iter_mut().zip(&grad[s / CORNERS * f..][..f]) {
                    *o += w * g;
                }
            }
        }
    });
    d
}

/// Evaluates `$body` with `$T` naming the element type of float dtype `$dtype` (f64, else f32:
/// `encode` admits no other).
macro_rules! with_float {
    ($dtype:expr, $T:ident => $body:expr) => {
        match $dtype {
            DType::F64 => {
                type $T = f64;
                $body
            }
            _ => {
                type $T = f32;
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
        _sources: IntTensor<Self>,
    ) -> FloatTensor<Self> {
        let [table, rows, weights] = [table, rows, weights].map(contiguous);
        let (n, slots, f) = (rows.shape()[0], rows.shape()[1], table.shape()[1]);
        let shape = vec![n, slots / CORNERS * f];
        let data = with_float!(table.dtype(), T => {
            let (table, weights) = (table.as_slice::<T>().expect(LAYOUT), weights.as_slice::<T>().expect(LAYOUT));
            TensorData::new(forward(table, ints(&rows), weights, slots, f), shape)
        });
        FlexTensor::from_data(data)
    }

    fn hash_grid_backward(
        grad: FloatTensor<Self>,
        weights: FloatTensor<Self>,
        touched: IntTensor<Self>,
        offsets: IntTensor<Self>,
        sources: IntTensor<Self>,
        table_rows: usize,
    ) -> FloatTensor<Self> {
        let [grad, weights, touched, offsets, sources] =
            [grad, weights, touched, offsets, sources].map(contiguous);
        let f = grad.shape()[1] * CORNERS / weights.shape()[1];
        let groups = Groups { touched: ints(&touched), offsets: ints(&offsets), sources: ints(&sources) };
        let data = with_float!(grad.dtype(), T => {
            let (grad, weights) = (grad.as_slice::<T>().expect(LAYOUT), weights.as_slice::<T>().expect(LAYOUT));
            TensorData::new(backward(grad, weights, &groups, table_rows, f), vec![table_rows, f])
        });
        FlexTensor::from_data(data)
    }
}
