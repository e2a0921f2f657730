//! The fused update as one CubeCL kernel, generic over the float type: one unit per element,
//! so no unit reads what another writes and there are no loops (lavapipe caps loop trips).

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// `m' = m·β1 + g·(1 − β1)`, `v' = v·β2 + (g·g)·(1 − β2)`,
/// `p' = p − ((m'/c1) / (sqrt(v'/c2) + ε))·lr`, rounded in this order as on Flex.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn adam_step<F: Float>(
    p: &[F],
    g: &[F],
    m: &[F],
    v: &[F],
    p_out: &mut [F],
    m_out: &mut [F],
    v_out: &mut [F],
    beta1: InputScalar,
    one_minus_beta1: InputScalar,
    beta2: InputScalar,
    one_minus_beta2: InputScalar,
    c1: InputScalar,
    c2: InputScalar,
    lr: InputScalar,
    epsilon: InputScalar,
    #[define(F)] _dtype: ElemType,
) {
    let i = ABSOLUTE_POS;
    if i >= p.len() {
        terminate!();
    }
    let gi = g[i];
    let mi = m[i] * beta1.get::<F>() + gi * one_minus_beta1.get::<F>();
    let vi = v[i] * beta2.get::<F>() + (gi * gi) * one_minus_beta2.get::<F>();
    let step = ((mi / c1.get::<F>()) / (F::sqrt(vi / c2.get::<F>()) + epsilon.get::<F>())) * lr.get::<F>();
    p_out[i] = p[i] - step;
    m_out[i] = mi;
    v_out[i] = vi;
}
