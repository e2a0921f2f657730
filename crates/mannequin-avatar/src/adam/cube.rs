//! The fused update on the CubeCL backends (wgpu, CUDA, …): every parameter in one kernel
//! launch (one a parameter cost ten launches an iteration), each writing three fresh buffers.
//! A launch binds seven buffers a parameter; where the device allows fewer bindings than a
//! step needs (Metal allows 31), the parameters go in as many launches as it takes.

use burn::backend::TensorMetadata;
use burn::backend::cubecl::dtype_to_elem_type;
use burn::backend::ops::FloatTensorOps;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::TensorData;
use burn_cubecl::cubecl::calculate_cube_count_elemwise;
use burn_cubecl::cubecl::prelude::{CubeDim, InputScalar, SequenceArg};
use burn_cubecl::kernel::into_contiguous;

use super::coefficients::Coefficients;
use super::kernels::adam_steps;

/// Units per cube. The cube count spreads over the grid's dimensions when one would exceed its
/// limit; the kernel reads the linear `ABSOLUTE_POS`.
const GROUP: u32 = 256;

/// Buffers a parameter binds: p, g, m, v in, p', m', v' out.
const BUFFERS: usize = 7;

/// One parameter's update: its value, gradient and moments, and its step's scalars.
pub(super) struct Update {
    pub param: CubeTensor,
    pub grad: CubeTensor,
    pub m: CubeTensor,
    pub v: CubeTensor,
    pub coefficients: Coefficients,
}

/// `(p', m', v')` of each update, in order. All updates take one step `t` (their coefficients
/// differ only in the learning rate) and share a float dtype and device.
pub(super) fn update_all(updates: Vec<Update>) -> Vec<(CubeTensor, CubeTensor, CubeTensor)> {
    let Some(first) = updates.first() else { return Vec::new() };
    let client = first.param.client.clone();
    let per_launch = (client.properties().hardware.max_bindings as usize).saturating_sub(1) / BUFFERS;
    let per_launch = per_launch.max(1);
    let mut out = Vec::with_capacity(updates.len());
    let mut updates = updates.into_iter().peekable();
    while updates.peek().is_some() {
        out.extend(launch(updates.by_ref().take(per_launch).collect()));
    }
    out
}

/// One launch over `updates`.
fn launch(updates: Vec<Update>) -> Vec<(CubeTensor, CubeTensor, CubeTensor)> {
    let first = &updates[0];
    let (dtype, device, client) =
        (first.param.dtype(), first.param.device.clone(), first.param.client.clone());
    let c = first.coefficients;
    let elem = dtype_to_elem_type(dtype);
    let scalar = |x: f64| InputScalar::new(x, elem);
    let lrs: Vec<f64> = updates.iter().map(|u| u.coefficients.lr).collect();
    let lrs =
        CubeBackend::float_from_data(TensorData::new(lrs, [updates.len()]).convert_dtype(dtype), &device);
    let n: usize = updates.iter().map(|u| u.param.shape().num_elements()).sum();
    let mut ins: [SequenceArg<_>; 4] = std::array::from_fn(|_| SequenceArg::new());
    let mut outs: [SequenceArg<_>; 3] = std::array::from_fn(|_| SequenceArg::new());
    let mut results = Vec::with_capacity(updates.len());
    for u in updates {
        let shape = u.param.shape();
        let fresh = || CubeBackend::float_empty(shape.clone(), &device, dtype.into());
        let (p, m, v) = (fresh(), fresh(), fresh());
        for (seq, t) in ins.iter_mut().zip([u.param, u.grad, u.m, u.v]) {
            seq.push(into_contiguous(t).into_buffer_arg());
        }
        for (seq, t) in outs.iter_mut().zip([&p, &m, &v]) {
            seq.push(t.clone().into_buffer_arg());
        }
        results.push((p, m, v));
    }
    let [p, g, m, v] = ins;
    let [p_out, m_out, v_out] = outs;
    adam_steps::launch(
        &client,
        calculate_cube_count_elemwise(&client, n.max(1), CubeDim::new_1d(GROUP)),
        CubeDim::new_1d(GROUP),
        p,
        g,
        m,
        v,
        p_out,
        m_out,
        v_out,
        lrs.into_buffer_arg(),
        scalar(c.beta1),
        scalar(c.one_minus_beta1),
        scalar(c.beta2),
        scalar(c.one_minus_beta2),
        scalar(c.c1),
        scalar(c.c2),
        scalar(c.epsilon),
        elem,
    );
    results
}
