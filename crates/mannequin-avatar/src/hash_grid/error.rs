//! Errors of the hash-grid encoder, naming the offending point or argument.

use burn::tensor::DType;

#[derive(Debug, thiserror::Error)]
pub enum HashGridError {
    /// A configuration the encoder cannot index (no levels, a table too large for 32-bit rows, …).
    #[error("hash-grid config: {0}")]
    Config(String),
    /// A bounding box that is empty, inverted or not finite.
    #[error("bounding box: {0}")]
    Aabb(String),
    #[error("point {index} is not finite: {point:?}")]
    NonFinite { index: usize, point: [f32; 3] },
    #[error("point {index} {point:?} lies outside the bounding box {min:?} .. {max:?}")]
    Outside { index: usize, point: [f32; 3], min: [f32; 3], max: [f32; 3] },
    #[error("no points to encode")]
    NoPoints,
    #[error("{0} points would overflow the 32-bit lookup indices")]
    TooManyPoints(usize),
    #[error("hash table: expected shape {expected:?}, found {found:?}")]
    TableShape { expected: [usize; 2], found: [usize; 2] },
    #[error("the encoder computes in f32 or f64, not {0:?}")]
    UnsupportedDtype(DType),
    #[error("hash table: dtype {found:?} differs from the lookup's {expected:?}")]
    TableDtype { expected: DType, found: DType },
}
