//! CubeCL kernels of the regularisers, in f32, with the host math of `laplacian.rs`,
//! `normal_consistency.rs` and `equilateral.rs`. The forward kernels write one loss share per
//! element (summed afterwards); the backward kernels write each element's gradient per corner,
//! and `gather_corners` sums them per vertex, so no two units write the same place.

// Kernels walk their lists by index: CubeCL has no iterators.
#![allow(clippy::needless_range_loop)]

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// Floor of the lengths, as `rows::EPS` on the host; squared, it is still a normal f32.
const EPS: f32 = 1e-12;

#[cube]
fn load(v: &[f32], i: usize) -> (f32, f32, f32) {
    (v[3 * i], v[3 * i + 1], v[3 * i + 2])
}

#[cube]
fn zero() -> (f32, f32, f32) {
    (0.0f32, 0.0f32, 0.0f32)
}

#[cube]
fn cross(a: (f32, f32, f32), b: (f32, f32, f32)) -> (f32, f32, f32) {
    (a.1 * b.2 - a.2 * b.1, a.2 * b.0 - a.0 * b.2, a.0 * b.1 - a.1 * b.0)
}

#[cube]
fn dot(a: (f32, f32, f32), b: (f32, f32, f32)) -> f32 {
    a.0 * b.0 + a.1 * b.1 + a.2 * b.2
}

#[cube]
fn sub(a: (f32, f32, f32), b: (f32, f32, f32)) -> (f32, f32, f32) {
    (a.0 - b.0, a.1 - b.1, a.2 - b.2)
}

#[cube]
fn scale(a: (f32, f32, f32), s: f32) -> (f32, f32, f32) {
    (a.0 * s, a.1 * s, a.2 * s)
}

/// `a·s + b·t`.
#[cube]
fn mix(a: (f32, f32, f32), s: f32, b: (f32, f32, f32), t: f32) -> (f32, f32, f32) {
    (a.0 * s + b.0 * t, a.1 * s + b.1 * t, a.2 * s + b.2 * t)
}

#[cube]
fn store(out: &mut [f32], at: usize, a: (f32, f32, f32)) {
    out[at] = a.0;
    out[at + 1] = a.1;
    out[at + 2] = a.2;
}

/// Row `k` of a local `[·, 3]` array += `x·t`.
#[cube]
fn accumulate(a: &mut Array<f32>, k: usize, x: (f32, f32, f32), t: f32) {
    a[3 * k] += x.0 * t;
    a[3 * k + 1] += x.1 * t;
    a[3 * k + 2] += x.2 * t;
}

/// Row `k` of a local `[·, 3]` array.
#[cube]
fn get(a: &Array<f32>, k: usize) -> (f32, f32, f32) {
    (a[3 * k], a[3 * k + 1], a[3 * k + 2])
}

#[cube]
fn put(a: &mut Array<f32>, k: usize, x: (f32, f32, f32)) {
    a[3 * k] = x.0;
    a[3 * k + 1] = x.1;
    a[3 * k + 2] = x.2;
}

/// `δ_i = v_i − mean of its ring` (0 for an isolated vertex) into `delta`, and `scale·‖δ_i‖²`
/// into `share`.
#[cube(launch)]
pub(crate) fn laplacian_deltas(
    v: &[f32],
    ring_start: &[i32],
    rings: &[i32],
    delta: &mut [f32],
    share: &mut [f32],
    n: u32,
    scale: f32,
) {
    let i = ABSOLUTE_POS;
    if i >= n as usize {
        terminate!();
    }
    let start = usize::cast_from(ring_start[i]);
    let end = usize::cast_from(ring_start[i + 1]);
    let mut sum = Array::<f32>::new(3usize);
    put(&mut sum, 0, zero());
    for r in start..end {
        let p = load(v, usize::cast_from(rings[r]));
        accumulate(&mut sum, 0, p, 1.0f32);
    }
    let connected = end > start;
    let inv = select(connected, 1.0f32 / f32::cast_from(end - start), 0.0f32);
    let d = mix(load(v, i), select(connected, 1.0f32, 0.0f32), get(&sum, 0), -inv);
    store(delta, 3 * i, d);
    share[i] = scale * dot(d, d);
}

