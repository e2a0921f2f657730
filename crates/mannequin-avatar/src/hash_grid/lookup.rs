//! The encoder's inputs are fixed canonical positions (the template's vertices), so everything
//! that depends only on them is computed once on the host: for each point, level and corner,
//! the table row and the trilinear weight; and the same entries grouped by table row, so the
//! backward pass can sum each row's gradient in a fixed order without atomics.
//!
//! Entries are stored level-major, `[L, N, 8]`: a pass over them reads one level's slice of the
//! table (T rows, 1 MiB by default) at a time, which stays in a CPU core's L2 cache, where a
//! point-major pass would jump across the whole table (16 MiB) at every point.

use burn::tensor::{DType, Device, Int, Tensor, TensorData};
use rayon::prelude::*;

use super::{Aabb, HashGridConfig, HashGridError, Level};

/// Corners of a grid cell; corner `c` is offset by one along axis `k` when bit `k` of `c` is set.
pub const CORNERS: usize = 8;

/// Rows and weights of a fixed point set, on the host.
#[derive(Clone, Debug)]
pub struct HashGridLookup {
    config: HashGridConfig,
    /// `[L, N, 8]` table rows (`l·T` + index), as `i32` so every backend can read them.
    rows: Vec<i32>,
    /// `[L, N, 8]` trilinear weights.
    weights: Vec<f64>,
    /// The table rows that some entry uses, ascending.
    touched: Vec<i32>,
    /// `touched[k]`'s entries are `offsets[k]..offsets[k + 1]` of the two arrays below.
    offsets: Vec<i32>,
    /// The (level, point) pair `l·N + i` of each entry, grouped by row; within a row in
    /// ascending entry order.
    grouped_pairs: Vec<i32>,
    /// The weight of each entry, in the same order: the backward pass then reads weights
    /// sequentially, and only the upstream gradient at random.
    grouped_weights: Vec<f64>,
}

impl HashGridLookup {
    /// Looks up every point of `points` (inside `aabb`) at every level of `config`.
    pub fn new(config: &HashGridConfig, aabb: &Aabb, points: &[[f32; 3]]) -> Result<Self, HashGridError> {
        config.validate()?;
        if points.is_empty() {
            return Err(HashGridError::NoPoints);
        }
        let n = points.len();
        if n.checked_mul(config.levels * CORNERS).is_none_or(|e| e > i32::MAX as usize) {
            return Err(HashGridError::TooManyPoints(n));
        }
        let unit: Vec<[f64; 3]> =
            points.iter().enumerate().map(|(i, &p)| aabb.normalise(i, p)).collect::<Result<_, _>>()?;
        let entries = config.levels * n * CORNERS;
        let (mut rows, mut weights) = (vec![0i32; entries], vec![0f64; entries]);
        let levels: Vec<Level> = (0..config.levels).map(|l| config.level(l)).collect();
        rows.par_chunks_mut(CORNERS).zip(weights.par_chunks_mut(CORNERS)).enumerate().for_each(
            |(pair, (rows, weights))| interpolate(&levels[pair / n], &unit[pair % n], rows, weights),
        );
        let (touched, offsets, sources) = group_by_row(&rows, config.table_rows());
        let grouped_pairs = sources.iter().map(|&s| s / CORNERS as i32).collect();
        let grouped_weights = sources.iter().map(|&s| weights[s as usize]).collect();
        Ok(Self { config: *config, rows, weights, touched, offsets, grouped_pairs, grouped_weights })
    }

    pub fn config(&self) -> &HashGridConfig {
        &self.config
    }

    pub fn num_points(&self) -> usize {
        self.rows.len() / (self.config.levels * CORNERS)
    }

    /// `[L, N, 8]` table rows: entry `(l·N + i)·8 + c` is corner `c` of point `i`'s cell at
    /// level `l`, whose bit `k` set means one step along axis `k`.
    pub fn rows(&self) -> &[i32] {
        &self.rows
    }

