//! The blur on the CubeCL backends: one kernel that blurs along the middle axis of
//! `[outer, len, inner]`, one unit per output value, run once along rows (`inner = 1`) and once
//! along columns. Works in f32; other float types are converted on the way in and out.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::{DType, FloatDType, TensorData};
use burn_cubecl::cubecl;
use burn_cubecl::kernel::into_contiguous;
use cubecl::prelude::*;

use super::{BlurBackend, TAPS, gaussian_window};
use crate::cube_launch::u32_of;

/// `output[o, t, j] = Σ_k weights[k] · input[o, t + k − padding, j]` over the taps whose source
/// lies inside `[0, len_in)`. The tap loop is unrolled, so no shader loop is long (kernels
/// index; they have no iterators).
#[allow(clippy::needless_range_loop, clippy::too_many_arguments)]
#[cube(launch)]
fn blur_axis(
    input: &[f32],
    weights: &[f32],
    output: &mut [f32],
    total: u32,
    len_in: u32,
    len_out: u32,
    inner: u32,
    padding: u32,
    #[comptime] taps: usize,
) {
    let i = ABSOLUTE_POS;
    if i >= total as usize {
        terminate!();
    }
    let (len_in, len_out, inner, padding) =
        (len_in as usize, len_out as usize, inner as usize, padding as usize);
    let j = i % inner;
    let t = (i / inner) % len_out;
    let o = i / (inner * len_out);
    let mut acc = 0.0f32;
    #[unroll]
    for k in 0..taps {
        let s = t + k;
        if s >= padding && s < len_in + padding {
            acc += weights[k] * input[(o * len_in + s - padding) * inner + j];
        }
    }
    output[i] = acc;
}

/// One pass along the middle axis of `x` viewed as `[outer, len_in, inner]`.
fn pass(
    x: CubeTensor,
    weights: &CubeTensor,
    [outer, len_in, inner]: [usize; 3],
    padding: usize,
) -> CubeTensor {
    let len_out = len_in + 2 * padding + 1 - TAPS;
    let total = outer * len_out * inner;
    let out = CubeBackend::float_empty([outer, len_out, inner].into(), &x.device, FloatDType::F32);
    let (client, dim) = (x.client.clone(), CubeDim::new_1d(256));
    blur_axis::launch(
        &client,
        cubecl::calculate_cube_count_elemwise(&client, total.max(1), dim),
        dim,
        x.into_buffer_arg(),
        weights.clone().into_buffer_arg(),
        out.clone().into_buffer_arg(),
        u32_of(total),
        u32_of(len_in),
        u32_of(len_out),
        u32_of(inner),
        u32_of(padding),
        TAPS,
    );
    out
}

/// The blur of a contiguous f32 `[N, H, W]` tensor with zero padding `padding`.
pub(crate) fn blur_f32(x: CubeTensor, padding: usize) -> CubeTensor {
    let [n, h, w]: [usize; 3] = x.shape().to_vec().try_into().expect("blur input is [N, H, W]");
    let g: Vec<f32> = gaussian_window().iter().map(|&v| v as f32).collect();
    let weights = CubeBackend::float_from_data(TensorData::new(g, [TAPS]), &x.device);
    let (oh, ow) = (h + 2 * padding + 1 - TAPS, w + 2 * padding + 1 - TAPS);
    let rows = pass(x, &weights, [n * h, w, 1], padding);
    let out = pass(rows, &weights, [n, h, ow], padding);
    CubeBackend::float_reshape(out, [n, oh, ow].into())
}

/// `x` as contiguous f32, and a way back to its own float type.
pub(crate) fn as_f32(x: CubeTensor) -> (CubeTensor, impl Fn(CubeTensor) -> CubeTensor) {
    let dtype = x.dtype();
    let x = if dtype == DType::F32 { x } else { CubeBackend::float_cast(x, FloatDType::F32) };
    let back = move |t| if dtype == DType::F32 { t } else { CubeBackend::float_cast(t, dtype.into()) };
    (into_contiguous(x), back)
}

impl BlurBackend for CubeBackend {
    fn gaussian_blur(x: FloatTensor<Self>, padding: usize) -> FloatTensor<Self> {
        let (x, back) = as_f32(x);
        back(blur_f32(x, padding))
    }
}