/// `∂L/∂v_k = 2·scale·upstream·(δ_k − Σ_{i∈N(k)} δ_i/|N(i)|)` (rings are symmetric).
#[cube(launch)]
pub(crate) fn laplacian_gather(
    delta: &[f32],
    ring_start: &[i32],
    rings: &[i32],
    upstream: &[f32],
    out: &mut [f32],
    n: u32,
    scale: f32,
) {
    let k = ABSOLUTE_POS;
    if k >= n as usize {
        terminate!();
    }
    let mut pulled = Array::<f32>::new(3usize);
    put(&mut pulled, 0, zero());
    for r in usize::cast_from(ring_start[k])..usize::cast_from(ring_start[k + 1]) {
        let i = usize::cast_from(rings[r]);
        let valence = f32::cast_from(ring_start[i + 1] - ring_start[i]);
        accumulate(&mut pulled, 0, load(delta, i), 1.0f32 / valence);
    }
    let s = 2.0f32 * scale * upstream[0];
    store(out, 3 * k, mix(load(delta, k), s, get(&pulled, 0), -s));
}

/// A length and `n/|n|²` from a vector's square, floored as on the host (no gradient below it).
#[cube]
fn floored(n: (f32, f32, f32)) -> (f32, (f32, f32, f32)) {
    let s = dot(n, n);
    let above = s > EPS * EPS;
    let inv = select(above, 1.0f32 / s, 0.0f32);
    (select(above, f32::sqrt(s), EPS), (n.0 * inv, n.1 * inv, n.2 * inv))
}

/// Per hinge `[a, b, c, d]` of `h`: forward (`backward` false) writes its share `(1 − cos)/h` to
/// `out[k]`; backward writes the gradient of `−cos/h` at `a, b, c, d` to `out[12k ..]`.
#[cube(launch)]
pub(crate) fn hinge_terms(v: &[f32], hinges: &[i32], out: &mut [f32], h: u32, #[comptime] backward: bool) {
    let k = ABSOLUTE_POS;
    if k >= h as usize {
        terminate!();
    }
    let p = load(v, usize::cast_from(hinges[4 * k]));
    let e = sub(load(v, usize::cast_from(hinges[4 * k + 1])), p);
    let u = sub(load(v, usize::cast_from(hinges[4 * k + 2])), p);
    let w = sub(load(v, usize::cast_from(hinges[4 * k + 3])), p);
    let n1 = cross(e, u);
    let n2 = cross(w, e);
    let (l1, dl1) = floored(n1);
    let (l2, dl2) = floored(n2);
    let ll = l1 * l2;
    let cos = dot(n1, n2) / ll;
    let weight = -1.0f32 / f32::cast_from(h);
    if backward {
        let g1 = mix(n2, weight / ll, dl1, -weight * cos);
        let g2 = mix(n1, weight / ll, dl2, -weight * cos);
        let gu = cross(g1, e);
        let gw = cross(e, g2);
        let ge = mix(cross(u, g1), 1.0f32, cross(g2, w), 1.0f32);
        let ga = (-(ge.0 + gu.0 + gw.0), -(ge.1 + gu.1 + gw.1), -(ge.2 + gu.2 + gw.2));
        store(out, 12 * k, ga);
        store(out, 12 * k + 3, ge);
        store(out, 12 * k + 6, gu);
        store(out, 12 * k + 9, gw);
    } else {
        out[k] = (1.0f32 - cos) / f32::cast_from(h);
    }
}

