//! The MLP on the CubeCL backends. The forward pass is one launch. The backward pass is one
//! per-row launch (recomputing the activations, as on Flex) and then, per layer, the weight
//! gradient as a product of the transposed activations by the layer's gradients and the bias
//! gradient as a sum over rows, all six products in two launches ([`crate::tall_product`]):
//! three launches, gathers only, nothing read back. Works in f32; other float types are
//! converted on the way in and out.

use burn::backend::TensorMetadata;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};

use super::MlpBackend;
use super::kernels::{mlp_backward_rows, mlp_forward};
use crate::cube_launch::{empty_f32, per_element, u32_of};
use crate::losses::blur::as_f32;
use crate::tall_product::{Left, Product, tall_products};

/// The rows `N` and widths `[I, H, O]` of `x` `[N, I]`, `w0` `[I, H]` and `w2` `[H, O]`.
fn sizes(x: &CubeTensor, w0: &CubeTensor, w2: &CubeTensor) -> (usize, [usize; 3]) {
    let (x, w0, w2) = (x.shape(), w0.shape(), w2.shape());
    (x[0], [x[1], w0[1], w2[1]])
}

impl MlpBackend for CubeBackend {
    fn mlp_forward(
        x: FloatTensor<Self>,
        w0: FloatTensor<Self>,
        b0: FloatTensor<Self>,
        w1: FloatTensor<Self>,
        b1: FloatTensor<Self>,
        w2: FloatTensor<Self>,
        b2: FloatTensor<Self>,
    ) -> FloatTensor<Self> {
        let (n, [i, h, o]) = sizes(&x, &w0, &w2);
        let (x, back) = as_f32(x);
        let [w0, b0, w1, b1, w2, b2] = [w0, b0, w1, b1, w2, b2].map(|t| as_f32(t).0);
        let out = empty_f32(vec![n, o], &x);
        let (h1t, h2t) = (empty_f32(vec![h, n], &x), empty_f32(vec![h, n], &x));
        let (count, dim) = per_element(&x, n);
        mlp_forward::launch(
            &x.client,
            count,
            dim,
            x.clone().into_buffer_arg(),
            w0.into_buffer_arg(),
            b0.into_buffer_arg(),
            w1.into_buffer_arg(),
            b1.into_buffer_arg(),
            w2.into_buffer_arg(),
            b2.into_buffer_arg(),
            h1t.into_buffer_arg(),
            h2t.into_buffer_arg(),
            out.clone().into_buffer_arg(),
            u32_of(n),
            i,
            h,
            o,
        );
        back(out)
    }

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
    ) {
        let (n, [i, h, o]) = sizes(&x, &w0, &w2);
        let (x, back) = as_f32(x);
        let (grad, _) = as_f32(grad);
        let [w0, b0, w1, b1, w2, _] = [w0, b0, w1, b1, w2, b2].map(|t| as_f32(t).0);
        let dx = empty_f32(vec![n, i], &x);
        let (g0, g1) = (empty_f32(vec![n, h], &x), empty_f32(vec![n, h], &x));
        let (h1t, h2t) = (empty_f32(vec![h, n], &x), empty_f32(vec![h, n], &x));
        let (count, dim) = per_element(&x, n);
        mlp_backward_rows::launch(
            &x.client,
            count,
            dim,
            x.clone().into_buffer_arg(),
            w0.into_buffer_arg(),
            b0.into_buffer_arg(),
            w1.into_buffer_arg(),
            b1.into_buffer_arg(),
            w2.into_buffer_arg(),
            grad.clone().into_buffer_arg(),
            dx.clone().into_buffer_arg(),
            g0.clone().into_buffer_arg(),
            g1.clone().into_buffer_arg(),
            h1t.clone().into_buffer_arg(),
            h2t.clone().into_buffer_arg(),
            u32_of(n),
            i,
            h,
            o,
        );
        // Layer `l`'s weight gradient is (its input)ᵀ·(its gradient), its bias gradient the sum
        // of its gradient over rows: products over the N rows into small outputs, all six in
        // two launches.
        let product = |a: Left, b: &CubeTensor, width: usize| Product { a, b: b.clone(), k: n, n: width };
        let sums = tall_products(vec![
            product(Left::Strided { a: x, columns: i, stride_k: i, stride_m: 1 }, &g0, h),
            product(Left::Ones, &g0, h),
            product(Left::Strided { a: h1t, columns: h, stride_k: 1, stride_m: n }, &g1, h),
            product(Left::Ones, &g1, h),
            product(Left::Strided { a: h2t, columns: h, stride_k: 1, stride_m: n }, &grad, o),
            product(Left::Ones, &grad, o),
        ]);
        let Ok([dw0, db0, dw1, db1, dw2, db2]) = <[CubeTensor; 6]>::try_from(sums) else {
            unreachable!("six products give six sums")
        };
        let [dw0, db0, dw1, db1, dw2, db2] = [dw0, db0, dw1, db1, dw2, db2].map(&back);
        (back(dx), dw0, db0, dw1, db1, dw2, db2)
    }
}
