//! The MLP head `I → H → H → O` (two hidden ReLU layers) as one differentiable op with a
//! hand-written backward on Flex (CPU) and CubeCL, for the widths the avatar uses. Through Burn's
//! ops each layer is a gemm plus bias, ReLU and their backward passes (some 60 launches with
//! autodiff on a GPU), and on the CPU the weight gradients (64×64 outputs over 13k rows) hardly
//! parallelise; on Flex rows go through in L1-sized tiles whose products are register-blocked,
//! and the weight gradients are summed per row chunk ([`crate::host_ops`] says where it runs);
//! on CubeCL the forward pass is one launch and the backward pass seven.

mod autodiff;
mod cube;
mod flex;
mod host;
mod kernels;

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

/// The layer widths `[I, H, O]` the op is compiled for: E_s (16 levels × 2 features) and
/// iHuman's colour encoder (16 × 4), each with 64 hidden units and 3 outputs.
pub const WIDTHS: [[usize; 3]; 2] = [[32, 64, 3], [64, 64, 3]];

/// Whether the op runs a network of `widths` (`[I, H, H, O]`).
pub fn supports(widths: &[usize]) -> bool {
    matches!(widths, [i, h, h2, o] if h == h2 && WIDTHS.contains(&[*i, *h, *o]))
}

/// Backends that run the fused MLP. Weights are `[in, out]`, biases `[1, out]`.
#[backend_extension(Flex, Cube, Autodiff)]
pub trait MlpBackend: Backend {
    /// Outputs `[N, O]` of inputs `x` `[N, I]`.
    #[allow(clippy::too_many_arguments)]
    fn mlp_forward(
        x: FloatTensor<Self>,
        w0: FloatTensor<Self>,
        b0: FloatTensor<Self>,
        w1: FloatTensor<Self>,
        b1: FloatTensor<Self>,
        w2: FloatTensor<Self>,
        b2: FloatTensor<Self>,
    ) -> FloatTensor<Self>;

    /// The gradients of `(x, w0, b0, w1, b1, w2, b2)` given the gradient `grad` `[N, O]` of the
    /// outputs.
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn mlp_backward(
        x: FloatTensor<Self>,
        w0: FloatTensor<Self>,
        b0: FloatTensor<Self>,
        w1: FloatTensor<Self>,
        b1: FloatTensor<Self>,
        w2: FloatTensor<Self>,
        b2: FloatTensor<Self>,
        grad: FloatTensor<Self>,
    ) -> (
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
    );
}

/// The network on `f32` inputs on a [`crate::host_ops::supported`] device or a CubeCL one (wgpu,
/// CUDA), for widths that [`supports`] accepts; differentiable with respect to every input.
pub fn mlp(x: Tensor<2>, weights: [Tensor<2>; 3], biases: [Tensor<2>; 3]) -> Tensor<2> {
    let [w0, w1, w2] = weights.map(|w| w.into_dispatch());
    let [b0, b1, b2] = biases.map(|b| b.into_dispatch());
    Tensor::from_dispatch(<Dispatch as MlpBackend>::mlp_forward(x.into_dispatch(), w0, b0, w1, b1, w2, b2))
}