/// Per face of `f`: forward (`backward` false) writes its share of the mean to `out[i]`;
/// backward writes the share's gradient at its three corners to `out[9i ..]`. Edge `k` runs
/// from corner `k` to corner `k + 1`; the angle at corner `k` lies between edges `k + 2` (in)
/// and `k` (out).
#[cube(launch)]
pub(crate) fn face_terms(v: &[f32], faces: &[i32], out: &mut [f32], f: u32, #[comptime] backward: bool) {
    let i = ABSOLUTE_POS;
    if i >= f as usize {
        terminate!();
    }
    let weight = 1.0f32 / f32::cast_from(f);
    // Edges `[3·3]`, squared lengths, floored lengths.
    let mut edges = Array::<f32>::new(9usize);
    let mut squared = Array::<f32>::new(3usize);
    let mut lengths = Array::<f32>::new(3usize);
    #[unroll]
    for k in 0..3usize {
        let from = load(v, usize::cast_from(faces[3 * i + k]));
        let to = load(v, usize::cast_from(faces[3 * i + (k + 1) % 3]));
        let e = sub(to, from);
        put(&mut edges, k, e);
        let s = dot(e, e);
        squared[k] = s;
        lengths[k] = select(s > EPS * EPS, f32::sqrt(s), EPS);
    }
    let mean = (lengths[0] + lengths[1] + lengths[2]) / 3.0f32;
    let mut loss = 0.0f32;
    let mut g_l = Array::<f32>::new(3usize);
    let mut g_e = Array::<f32>::new(9usize);
    #[unroll]
    for k in 0..3usize {
        loss += (lengths[k] - mean) * (lengths[k] - mean) / 3.0f32;
        g_l[k] = weight * 2.0f32 / 3.0f32 * (lengths[k] - mean);
        put(&mut g_e, k, zero());
    }
    #[unroll]
    for k in 0..3usize {
        let into = (k + 2) % 3;
        let e_in = get(&edges, into);
        let e_out = get(&edges, k);
        let (li, lo) = (lengths[into], lengths[k]);
        let cos = -dot(e_in, e_out) / (li * lo);
        loss += (1.0f32 - cos) * (1.0f32 - cos);
        let gamma = -weight * 2.0f32 * (1.0f32 - cos);
        accumulate(&mut g_e, into, e_out, -gamma / (li * lo));
        accumulate(&mut g_e, k, e_in, -gamma / (li * lo));
        g_l[into] -= gamma * cos / li;
        g_l[k] -= gamma * cos / lo;
    }
    if backward {
        // d_k flows +1 to corner k + 1 and −1 to corner k.
        let mut d = Array::<f32>::new(9usize);
        #[unroll]
        for k in 0..3usize {
            let along = select(squared[k] > EPS * EPS, g_l[k] / lengths[k], 0.0f32);
            put(&mut d, k, mix(get(&g_e, k), 1.0f32, get(&edges, k), along));
        }
        #[unroll]
        for k in 0..3usize {
            store(out, 9 * i + 3 * k, sub(get(&d, (k + 2) % 3), get(&d, k)));
        }
    } else {
        out[i] = weight * loss;
    }
}

/// Per vertex: `upstream ·` the sum of the per-corner gradients `grads[3s ..]` over its slots.
#[cube(launch)]
pub(crate) fn gather_corners(
    grads: &[f32],
    start: &[i32],
    slots: &[i32],
    upstream: &[f32],
    out: &mut [f32],
    n: u32,
) {
    let i = ABSOLUTE_POS;
    if i >= n as usize {
        terminate!();
    }
    let mut sum = Array::<f32>::new(3usize);
    put(&mut sum, 0, zero());
    for r in usize::cast_from(start[i])..usize::cast_from(start[i + 1]) {
        accumulate(&mut sum, 0, load(grads, usize::cast_from(slots[r])), 1.0f32);
    }
    store(out, 3 * i, scale(get(&sum, 0), upstream[0]));
}
