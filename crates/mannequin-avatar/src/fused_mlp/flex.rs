//! The op on Flex: the host passes run on the tensors' own buffers, for the compiled widths.

use burn::backend::Flex;
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::FloatTensor;
use burn::tensor::TensorData;

use super::host::{self, Weights};
use super::{MlpBackend, WIDTHS};
use crate::host_ops::contiguous;

const LAYOUT: &str = "MLP tensors are f32 (the avatar's parameters and encodings)";

fn tensor(values: Vec<f32>, shape: [usize; 2]) -> FlexTensor {
    FlexTensor::from_data(TensorData::new(values, shape))
}

/// Runs `$body` with the const widths `I, H, O` matching the runtime `[i, h, o]`.
macro_rules! with_widths {
    ($widths:expr, |$i:ident, $h:ident, $o:ident| $body:expr) => {
        match $widths {
            [32, 64, 3] => {
                const $i: usize = 32;
                const $h: usize = 64;
                const $o: usize = 3;
                $body
            }
            [64, 64, 3] => {
                const $i: usize = 64;
                const $h: usize = 64;
                const $o: usize = 3;
                $body
            }
            other => unreachable!("MLP widths {other:?} are not among {WIDTHS:?} (checked by `supports`)"),
        }
    };
}

/// The contiguous tensors and the widths `[I, H, O]`.
fn prepare(x: FlexTensor, params: [FlexTensor; 6]) -> (FlexTensor, [FlexTensor; 6], [usize; 3]) {
    let (x, params) = (contiguous(x), params.map(contiguous));
    let (w0, w2) = (params[0].layout().shape().to_vec(), params[4].layout().shape().to_vec());
    let widths = [w0[0], w0[1], w2[1]];
    (x, params, widths)
}

fn weights(p: &[FlexTensor; 6]) -> Weights<'_> {
    let s = |k: usize| p[k].as_slice::<f32>().expect(LAYOUT);
    Weights { w: [s(0), s(2), s(4)], b: [s(1), s(3), s(5)] }
}

impl MlpBackend for Flex {
    fn mlp_forward(
        x: FloatTensor<Self>,
        w0: FloatTensor<Self>,
        b0: FloatTensor<Self>,
        w1: FloatTensor<Self>,
        b1: FloatTensor<Self>,
        w2: FloatTensor<Self>,
        b2: FloatTensor<Self>,
    ) -> FloatTensor<Self> {
        let (x, p, widths) = prepare(x, [w0, b0, w1, b1, w2, b2]);
        let xs = x.as_slice::<f32>().expect(LAYOUT);
        with_widths!(widths, |I, H, O| tensor(host::forward::<I, H, O>(xs, &weights(&p)), [xs.len() / I, O]))
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
        let (x, p, widths) = prepare(x, [w0, b0, w1, b1, w2, b2]);
        let grad = contiguous(grad);
        let (xs, gs) = (x.as_slice::<f32>().expect(LAYOUT), grad.as_slice::<f32>().expect(LAYOUT));
        let [i, h, o] = widths;
        let (dx, [dw0, dw1, dw2], [db0, db1, db2]) =
            with_widths!(widths, |I, H, O| host::backward::<I, H, O>(xs, gs, &weights(&p)));
        (
            tensor(dx, [xs.len() / i, i]),
            tensor(dw0, [i, h]),
            tensor(db0, [1, h]),
            tensor(dw1, [h, h]),
            tensor(db1, [1, h]),
            tensor(dw2, [h, o]),
            tensor(db2, [1, o]),
        )
    }
}
