//! Row-wise vector algebra on `[N, 3]` tensors, for the mesh regularisers.

use burn::tensor::Tensor;

/// Floor on a length (of an edge, or of a normal), so that degenerate faces give a finite
/// gradient.
pub(super) const EPS: f64 = 1e-12;

/// Row-wise dot product of `[N, 3]` tensors, `[N, 1]`.
pub(super) fn dot(x: Tensor<2>, y: Tensor<2>) -> Tensor<2> {
    (x * y).sum_dim(1)
}

/// `sqrt(max(s, EPS²))`: a length from its square, floored at [`EPS`].
pub(super) fn length(squared: Tensor<2>) -> Tensor<2> {
    squared.clamp_min(EPS * EPS).sqrt()
}
