//! The grid geometry: level resolutions, the bounding box that maps positions into the unit
//! cube, and the map from a grid corner to its row of the table (instant-ngp, Müller et al. 2022,
//! Sec. 3).

use super::HashGridError;

/// Primes of instant-ngp's spatial hash, one per axis (the first is 1 for cache coherence).
pub const HASH_PRIMES: [u32; 3] = [1, 2_654_435_761, 805_459_861];

/// Feature counts per level the kernels are compiled for (as in tiny-cuda-nn's grid encoding).
pub const FEATURES_PER_LEVEL: [usize; 4] = [1, 2, 4, 8];

/// The largest level resolution accepted: corner coordinates then stay exact in `f64` and fit
/// the hash's `u32` arithmetic with room to spare.
const MAX_RESOLUTION: u64 = 1 << 24;

/// Hyper-parameters of the encoding (instant-ngp Table 1 names: L, T, N_min, b, F).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HashGridConfig {
    /// L, the number of levels.
    pub levels: usize,
    /// log2 T: every level owns T rows of the table.
    pub log2_table_size: u32,
    /// N_min, the resolution of the coarsest level.
    pub base_resolution: u32,
    /// b, the factor between successive resolutions.
    pub growth: f64,
    /// F, the features stored per table row: 1, 2, 4 or 8.
    pub features_per_level: usize,
}

impl Default for HashGridConfig {
    /// The shape encoder of the issue: 16 levels, T = 2^17, N_min = 4, b = 1.5, F = 2.
    fn default() -> Self {
        Self { levels: 16, log2_table_size: 17, base_resolution: 4, growth: 1.5, features_per_level: 2 }
    }
}

impl HashGridConfig {
    /// T, the rows per level.
    pub fn table_size(&self) -> usize {
        1 << self.log2_table_size
    }

    /// L·T, the rows of the whole table.
    pub fn table_rows(&self) -> usize {
        self.levels * self.table_size()
    }

    /// L·F, the width of the encoding.
    pub fn output_dim(&self) -> usize {
        self.levels * self.features_per_level
    }

    /// N_l = ⌊N_min · b^l⌋, the cells per axis at level `l` (instant-ngp Eq. 2–3, as printed in
    /// the paper: corners sit at integer multiples of 1/N_l of the unit cube, with no half-cell
    /// shift). Level `l` has (N_l + 1)³ corners.
    pub fn resolution(&self, level: usize) -> u32 {
        (self.base_resolution as f64 * self.growth.powi(level as i32)).floor() as u32
    }

    /// Level `l`'s resolution and indexing rule.
    pub fn level(&self, l: usize) -> Level {
        let resolution = self.resolution(l);
        let side = resolution as u64 + 1;
        Level {
            resolution,
            dense: side * side * side <= self.table_size() as u64,
            first_row: l * self.table_size(),
            table_size: self.table_size(),
        }
    }

    /// Checks that every level can be indexed with 32-bit rows.
    pub fn validate(&self) -> Result<(), HashGridError> {
        let bad = |reason: String| Err(HashGridError::Config(reason));
        if self.levels == 0 {
            return bad("at least one level is needed".into());
        }
        if !FEATURES_PER_LEVEL.contains(&self.features_per_level) {
            return bad(format!("{} features per level; use 1, 2, 4 or 8", self.features_per_level));
        }
        if !(1..=30).contains(&self.log2_table_size) {
            return bad(format!("log2 table size {} is not in 1..=30", self.log2_table_size));
        }
        if self.levels.checked_mul(self.table_size()).is_none_or(|rows| rows > i32::MAX as usize) {
            return bad(format!(
                "{} levels of 2^{} rows overflow i32 rows",
                self.levels, self.log2_table_size
            ));
        }
        if self.base_resolution == 0 {
            return bad("the base resolution must be at least 1".into());
        }
        if !(self.growth.is_finite() && self.growth >= 1.0) {
            return bad(format!("growth {} must be finite and at least 1", self.growth));
        }
        let finest = self.base_resolution as f64 * self.growth.powi(self.levels as i32 - 1);
        if finest > MAX_RESOLUTION as f64 {
            return bad(format!("the finest resolution {finest} exceeds {MAX_RESOLUTION}"));
        }
        Ok(())
    }
}

