//! The fused update as one CubeCL kernel, generic over the float type: one unit per element,
//! so no unit reads what another writes and there are no loops (lavapipe caps loop trips).

// Kernels index their buffers: iterator forms do not exist in CubeCL.
#![allow(clippy::needless_range_loop)]

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// `m' = m·β1 + g·(1 − β1)`, `v' = v·β2 + (g·g)·(1 − β2)`,
/// `p' = p − ((m'/c1) / (sqrt(v'/c2) + ε))·lr`, rounded in this order as on Flex, over several
/// parameters in one launch: unit `i` updates element `i` of the parameters laid end to end
/// (parameter `k` at learning rate `lrs[k]`).
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn adam_steps<F: Float>(
    p: &Sequence<Box<[F]>>,
    g: &Sequence<Box<[F]>>,
    m: &Sequence<Box<[F]>>,
    v: &Sequence<Box<[F]>>,
    p_out: &mut Sequence<Box<[F]>>,
    m_out: &mut Sequence<Box<[F]>>,
    v_out: &mut Sequence<Box<[F]>>,
    lrs: &[F],
    beta1: InputScalar,
    one_minus_beta1: InputScalar,
    beta2: InputScalar,
    one_minus_beta2: InputScalar,
    c1: InputScalar,
    c2: InputScalar,
    epsilon: InputScalar,
    #[define(F)] _dtype: ElemType,
) {
    let i = ABSOLUTE_POS;
    let mut start = 0usize;
    #[unroll]
    for k in 0..p.len() {
        let len = p.index(k).len();
        if i >= start && i < start + len {
            let j = i - start;
            let gi = g.index(k)[j];
            let mi = m.index(k)[j] * beta1.get::<F>() + gi * one_minus_beta1.get::<F>();
            let vi = v.index(k)[j] * beta2.get::<F>() + (gi * gi) * one_minus_beta2.get::<F>();
            let step = ((mi / c1.get::<F>()) / (F::sqrt(vi / c2.get::<F>()) + epsilon.get::<F>())) * lrs[k];
            p_out.index_mut(k)[j] = p.index(k)[j] - step;
            m_out.index_mut(k)[j] = mi;
            v_out.index_mut(k)[j] = vi;
        }
        start += len;
    }
}
