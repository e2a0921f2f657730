//! `aᵀ·b` for a long shared dimension and a small output on the CubeCL backends: the weight and
//! bias gradients of the MLP head (13k rows into 64×64) and the skinning's transform gradients
//! (13k vertices into 25×12). A general matrix product parallelises over outputs, so there it
//! walks all rows in a few units; on an H200 five such products took 17 ms of a 32 ms step. Here
//! the rows are split in chunks, each (chunk, output) one unit, and the chunks summed after:
//! two launches. `tests/fused_mlp.rs` and `tests/fused_skinning.rs` hold it to the Flex twins.

mod kernels;

use burn::backend::ops::FloatTensorOps;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::FloatDType;

use crate::cube_launch::{per_element, u32_of};
use kernels::{chunk_products, sum_chunks};

/// Rows one unit sums.
const CHUNK: usize = 256;

/// The left factor of a product, read as `a[k·stride_k + m·stride_m]` for row `k`, column `m`
/// of the `[K, M]` matrix whose transpose multiplies (so a transposed view costs no copy).
// Built for one call and moved into it: its size never sits in a collection.
#[allow(clippy::large_enum_variant)]
pub(crate) enum Left {
    Strided {
        a: CubeTensor,
        columns: usize,
        stride_k: usize,
        stride_m: usize,
    },
    /// A column of ones: the product is `b`'s column sums.
    Ones,
}

/// `aᵀ·b` `[M, N]` of contiguous f32 `b` `[K, N]` (M = 1 for [`Left::Ones`]).
pub(crate) fn tall_product(a: Left, b: &CubeTensor, k: usize, n: usize) -> CubeTensor {
    let (ones, a, m, stride_k, stride_m) = match a {
        Left::Strided { a, columns, stride_k, stride_m } => (false, a, columns, stride_k, stride_m),
        // An unread one-element buffer stands in for the ones.
        Left::Ones => (true, b.clone(), 1, 0, 0),
    };
    let (outputs, chunks) = (m * n, k.div_ceil(CHUNK).max(1));
    let empty = |shape: Vec<usize>| CubeBackend::float_empty(shape.into(), &b.device, FloatDType::F32);
    let (partials, out) = (empty(vec![chunks * outputs]), empty(vec![m, n]));
    let (count, dim) = per_element(b, chunks * outputs);
    chunk_products::launch(
        &b.client,
        count,
        dim,
        a.into_buffer_arg(),
        b.clone().into_buffer_arg(),
        partials.clone().into_buffer_arg(),
        u32_of(k),
        u32_of(m),
        u32_of(n),
        u32_of(stride_k),
        u32_of(stride_m),
        u32_of(CHUNK),
        ones,
    );
    let (count, dim) = per_element(b, outputs);
    sum_chunks::launch(
        &b.client,
        count,
        dim,
        partials.into_buffer_arg(),
        out.clone().into_buffer_arg(),
        u32_of(chunks),
        u32_of(outputs),
    );
    out
}
