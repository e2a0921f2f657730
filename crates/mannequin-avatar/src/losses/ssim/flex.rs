//! The fused SSIM on Flex, through the host blur. Forward: the five moments blurred straight
//! from the images (the products are formed row by row inside the blur) and saved interleaved
//! per row, `[C, H − 10, 5, W − 10]`; then the map. Backward, for `x` (and for `y` with the
//! roles swapped): per pixel, the map's gradient times ∂S/∂E[x²], ∂S/∂E[xy] and ∂S/∂μx, formed
//! row by row inside the transposed blur (padding 10); then, by the product rule,
//! `dx = Gᵀ(∂S/∂μx) + 2x·Gᵀ(∂S/∂E[x²]) + y·Gᵀ(∂S/∂E[xy])`, row by row as the blur finishes.

use burn::backend::Flex;
use burn::backend::flex::FlexTensor;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::tensor::{DType, FloatDType, TensorData};
use rayon::prelude::*;

use super::{C1, C2, SsimBackend};
use crate::losses::blur::{Planes, Sample, TAPS, blur_rows};

/// SSIM's factors at one pixel, `S = a1·a2 / (b1·b2)`, from its moments `[μx, μy, E[x²],
/// E[y²], E[xy]]`. Grouped so that identical images give `a1 = b1` and `a2 = b2` exactly,
/// hence S = 1 exactly; symmetric in x and y.
struct Terms<T> {
    a1: T,
    a2: T,
    b1: T,
    b2: T,
}

impl<T: Sample> Terms<T> {
    fn new([mx, my, exx, eyy, exy]: [T; 5]) -> Self {
        let two = T::of(2.0);
        let (mx2, my2, mxy) = (mx * mx, my * my, mx * my);
        Terms {
            a1: two * mxy + T::of(C1),
            a2: two * (exy - mxy) + T::of(C2),
            b1: (mx2 + my2) + T::of(C1),
            b2: (exx - mx2) + (eyy - my2) + T::of(C2),
        }
    }

    fn ssim(&self) -> T {
        self.a1 * self.a2 / (self.b1 * self.b2)
    }
}

/// The map `[C, oh, ow]` and the moments `[C, oh, 5, ow]`.
fn forward<T: Sample>(x: &[T], y: &[T], [c, h, w]: [usize; 3]) -> (Vec<T>, Vec<T>) {
    let s = Planes { groups: c, k: 5, h, w, p: 0 };
    let ow = s.out_w();
    let moments = blur_rows(
        s,
        5 * ow,
        |ch, row, src| {
            let start = (ch * h + row) * w;
            let (xs, ys) = (&x[start..start + w], &y[start..start + w]);
            let (mx, rest) = src.split_at_mut(w);
            let (my, rest) = rest.split_at_mut(w);
            let (exx, rest) = rest.split_at_mut(w);
            let (eyy, exy) = rest.split_at_mut(w);
            for i in 0..w {
                let (u, v) = (xs[i], ys[i]);
                (mx[i], my[i], exx[i], eyy[i], exy[i]) = (u, v, u * u, v * v, u * v);
            }
        },
        |_, _, blurred, out| out.copy_from_slice(blurred),
    );
    let mut map = vec![T::default(); c * s.out_h() * ow];
    map.par_chunks_mut(ow).zip(moments.par_chunks(5 * ow)).for_each(|(out, m)| {
        let m: [&[T]; 5] = std::array::from_fn(|k| &m[k * ow..(k + 1) * ow]);
        for (i, o) in out.iter_mut().enumerate() {
            *o = Terms::new([m[0][i], m[1][i], m[2][i], m[3][i], m[4][i]]).ssim();
        }
    });
    (map, moments)
}

