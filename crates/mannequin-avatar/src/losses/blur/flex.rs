//! The blur op on Flex, through the host blur. Runs in f64 for f64 tensors and in f32 otherwise.

use burn::backend::Flex;
use burn::backend::flex::FlexTensor;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::tensor::{DType, FloatDType, TensorData};

use super::BlurBackend;
use super::host::{Planes, Sample, blur_rows};
use crate::host_ops::contiguous;

/// The blur of a contiguous `[n, h, w]` buffer with zero padding `p`.
fn blur<T: Sample>(x: &[T], [n, h, w]: [usize; 3], p: usize) -> TensorData {
    let s = Planes { groups: n, k: 1, h, w, p };
    let out = blur_rows(
        s,
        s.out_w(),
        |plane, y, row| row.copy_from_slice(&x[(plane * h + y) * w..][..w]),
        |_, _, blurred, out| out.copy_from_slice(blurred),
    );
    TensorData::new(out, [n, s.out_h(), s.out_w()])
}

impl BlurBackend for Flex {
    fn gaussian_blur(x: FloatTensor<Self>, padding: usize) -> FloatTensor<Self> {
        let dtype = x.dtype();
        let dims: [usize; 3] = x.layout().shape().to_vec().try_into().expect("blur input is [N, H, W]");
        let data = match dtype {
            DType::F64 => blur(contiguous(x).as_slice::<f64>().expect("f64"), dims, padding),
            DType::F32 => blur(contiguous(x).as_slice::<f32>().expect("f32"), dims, padding),
            other => {
                let y = Self::gaussian_blur(Flex::float_cast(x, FloatDType::F32), padding);
                return Flex::float_cast(y, other.into());
            }
        };
        FlexTensor::from_data(data)
    }
}
