//! Adam's update as fused backend ops: one pass over p, g, m and v that writes p', m' and v',
//! instead of a chain of tensor ops that each read and write a whole buffer (the hash-grid table
//! has millions of entries). On Flex each parameter's update is one op; on a CubeCL device all
//! of them are one kernel launch (`cube.rs`).

use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::CubeTensor;
use burn::backend::{
    Backend, BackendTensor, Dispatch, DispatchAutodiffContext, DispatchTensor, DispatchTensorKind,
    backend_extension,
};
use burn::tensor::Tensor;

use super::coefficients::Coefficients;
use super::cube;
use crate::host_ops;

/// Backends that can run the fused update of one parameter on plain (non-autodiff) tensors of
/// one shape and float dtype. Optimiser state is never differentiated, so there is no autodiff
/// layer. CubeCL devices update every parameter at once instead ([`steps`]).
#[backend_extension(Flex)]
pub trait AdamBackend: Backend {
    /// `(p', m', v')` with, elementwise and in this order of rounding,
    /// `m' = m·β1 + g·(1 − β1)`, `v' = v·β2 + (g·g)·(1 − β2)` and
    /// `p' = p − ((m'/c1) / (sqrt(v'/c2) + ε))·lr`.
    fn adam_step(
        param: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        m: FloatTensor<Self>,
        v: FloatTensor<Self>,
        coefficients: Coefficients,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>);
}

/// One parameter's update: inner tensors `param`, `grad`, `m`, `v` of one shape, dtype and
/// device, and the step's scalars.
pub struct Update {
    pub param: Tensor<2>,
    pub grad: Tensor<2>,
    pub m: Tensor<2>,
    pub v: Tensor<2>,
    pub coefficients: Coefficients,
}

/// `(param', m', v')` of each update, in order; all take one step `t` on one device. Buffers
/// that only their argument holds may be updated in place.
pub fn steps(updates: Vec<Update>) -> Vec<(Tensor<2>, Tensor<2>, Tensor<2>)> {
    let on_cube = updates.first().is_some_and(|u| host_ops::on_cube(&u.param.device()));
    if on_cube {
        let updates = updates
            .into_iter()
            .map(|u| cube::Update {
                param: into_cube(u.param),
                grad: into_cube(u.grad),
                m: into_cube(u.m),
                v: into_cube(u.v),
                coefficients: u.coefficients,
            })
            .collect();
        return cube::update_all(updates)
            .into_iter()
            .map(|(p, m, v)| (from_cube(p), from_cube(m), from_cube(v)))
            .collect();
    }
    updates
        .into_iter()
        .map(|u| {
            let (p, m, v) = <Dispatch as AdamBackend>::adam_step(
                u.param.into_dispatch(),
                u.grad.into_dispatch(),
                u.m.into_dispatch(),
                u.v.into_dispatch(),
                u.coefficients,
            );
            (Tensor::from_dispatch(p), Tensor::from_dispatch(m), Tensor::from_dispatch(v))
        })
        .collect()
}

/// The CubeCL tensor of an inner tensor on a CubeCL device.
fn into_cube(t: Tensor<2>) -> CubeTensor {
    match t.into_dispatch().kind {
        DispatchTensorKind::Cube(t) => t.float(),
        other => unreachable!("the caller checked the device, not {other:?}"),
    }
}

fn from_cube(t: CubeTensor) -> Tensor<2> {
    Tensor::from_dispatch(DispatchTensor {
        kind: DispatchTensorKind::Cube(BackendTensor::Float(t)),
        autodiff: DispatchAutodiffContext::Disabled,
    })
}