/// The gradient with respect to `own` (x, or y with `swap`), `[C, H, W]`.
fn gradient<T: Sample>(
    own: &[T],
    other: &[T],
    moments: &[T],
    grad: &[T],
    [c, h, w]: [usize; 3],
    swap: bool,
) -> Vec<T> {
    let s = Planes { groups: c, k: 3, h: h + 1 - TAPS, w: w + 1 - TAPS, p: TAPS - 1 };
    let (oh, ow) = (s.h, s.w);
    // Moment rows as seen from `own`: its mean, the other's, its E[·²], the other's, E[xy].
    let order = if swap { [1, 0, 3, 2, 4] } else { [0, 1, 2, 3, 4] };
    let two = T::of(2.0);
    blur_rows(
        s,
        w,
        |ch, row, src| {
            let m = &moments[(ch * oh + row) * 5 * ow..][..5 * ow];
            let m: [&[T]; 5] = order.map(|k| &m[k * ow..(k + 1) * ow]);
            let g = &grad[(ch * oh + row) * ow..][..ow];
            let (d_own2, rest) = src.split_at_mut(ow);
            let (d_cross, d_mean) = rest.split_at_mut(ow);
            for i in 0..ow {
                let v = [m[0][i], m[1][i], m[2][i], m[3][i], m[4][i]];
                let t = Terms::new(v);
                let d = t.b1 * t.b2;
                let s = t.a1 * t.a2 / d;
                // With S = a1·a2/(b1·b2): ∂S/∂E[x²] = −S/b2, ∂S/∂E[xy] = 2·a1/(b1·b2), and
                // ∂S/∂μx = 2μy·(a2 − a1)/(b1·b2) + 2μx·S·(1/b2 − 1/b1).
                d_own2[i] = g[i] * (T::default() - s / t.b2);
                d_cross[i] = g[i] * two * t.a1 / d;
                d_mean[i] = g[i] * two * (v[1] * (t.a2 - t.a1) / d + v[0] * (s / t.b2 - s / t.b1));
            }
        },
        |ch, row, t, out| {
            let start = (ch * h + row) * w;
            let (own, other) = (&own[start..start + w], &other[start..start + w]);
            for i in 0..w {
                out[i] = t[2 * w + i] + two * own[i] * t[i] + other[i] * t[w + i];
            }
        },
    )
}

fn dims(t: &FlexTensor) -> [usize; 3] {
    t.layout().shape().to_vec().try_into().expect("SSIM inputs are [C, H, W]")
}

/// Contiguous, and in f64 or f32 (other float types are converted to f32).
fn prepared(t: FlexTensor) -> FlexTensor {
    let t = match t.dtype() {
        DType::F64 | DType::F32 => t,
        _ => Flex::float_cast(t, FloatDType::F32),
    };
    if t.is_contiguous() { t } else { t.to_contiguous() }
}

/// `t` in the float type `dtype` of the op's inputs.
fn back_to(t: FlexTensor, dtype: DType) -> FlexTensor {
    if t.dtype() == dtype { t } else { Flex::float_cast(t, dtype.into()) }
}

/// Binds each named tensor to its f64 or f32 slice and evaluates `body` (generic code needs a
/// concrete element type to read a Flex buffer).
macro_rules! with_slices {
    ($dtype:expr, [$($t:ident),*], $body:expr) => {
        match $dtype {
            DType::F64 => { $(let $t = $t.as_slice::<f64>().expect("f64");)* $body }
            _ => { $(let $t = $t.as_slice::<f32>().expect("f32");)* $body }
        }
    };
}

impl SsimBackend for Flex {
    fn ssim_forward(x: FloatTensor<Self>, y: FloatTensor<Self>) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let dtype = x.dtype();
        let [c, h, w] = dims(&x);
        let (oh, ow) = (h + 1 - TAPS, w + 1 - TAPS);
        let (x, y) = (prepared(x), prepared(y));
        let (map, moments) = with_slices!(dtype, [x, y], {
            let (map, moments) = forward(x, y, [c, h, w]);
            (TensorData::new(map, [c, oh, ow]), TensorData::new(moments, [c, oh, 5, ow]))
        });
        (back_to(FlexTensor::from_data(map), dtype), FlexTensor::from_data(moments))
    }

    fn ssim_backward(
        x: FloatTensor<Self>,
        y: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        want_x: bool,
        want_y: bool,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let dtype = x.dtype();
        let shape = dims(&x);
        let [x, y, moments, grad] = [x, y, moments, grad].map(prepared);
        let [dx, dy] = with_slices!(dtype, [x, y, moments, grad], {
            [(want_x, x, y, false), (want_y, y, x, true)].map(|(want, own, other, swap)| match want {
                true => TensorData::new(gradient(own, other, moments, grad, shape, swap), shape),
                false => TensorData::new(Vec::<f32>::new(), [0]),
            })
        });
        (back_to(FlexTensor::from_data(dx), dtype), back_to(FlexTensor::from_data(dy), dtype))
    }
}
