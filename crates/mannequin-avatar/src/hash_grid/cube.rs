//! The op on the CubeCL backends (wgpu, CUDA, …): one kernel launch each way, nothing read back.

use burn::backend::TensorMetadata;
use burn::backend::cubecl::dtype_to_elem_type;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::{FloatTensor, IntTensor};
use burn::backend::wgpu::CubeBackend;
use burn_cubecl::cubecl::calculate_cube_count_elemwise;
use burn_cubecl::cubecl::prelude::CubeDim;
use burn_cubecl::kernel::into_contiguous;

use super::HashGridBackend;
use super::kernels::{encode_backward, encode_forward};

/// Units per cube. The cube count spreads over the grid's dimensions when one would exceed its
/// limit; the kernels read the linear `ABSOLUTE_POS`.
const GROUP: u32 = 256;

fn u32_of(v: usize) -> u32 {
    u32::try_from(v).expect("hash-grid sizes were checked to fit i32")
}

impl HashGridBackend for CubeBackend {
    fn hash_grid_forward(
        table: FloatTensor<Self>,
        rows: IntTensor<Self>,
        weights: FloatTensor<Self>,
        _touched: IntTensor<Self>,
        _offsets: IntTensor<Self>,
        _grouped_pairs: IntTensor<Self>,
        _grouped_weights: FloatTensor<Self>,
    ) -> FloatTensor<Self> {
        let (pairs, f) = (rows.shape()[0], table.shape()[1]);
        let dtype = table.dtype();
        let out = Self::float_empty([pairs, f].into(), &table.device, dtype.into());
        encode_forward::launch(
            &table.client.clone(),
            calculate_cube_count_elemwise(&table.client, pairs, CubeDim::new_1d(GROUP)),
            CubeDim::new_1d(GROUP),
            into_contiguous(table).into_buffer_arg(),
            into_contiguous(rows).into_buffer_arg(),
            into_contiguous(weights).into_buffer_arg(),
            out.clone().into_buffer_arg(),
            u32_of(pairs),
            f,
            dtype_to_elem_type(dtype),
        );
        out
    }

    fn hash_grid_backward(
        grad: FloatTensor<Self>,
        touched: IntTensor<Self>,
        offsets: IntTensor<Self>,
        grouped_pairs: IntTensor<Self>,
        grouped_weights: FloatTensor<Self>,
        table_rows: usize,
    ) -> FloatTensor<Self> {
        let f = grad.shape()[1];
        let dtype = grad.dtype();
        let d_table = Self::float_zeros([table_rows, f].into(), &grad.device, dtype.into());
        let rows = touched.shape()[0];
        encode_backward::launch(
            &grad.client.clone(),
            calculate_cube_count_elemwise(&grad.client, rows, CubeDim::new_1d(GROUP)),
            CubeDim::new_1d(GROUP),
            into_contiguous(grad).into_buffer_arg(),
            into_contiguous(touched).into_buffer_arg(),
            into_contiguous(offsets).into_buffer_arg(),
            into_contiguous(grouped_pairs).into_buffer_arg(),
            into_contiguous(grouped_weights).into_buffer_arg(),
            d_table.clone().into_buffer_arg(),
            u32_of(rows),
            f,
            dtype_to_elem_type(dtype),
        );
        d_table
    }
}
