//! The fused update on Flex: rayon over blocks of elements, one pass over p, g, m and v. A
//! tensor that is the sole owner of its whole buffer is updated in place; any other is copied
//! block by block into a fresh output, where the update then finishes while the block is still
//! in cache. Either way each element is read and written once from memory.

use std::ops::{Add, Div, Mul, Sub};

use burn::backend::Flex;
use burn::backend::TensorMetadata;
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::FloatTensor;
use burn::tensor::DType;
use rayon::prelude::*;

use super::coefficients::Coefficients;
use super::fused::AdamBackend;

/// Elements per task: four blocks of this many f32 stay in L2 between the copy and the update.
const BLOCK: usize = 8192;

const LAYOUT: &str = "Adam's tensors share the parameter's shape and float dtype";

trait Real:
    Copy + Send + Sync + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// Rounds a host scalar as Burn's Flex scalar ops do (`as`).
    fn of(x: f64) -> Self;
    fn sqrt(self) -> Self;
    fn slice(t: &FlexTensor) -> Option<&[Self]>;
    /// The whole buffer, if `t` is its only owner.
    fn whole_mut(t: &mut FlexTensor) -> Option<&mut [Self]>;
}

macro_rules! real {
    ($t:ty) => {
        impl Real for $t {
            fn of(x: f64) -> Self {
                x as $t
            }
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            fn slice(t: &FlexTensor) -> Option<&[Self]> {
                t.as_slice()
            }
            fn whole_mut(t: &mut FlexTensor) -> Option<&mut [Self]> {
                t.try_storage_mut()
            }
        }
    };
}

real!(f32);
real!(f64);

/// Coefficients rounded once to the element type.
#[derive(Clone, Copy)]
struct Scalars<T> {
    beta1: T,
    one_minus_beta1: T,
    beta2: T,
    one_minus_beta2: T,
    c1: T,
    c2: T,
    lr: T,
    epsilon: T,
}

impl<T: Real> Scalars<T> {
    fn new(c: &Coefficients) -> Self {
        Self {
            beta1: T::of(c.beta1),
            one_minus_beta1: T::of(c.one_minus_beta1),
            beta2: T::of(c.beta2),
            one_minus_beta2: T::of(c.one_minus_beta2),
            c1: T::of(c.c1),
            c2: T::of(c.c2),
            lr: T::of(c.lr),
            epsilon: T::of(c.epsilon),
        }
    }

    /// One block in place, each operation rounded as in the tensor-op chain (see `fused.rs`).
    fn update(&self, p: &mut [T], g: &[T], m: &mut [T], v: &mut [T]) {
        for (((p, &g), m), v) in p.iter_mut().zip(g).zip(m.iter_mut()).zip(v.iter_mut()) {
            *m = *m * self.beta1 + g * self.one_minus_beta1;
            *v = *v * self.beta2 + (g * g) * self.one_minus_beta2;
            *p = *p - ((*m / self.c1) / ((*v / self.c2).sqrt() + self.epsilon)) * self.lr;
        }
    }
}

/// Where one state tensor (p, m or v) is written, and where it is read from if elsewhere.
struct Slot {
    out: FlexTensor,
    source: Option<FlexTensor>,
}

impl Slot {
    fn new<T: Real>(t: FlexTensor) -> Self {
        let n = t.shape().num_elements();
        let whole = t.layout().contiguous_offsets() == Some((0, n)) && t.bytes().len() == n * size_of::<T>();
        if whole && t.is_unique() {
            return Self { out: t, source: None };
        }
        let out = FlexTensor::empty(t.shape(), t.dtype());
        let source = if t.is_contiguous() { t } else { t.to_contiguous() };
        Self { out, source: Some(source) }
    }

    /// The output buffer and, where it is not updated in place, the input to copy into it.
    fn slices<T: Real>(&mut self) -> (&mut [T], Option<&[T]>) {
        let out = T::whole_mut(&mut self.out).expect("a fresh or sole-owner buffer");
        (out, self.source.as_ref().map(|s| T::slice(s).expect(LAYOUT)))
    }
}

/// `out[range] ← source[range]` where the slot is not in place.
fn load<'a, T: Real>(out: &'a mut [T], source: Option<&[T]>, start: usize) -> &'a mut [T] {
    if let Some(source) = source {
        out.copy_from_slice(&source[start..start + out.len()]);
    }
    out
}

fn fused<T: Real>(
    param: FlexTensor,
    grad: FlexTensor,
    m: FlexTensor,
    v: FlexTensor,
    c: &Coefficients,
) -> (FlexTensor, FlexTensor, FlexTensor) {
    let scalars = Scalars::<T>::new(c);
    let grad = if grad.is_contiguous() { grad } else { grad.to_contiguous() };
    let g = T::slice(&grad).expect(LAYOUT);
    let [mut p, mut m, mut v] = [param, m, v].map(Slot::new::<T>);
    let ((p_out, p_in), (m_out, m_in), (v_out, v_in)) = (p.slices::<T>(), m.slices::<T>(), v.slices::<T>());
    assert!(p_out.len() == g.len() && m_out.len() == g.len() && v_out.len() == g.len(), "{LAYOUT}");
    p_out
        .par_chunks_mut(BLOCK)
        .zip(m_out.par_chunks_mut(BLOCK))
        .zip(v_out.par_chunks_mut(BLOCK))
        .zip(g.par_chunks(BLOCK))
        .enumerate()
        .for_each(|(b, (((p, m), v), g))| {
            let start = b * BLOCK;
            scalars.update(load(p, p_in, start), g, load(m, m_in, start), load(v, v_in, start));
        });
    (p.out, m.out, v.out)
}

impl AdamBackend for Flex {
    fn adam_step(
        param: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        m: FloatTensor<Self>,
        v: FloatTensor<Self>,
        coefficients: Coefficients,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        match param.dtype() {
            DType::F64 => fused::<f64>(param, grad, m, v, &coefficients),
            _ => fused::<f32>(param, grad, m, v, &coefficients),
        }
    }
}