/// One level of the grid: where its rows start and how a corner finds its row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    /// N_l, the cells per axis.
    pub resolution: u32,
    /// Whether every corner has its own row: (N_l + 1)³ ≤ T. Coarse levels do, fine levels share
    /// rows through the spatial hash.
    pub dense: bool,
    /// l·T, the level's first row of the table.
    pub first_row: usize,
    table_size: usize,
}

impl Level {
    /// The table row of corner `c` (integer grid coordinates): the level's first row plus the
    /// dense index `x + (N+1)(y + (N+1)z)`, or the hash `(x·π₁ ⊕ y·π₂ ⊕ z·π₃) mod T` in wrapping
    /// `u32` arithmetic (instant-ngp Eq. 4).
    pub fn row(&self, c: [u32; 3]) -> usize {
        let index = if self.dense {
            let side = self.resolution as usize + 1;
            c[0] as usize + side * (c[1] as usize + side * c[2] as usize)
        } else {
            spatial_hash(c) as usize & (self.table_size - 1)
        };
        self.first_row + index
    }
}

/// instant-ngp's spatial hash before the modulo: `x·π₁ ⊕ y·π₂ ⊕ z·π₃` with wrapping `u32`
/// products.
pub fn spatial_hash(c: [u32; 3]) -> u32 {
    let [p0, p1, p2] = HASH_PRIMES;
    c[0].wrapping_mul(p0) ^ c[1].wrapping_mul(p1) ^ c[2].wrapping_mul(p2)
}

/// An axis-aligned box that the encoder stretches onto the unit cube.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

impl Aabb {
    /// A box with finite corners and `min < max` on every axis.
    pub fn new(min: [f32; 3], max: [f32; 3]) -> Result<Self, HashGridError> {
        let ok = (0..3).all(|k| min[k].is_finite() && max[k].is_finite() && min[k] < max[k]);
        if !ok {
            return Err(HashGridError::Aabb(format!("{min:?} .. {max:?} is not a finite, non-empty box")));
        }
        Ok(Self { min, max })
    }

    /// The tight box of `points` grown on every side by `margin` times its largest side, so
    /// that points slightly off the template (and flat point sets) still fit.
    pub fn enclosing(points: &[[f32; 3]], margin: f32) -> Result<Self, HashGridError> {
        if !(margin.is_finite() && margin > 0.0) {
            return Err(HashGridError::Aabb(format!("margin {margin} must be positive")));
        }
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for (index, p) in points.iter().enumerate() {
            if !p.iter().all(|v| v.is_finite()) {
                return Err(HashGridError::NonFinite { index, point: *p });
            }
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let side = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f32, f32::max);
        if points.is_empty() || side == 0.0 {
            return Err(HashGridError::Aabb("the points do not span any extent".into()));
        }
        let pad = margin * side;
        Self::new(lo.map(|v| v - pad), hi.map(|v| v + pad))
    }

    /// `p` in unit-cube coordinates, or why it cannot be encoded (`index` names it).
    pub(crate) fn normalise(&self, index: usize, p: [f32; 3]) -> Result<[f64; 3], HashGridError> {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(HashGridError::NonFinite { index, point: p });
        }
        if (0..3).any(|k| p[k] < self.min[k] || p[k] > self.max[k]) {
            return Err(HashGridError::Outside { index, point: p, min: self.min, max: self.max });
        }
        Ok(std::array::from_fn(|k| {
            (p[k] as f64 - self.min[k] as f64) / (self.max[k] as f64 - self.min[k] as f64)
        }))
    }
}