    /// `[L, N, 8]` trilinear weights, in the order of [`rows`](Self::rows).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Uploads the lookup to `device`, with weights in `dtype` (the table's dtype: f32 or f64).
    pub fn to_device(&self, device: &Device, dtype: DType) -> Result<DeviceLookup, HashGridError> {
        let shape = [self.rows.len() / CORNERS, CORNERS];
        let floats = |v: &[f64], shape: Vec<usize>| match dtype {
            DType::F64 => Ok(TensorData::new(v.to_vec(), shape)),
            DType::F32 => Ok(TensorData::new(v.iter().map(|&w| w as f32).collect(), shape)),
            other => Err(HashGridError::UnsupportedDtype(other)),
        };
        let ints = |v: &[i32]| {
            Tensor::<1, Int>::from_data(TensorData::new(v.to_vec(), [v.len()]), (device, DType::I32))
        };
        let entries = self.grouped_weights.len();
        Ok(DeviceLookup {
            config: self.config,
            rows: Tensor::from_data(TensorData::new(self.rows.clone(), shape), (device, DType::I32)),
            weights: Tensor::from_data(floats(&self.weights, shape.to_vec())?, (device, dtype)),
            touched: ints(&self.touched),
            offsets: ints(&self.offsets),
            grouped_pairs: ints(&self.grouped_pairs),
            grouped_weights: Tensor::from_data(
                floats(&self.grouped_weights, vec![entries])?,
                (device, dtype),
            ),
        })
    }
}

/// Rows and trilinear weights of unit-cube point `u` at `level` (instant-ngp Sec. 3: scale by
/// N_l, take the enclosing cell, weight each corner by the product of per-axis fractions). A
/// coordinate on the upper face stays in the last cell with fraction 1.
fn interpolate(level: &Level, u: &[f64; 3], rows: &mut [i32], weights: &mut [f64]) {
    let n = level.resolution as f64;
    let mut cell = [0u32; 3];
    let mut frac = [0f64; 3];
    for k in 0..3 {
        let x = u[k] * n;
        let c = x.floor().min(n - 1.0);
        cell[k] = c as u32;
        frac[k] = x - c;
    }
    for corner in 0..CORNERS {
        let mut c = cell;
        let mut w = 1.0;
        for k in 0..3 {
            if corner >> k & 1 == 1 {
                c[k] += 1;
                w *= frac[k];
            } else {
                w *= 1.0 - frac[k];
            }
        }
        rows[corner] = level.row(c) as i32;
        weights[corner] = w;
    }
}

/// Counting sort of the entries by table row: `(touched rows, offsets, entry indices)`; within a
/// row, entries keep ascending order.
fn group_by_row(rows: &[i32], table_rows: usize) -> (Vec<i32>, Vec<i32>, Vec<i32>) {
    let mut cursor = vec![0u32; table_rows];
    for &r in rows {
        cursor[r as usize] += 1;
    }
    let touched: Vec<i32> = (0..table_rows).filter(|&r| cursor[r] > 0).map(|r| r as i32).collect();
    let mut offsets = Vec::with_capacity(touched.len() + 1);
    let mut start = 0u32;
    offsets.push(0);
    for &r in &touched {
        let count = cursor[r as usize];
        cursor[r as usize] = start;
        start += count;
        offsets.push(start as i32);
    }
    let mut sources = vec![0i32; rows.len()];
    for (entry, &r) in rows.iter().enumerate() {
        let at = &mut cursor[r as usize];
        sources[*at as usize] = entry as i32;
        *at += 1;
    }
    (touched, offsets, sources)
}

/// A [`HashGridLookup`] on a device, ready for [`encode`](super::encode).
#[derive(Clone, Debug)]
pub struct DeviceLookup {
    pub(crate) config: HashGridConfig,
    pub(crate) rows: Tensor<2, Int>,
    pub(crate) weights: Tensor<2>,
    pub(crate) touched: Tensor<1, Int>,
    pub(crate) offsets: Tensor<1, Int>,
    pub(crate) grouped_pairs: Tensor<1, Int>,
    pub(crate) grouped_weights: Tensor<1>,
}

impl DeviceLookup {
    pub fn config(&self) -> &HashGridConfig {
        &self.config
    }

    pub fn num_points(&self) -> usize {
        self.rows.dims()[0] / self.config.levels
    }
}
