//! CubeCL kernels of the MLP, one unit per row, for comptime widths `I → H → H → O`. A row's
//! hidden activations go to global memory transposed (`[H, N]`, so a cube's writes and reads
//! are contiguous), not into per-unit arrays: with arrays of 64 floats per unit, lavapipe's
//! shader compiler runs for many minutes. Every loop runs at run time over scalar sums, and the
//! weights are read at the same address across a cube, so the cache serves them. Sums run over
//! the inputs in order from the bias, as on Flex.

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// One row of `bias + a·w` (`w` `[k, n]`), through a ReLU if `relu`: the row's input `c` is
/// `a[a_at + c·a_step]`, its output `j` goes to `out[out_at + j·out_step]`.
#[cube]
#[allow(clippy::too_many_arguments)]
fn layer(
    a: &[f32],
    a_at: usize,
    a_step: usize,
    w: &[f32],
    bias: &[f32],
    out: &mut [f32],
    out_at: usize,
    out_step: usize,
    #[comptime] k: usize,
    #[comptime] n: usize,
    #[comptime] relu: bool,
) {
    for j in 0..n {
        let mut acc = bias[j];
        for c in 0..k {
            acc += a[a_at + c * a_step] * w[c * n + j];
        }
        if relu {
            acc = select(acc > 0.0, acc, 0.0);
        }
        out[out_at + j * out_step] = acc;
    }
}

/// Entry `c` of one row of `w·up` (`w` `[k, n]`, the row's `up` at `up[up_at..up_at + n]`): the
/// gradient of a layer's input `c` given that of its outputs.
#[cube]
fn back(up: &[f32], up_at: usize, w: &[f32], c: usize, #[comptime] n: usize) -> f32 {
    let mut acc = 0.0f32;
    for j in 0..n {
        acc += up[up_at + j] * w[c * n + j];
    }
    acc
}

/// `out` `[N, o]`: the network on each row of `x` `[N, i]`; `h1t`, `h2t` `[h, N]` are scratch.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn mlp_forward(
    x: &[f32],
    w0: &[f32],
    b0: &[f32],
    w1: &[f32],
    b1: &[f32],
    w2: &[f32],
    b2: &[f32],
    h1t: &mut [f32],
    h2t: &mut [f32],
    out: &mut [f32],
    rows: u32,
    #[comptime] i: usize,
    #[comptime] h: usize,
    #[comptime] o: usize,
) {
    let r = ABSOLUTE_POS;
    let n = rows as usize;
    if r >= n {
        terminate!();
    }
    layer(x, r * i, 1, w0, b0, h1t, r, n, i, h, true);
    layer(&*h1t, r, n, w1, b1, h2t, r, n, h, h, true);
    layer(&*h2t, r, n, w2, b2, out, r * o, 1, h, o, false);
}

/// The per-row half of the backward pass given `grad` `[N, o]`: `dx` `[N, i]`, the gradients
/// `g0`, `g1` `[N, h]` of the two hidden layers' pre-activations, and the activations
/// transposed, `h1t`, `h2t` `[h, N]` (so each is the left factor of a weight gradient as is).
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn mlp_backward_rows(
    x: &[f32],
    w0: &[f32],
    b0: &[f32],
    w1: &[f32],
    b1: &[f32],
    w2: &[f32],
    grad: &[f32],
    dx: &mut [f32],
    g0: &mut [f32],
    g1: &mut [f32],
    h1t: &mut [f32],
    h2t: &mut [f32],
    rows: u32,
    #[comptime] i: usize,
    #[comptime] h: usize,
    #[comptime] o: usize,
) {
    let r = ABSOLUTE_POS;
    let n = rows as usize;
    if r >= n {
        terminate!();
    }
    layer(x, r * i, 1, w0, b0, h1t, r, n, i, h, true);
    layer(&*h1t, r, n, w1, b1, h2t, r, n, h, h, true);
    // Zeroed where the ReLU clipped the layer's output.
    for c in 0..h {
        g1[r * h + c] = select(h2t[c * n + r] > 0.0, back(grad, r * o, w2, c, o), 0.0);
    }
    for c in 0..h {
        g0[r * h + c] = select(h1t[c * n + r] > 0.0, back(&*g1, r * h, w1, c, h), 0.0);
    }
    for c in 0..i {
        dx[r * i + c] = back(&*g0, r * h, w0, c, h);
    }
}
