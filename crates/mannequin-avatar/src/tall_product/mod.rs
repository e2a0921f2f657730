//! `aᵀ·b` for a long shared dimension and a small output on the CubeCL backends: the weight and
//! bias gradients of the MLP head (13k rows into 64×64) and the skinning's transform gradients
//! (13k vertices into 25×12). A general matrix product parallelises over outputs, so there it
//! walks all rows in a few units; on an H200 five such products took 17 ms of a 32 ms step. Here
//! the rows are split in chunks, each (chunk, output) one unit, and the chunks summed after; all
//! the products of one backward pass go in together: two launches, however many products (the
//! MLP's six took twelve one by one). `tests/fused_mlp.rs` and `tests/fused_skinning.rs` hold
//! it to the Flex twins.

mod kernels;

use burn::backend::ops::FloatTensorOps;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::{FloatDType, TensorData};
use burn_cubecl::cubecl::prelude::SequenceArg;

use crate::cube_launch::{per_element, u32_of};
use kernels::{FIELDS, chunk_products, sum_chunks};

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

/// One product `aᵀ·b` `[M, N]` of contiguous f32 `b` `[K, N]` (M = 1 for [`Left::Ones`]).
pub(crate) struct Product {
    pub a: Left,
    pub b: CubeTensor,
    pub k: usize,
    pub n: usize,
}

/// The products, in order, in two launches.
pub(crate) fn tall_products(products: Vec<Product>) -> Vec<CubeTensor> {
    let Some(first) = products.first() else { return Vec::new() };
    let like = first.b.clone();
    let empty = |shape: Vec<usize>| CubeBackend::float_empty(shape.into(), &like.device, FloatDType::F32);
    let (mut lefts, mut rights, mut outs) = (SequenceArg::new(), SequenceArg::new(), SequenceArg::new());
    let (mut table, mut results) = (Vec::new(), Vec::new());
    let (mut partial_units, mut output_units) = (0, 0);
    for Product { a, b, k, n } in products {
        let (ones, a, m, stride_k, stride_m) = match a {
            Left::Strided { a, columns, stride_k, stride_m } => (false, a, columns, stride_k, stride_m),
            // An unread buffer stands in for the ones.
            Left::Ones => (true, b.clone(), 1, 0, 0),
        };
        let out = empty(vec![m, n]);
        partial_units += k.div_ceil(CHUNK).max(1) * m * n;
        output_units += m * n;
        table.extend([k, m, n, stride_k, stride_m, usize::from(ones)].map(|v| f32::from_bits(u32_of(v))));
        lefts.push(a.into_buffer_arg());
        rights.push(b.into_buffer_arg());
        outs.push(out.clone().into_buffer_arg());
        results.push(out);
    }
    debug_assert_eq!(table.len(), FIELDS * results.len());
    let n_table = table.len();
    let table = CubeBackend::float_from_data(TensorData::new(table, [n_table]), &like.device);
    let partials = empty(vec![partial_units]);
    let (count, dim) = per_element(&like, partial_units);
    chunk_products::launch(
        &like.client,
        count,
        dim,
        lefts,
        rights,
        table.clone().into_buffer_arg(),
        partials.clone().into_buffer_arg(),
        u32_of(CHUNK),
    );
    let (count, dim) = per_element(&like, output_units);
    sum_chunks::launch(
        &like.client,
        count,
        dim,
        partials.into_buffer_arg(),
        table.into_buffer_arg(),
        outs,
        u32_of(CHUNK),
    );
    results
}
