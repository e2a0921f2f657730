//! The fused update on the CubeCL backends (wgpu, CUDA, …): one kernel launch writing three
//! fresh buffers.

use burn::backend::TensorMetadata;
use burn::backend::cubecl::dtype_to_elem_type;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::CubeBackend;
use burn_cubecl::cubecl::calculate_cube_count_elemwise;
use burn_cubecl::cubecl::prelude::{CubeDim, InputScalar};
use burn_cubecl::kernel::into_contiguous;

use super::fused::{AdamBackend, Coefficients};
use super::kernels::adam_step;

/// Units per cube. The cube count spreads over the grid's dimensions when one would exceed its
/// limit; the kernel reads the linear `ABSOLUTE_POS`.
const GROUP: u32 = 256;

impl AdamBackend for CubeBackend {
    fn adam_step(
        param: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        m: FloatTensor<Self>,
        v: FloatTensor<Self>,
        c: Coefficients,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let (shape, dtype, device) = (param.shape(), param.dtype(), param.device.clone());
        let n = shape.num_elements();
        let client = param.client.clone();
        let out = || Self::float_empty(shape.clone(), &device, dtype.into());
        let (p_out, m_out, v_out) = (out(), out(), out());
        let elem = dtype_to_elem_type(dtype);
        let scalar = |x: f64| InputScalar::new(x, elem);
        adam_step::launch(
            &client,
            calculate_cube_count_elemwise(&client, n, CubeDim::new_1d(GROUP)),
            CubeDim::new_1d(GROUP),
            into_contiguous(param).into_buffer_arg(),
            into_contiguous(grad).into_buffer_arg(),
            into_contiguous(m).into_buffer_arg(),
            into_contiguous(v).into_buffer_arg(),
            p_out.clone().into_buffer_arg(),
            m_out.clone().into_buffer_arg(),
            v_out.clone().into_buffer_arg(),
            scalar(c.beta1),
            scalar(c.one_minus_beta1),
            scalar(c.beta2),
            scalar(c.one_minus_beta2),
            scalar(c.c1),
            scalar(c.c2),
            scalar(c.lr),
            scalar(c.epsilon),
            elem,
        );
        (p_out, m_out, v_out)
    }
}
