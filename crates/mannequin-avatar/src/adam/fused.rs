//! Adam's update of one parameter as a single backend op: one pass over p, g, m and v that
//! writes p', m' and v', instead of a chain of tensor ops that each read and write a whole
//! buffer (the hash-grid table has millions of entries).

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPSILON: f64 = 1e-15;

/// Adam's scalars at step `t`, in f64. Each backend rounds each of them once to the tensors'
/// element type, as Burn's scalar ops do, so on Flex the fused update reproduces the tensor-op
/// chain it replaced bit for bit (and training runs and checkpoints do not change).
#[derive(Clone, Copy, Debug)]
pub struct Coefficients {
    pub beta1: f64,
    pub one_minus_beta1: f64,
    pub beta2: f64,
    pub one_minus_beta2: f64,
    /// Bias corrections `1 − β1^t` and `1 − β2^t`.
    pub c1: f64,
    pub c2: f64,
    pub lr: f64,
    pub epsilon: f64,
}

impl Coefficients {
    /// The scalars of step `t ≥ 1` at learning rate `lr`.
    pub fn new(t: i32, lr: f64) -> Self {
        Self {
            beta1: BETA1,
            one_minus_beta1: 1.0 - BETA1,
            beta2: BETA2,
            one_minus_beta2: 1.0 - BETA2,
            c1: 1.0 - BETA1.powi(t),
            c2: 1.0 - BETA2.powi(t),
            lr,
            epsilon: EPSILON,
        }
    }
}

/// Backends that can run the fused update on plain (non-autodiff) tensors of one shape and
/// float dtype. Optimiser state is never differentiated, so there is no autodiff layer.
#[backend_extension(Flex, Cube)]
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

/// The fused update of inner tensors `param`, `grad`, `m`, `v` (same shape, dtype and device);
/// returns `(param', m', v')`. Buffers that only their argument holds may be updated in place.
pub fn step(
    param: Tensor<2>,
    grad: Tensor<2>,
    m: Tensor<2>,
    v: Tensor<2>,
    coefficients: Coefficients,
) -> (Tensor<2>, Tensor<2>, Tensor<2>) {
    let (p, m, v) = <Dispatch as AdamBackend>::adam_step(
        param.into_dispatch(),
        grad.into_dispatch(),
        m.into_dispatch(),
        v.into_dispatch(),
        coefficients,
    );
    (Tensor::from_dispatch(p), Tensor::from_dispatch(m), Tensor::from_dispatch(v))
}
