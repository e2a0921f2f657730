//! Multi-resolution hash encoding (instant-ngp, Müller et al. 2022) of fixed points, as a
//! differentiable Burn op on Flex (CPU) and CubeCL (wgpu, CUDA) with a hand-written backward.
//!
//! The shape encoder E_s maps canonical vertex positions to offsets (Tavatar Eq. 4) through this
//! encoding and an MLP. The positions never change, so [`HashGridLookup`] computes each point's
//! table rows and trilinear weights once; [`encode`] is then linear in the table: a gather in
//! the forward pass and, in the backward pass, a per-row sum over the entries grouped by row,
//! which is deterministic on every backend (bit-identical gradients from run to run).
//!
//! ```
//! use burn::tensor::{DType, Device};
//! use mannequin_avatar::hash_grid::{Aabb, HashGridConfig, HashGridLookup, encode, init_table};
//! let device = Device::flex().autodiff();
//! let config = HashGridConfig::default();
//! let points = [[0.0, 0.0, 0.0], [0.1, 0.9, -0.2]];
//! let lookup = HashGridLookup::new(&config, &Aabb::enclosing(&points, 0.05).unwrap(), &points)
//!     .unwrap()
//!     .to_device(&device, DType::F32)
//!     .unwrap();
//! let table = init_table(&config, 7, &device).require_grad();
//! let features = encode(&lookup, table.clone()).unwrap(); // [2, 32]
//! let grads = features.sum().backward();
//! assert_eq!(table.grad(&grads).unwrap().dims(), [config.table_rows(), 2]);
//! ```

mod autodiff;
mod config;
mod cube;
mod error;
mod flex;
mod init;
mod kernels;
mod lookup;

use burn::backend::tensor::{FloatTensor, IntTensor};
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

pub use config::{Aabb, FEATURES_PER_LEVEL, HASH_PRIMES, HashGridConfig, Level, spatial_hash};
pub use error::HashGridError;
pub use init::{INIT_SCALE, init_table};
pub use lookup::{CORNERS, DeviceLookup, HashGridLookup};

/// Backends that can run the encoding, on a [`DeviceLookup`]'s tensors: `rows` and `weights` are
/// `[L·N, 8]` (level-major: pair `p = l·N + i` is point `i` at level `l`); `touched` lists the
/// table rows in use, and row `touched[t]`'s entries are `offsets[t]..offsets[t + 1]` of
/// `grouped_pairs` (their pairs `p`) and `grouped_weights`. [`encode`] is the checked entry point.
#[backend_extension(Flex, Cube, Autodiff)]
pub trait HashGridBackend: Backend {
    /// `[L·N, F]` features: `out[p, k] = Σ_c weights[p, c] · table[rows[p, c], k]`. The grouping
    /// tensors are not read here; they ride along so the autodiff layer can hand them to the
    /// backward pass.
    fn hash_grid_forward(
        table: FloatTensor<Self>,
        rows: IntTensor<Self>,
        weights: FloatTensor<Self>,
        touched: IntTensor<Self>,
        offsets: IntTensor<Self>,
        grouped_pairs: IntTensor<Self>,
        grouped_weights: FloatTensor<Self>,
    ) -> FloatTensor<Self>;

    /// The `[table_rows, F]` gradient of the table given the gradient `grad` `[L·N, F]` of the
    /// features: each touched row sums `weight · grad` over its entries in ascending order.
    fn hash_grid_backward(
        grad: FloatTensor<Self>,
        touched: IntTensor<Self>,
        offsets: IntTensor<Self>,
        grouped_pairs: IntTensor<Self>,
        grouped_weights: FloatTensor<Self>,
        table_rows: usize,
    ) -> FloatTensor<Self>;
}

/// The `[N, L·F]` encoding of the lookup's points (point `i`'s level `l` features at columns
/// `l·F .. (l+1)·F`), differentiable with respect to `table` (`[L·T, F]`, on the lookup's device
/// and in its dtype).
pub fn encode(lookup: &DeviceLookup, table: Tensor<2>) -> Result<Tensor<2>, HashGridError> {
    let config = &lookup.config;
    let expected = [config.table_rows(), config.features_per_level];
    if table.dims() != expected {
        return Err(HashGridError::TableShape { expected, found: table.dims() });
    }
    let (found, expected) = (table.dtype(), lookup.weights.dtype());
    if found != expected {
        return Err(HashGridError::TableDtype { expected, found });
    }
    let features = <Dispatch as HashGridBackend>::hash_grid_forward(
        table.into_dispatch(),
        lookup.rows.clone().into_dispatch(),
        lookup.weights.clone().into_dispatch(),
        lookup.touched.clone().into_dispatch(),
        lookup.offsets.clone().into_dispatch(),
        lookup.grouped_pairs.clone().into_dispatch(),
        lookup.grouped_weights.clone().into_dispatch(),
    );
    let (l, n, f) = (config.levels, lookup.num_points(), config.features_per_level);
    Ok(Tensor::<2>::from_dispatch(features).reshape([l, n, f]).swap_dims(0, 1).reshape([n, l * f]))
}
