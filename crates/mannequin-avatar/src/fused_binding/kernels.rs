//! CubeCL kernels of the binding: the math of `host.rs`, one unit per face or vertex. Every sum
//! onto a vertex is a gather over its face corners (and its one-ring, for the shortest edges
//! that end there), so no unit writes where another does: WGSL has no float atomics, and the
//! result does not depend on scheduling.
//!
//! The mesh arrives as `u32` tables: `faces` `[F · 3]`; `corner_start` `[V + 1]` and `corners`,
//! each vertex's corners `3f + c` in ascending face order; `ring_start` `[V + 1]` and `rings`,
//! each vertex's one-ring as [`crate::one_ring_mesh::OneRingMesh::ring`] lists it.

// Kernels index their tables: they have no iterators.
#![allow(clippy::needless_range_loop)]

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// Sizes, where the output planes start, and the binding's constants.
#[derive(CubeLaunch, CubeType, Clone, Copy)]
pub(crate) struct Params {
    pub faces: u32,
    pub vertices: u32,
    /// Row of the first vertex Gaussian.
    pub split: u32,
    /// Where the frames, scales and normals planes start (means start at 0).
    pub frames: u32,
    pub scales: u32,
    pub normals: u32,
    pub norm_eps: f32,
    pub face_scale: f32,
    pub vertex_scale: f32,
    pub normal_scale: f32,
}

#[derive(CubeType, Clone, Copy)]
struct V3 {
    x: f32,
    y: f32,
    z: f32,
}

#[cube]
fn v3(x: f32, y: f32, z: f32) -> V3 {
    V3 { x, y, z }
}

#[cube]
fn zero() -> V3 {
    v3(0.0f32, 0.0f32, 0.0f32)
}

#[cube]
fn add(a: &V3, b: &V3) -> V3 {
    v3(a.x + b.x, a.y + b.y, a.z + b.z)
}

#[cube]
fn sub(a: &V3, b: &V3) -> V3 {
    v3(a.x - b.x, a.y - b.y, a.z - b.z)
}

#[cube]
fn scale(a: &V3, s: f32) -> V3 {
    v3(a.x * s, a.y * s, a.z * s)
}

#[cube]
fn dot(a: &V3, b: &V3) -> f32 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

#[cube]
fn cross(a: &V3, b: &V3) -> V3 {
    v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x)
}

/// `‖x‖` kept differentiable at zero, as `host::norm`.
#[cube]
fn norm(a: &V3, eps: f32) -> f32 {
    f32::sqrt(dot(a, a) + eps)
}

/// The VJP of `x / ‖x‖` at unit `n`, as `host::normalise_vjp`.
#[cube]
fn normalise_vjp(n: &V3, length: f32, g: &V3) -> V3 {
    scale(&sub(g, &scale(n, dot(n, g))), 1.0f32 / length)
}

/// The three values from `at`.
#[cube]
fn load(buf: &[f32], at: usize) -> V3 {
    v3(buf[at], buf[at + 1], buf[at + 2])
}

#[cube]
fn store(buf: &mut [f32], at: usize, a: &V3) {
    buf[at] = a.x;
    buf[at + 1] = a.y;
    buf[at + 2] = a.z;
}

/// Vertex `i` of `v` `[V · 3]`.
#[cube]
fn point(v: &[f32], i: u32) -> V3 {
    load(v, 3 * usize::cast_from(i))
}

/// Writes row `k`: mean, frame (row-major, columns t1, t2, n), disk scales, normal.
#[cube]
#[allow(clippy::too_many_arguments)]
fn write_row(out: &mut [f32], p: &Params, k: usize, mean: &V3, t1: &V3, t2: &V3, n: &V3, in_plane: f32) {
    store(out, 3 * k, mean);
    let f = p.frames as usize + 9 * k;
    store(out, f, &v3(t1.x, t2.x, n.x));
    store(out, f + 3, &v3(t1.y, t2.y, n.y));
    store(out, f + 6, &v3(t1.z, t2.z, n.z));
    store(out, p.scales as usize + 3 * k, &v3(in_plane, in_plane, p.normal_scale));
    store(out, p.normals as usize + 3 * k, n);
}

/// A row's gradient, as `host::read_row` reads it: the normal output adds to n, and the two
/// in-plane scales to one.
#[derive(CubeType, Clone, Copy)]
struct RowGrad {
    mean: V3,
    t1: V3,
    t2: V3,
    n: V3,
    s: f32,
}

/// The gradient of a row that is not in the output.
#[cube]
fn zero_row() -> RowGrad {
    RowGrad { mean: zero(), t1: zero(), t2: zero(), n: zero(), s: 0.0f32 }
}

#[cube]
fn read_row(grad: &[f32], p: &Params, k: usize) -> RowGrad {
    let f = p.frames as usize + 9 * k;
    let s = p.scales as usize + 3 * k;
    RowGrad {
        mean: load(grad, 3 * k),
        t1: v3(grad[f], grad[f + 3], grad[f + 6]),
        t2: v3(grad[f + 1], grad[f + 4], grad[f + 7]),
        n: add(&v3(grad[f + 2], grad[f + 5], grad[f + 8]), &load(grad, p.normals as usize + 3 * k)),
        s: grad[s] + grad[s + 1],
    }
}

/// What Eqs. 5–8 read of one face, as `host::Face`.
#[derive(CubeType, Clone, Copy)]
struct Face {
    a: V3,
    b: V3,
    c: V3,
    e_ab: V3,
    e_ac: V3,
    /// Lengths of the edges opposite a, b and c.
    la: f32,
    lb: f32,
    lc: f32,
    perimeter: f32,
    cross: V3,
    double_area: f32,
}

/// Corner `c` of face `f`.
#[cube]
fn corner(v: &[f32], faces: &[u32], f: usize, c: usize) -> V3 {
    point(v, faces[3 * f + c])
}

/// `(b − a) × (c − a)` of face `f`, as `host::Face::new` computes it.
#[cube]
fn face_cross(v: &[f32], faces: &[u32], f: usize) -> V3 {
    let a = corner(v, faces, f, 0);
    cross(&sub(&corner(v, faces, f, 1), &a), &sub(&corner(v, faces, f, 2), &a))
}

#[cube]
fn face(v: &[f32], faces: &[u32], f: usize, eps: f32) -> Face {
    let a = corner(v, faces, f, 0);
    let b = corner(v, faces, f, 1);
    let c = corner(v, faces, f, 2);
    let e_ab = sub(&b, &a);
    let e_ac = sub(&c, &a);
    let la = norm(&sub(&b, &c), eps);
    let lb = norm(&e_ac, eps);
    let lc = norm(&e_ab, eps);
    let perimeter = la + lb + lc;
    let x = cross(&e_ab, &e_ac);
    let double_area = norm(&x, eps);
    Face { a, b, c, e_ab, e_ac, la, lb, lc, perimeter, cross: x, double_area }
}

/// The incenter relative to corner a (see `host::Face::incenter_from_a`).
#[cube]
fn incenter_from_a(t: &Face) -> V3 {
    scale(&add(&scale(&t.e_ab, t.lb), &scale(&t.e_ac, t.lc)), 1.0f32 / t.perimeter)
}

/// The corners' gradients given the row's gradient `g` and the extra gradient `g_cross` of the
/// face's cross product, as `host::Face::vjp`.
#[cube]
fn face_vjp(t: &Face, g: &RowGrad, g_cross: &V3, face_scale: f32) -> (V3, V3, V3) {
    let (p, a2) = (t.perimeter, t.double_area);
    let n = scale(&t.cross, 1.0f32 / a2);
    let t1 = scale(&t.e_ab, 1.0f32 / t.lc);
    // t2 = n × t1.
    let g_n = add(&g.n, &cross(&t1, &g.t2));
    let g_t1 = add(&g.t1, &cross(&g.t2, &n));
    // s = β r with r = 2A / P.
    let g_r = face_scale * g.s;
    let g_p = -g_r * (a2 / p) / p;
    // n = x / ‖x‖ and ‖x‖ itself (through r).
    let g_a2 = g_r / p - dot(&g_n, &n) / a2;
    let g_x = add(&add(&scale(&g_n, 1.0f32 / a2), &scale(&n, g_a2)), g_cross);
    // mean = (a la + b lb + c lc) / P.
    let g_sum = scale(&g.mean, 1.0f32 / p);
    let m = incenter_from_a(t);
    let g_la = g_p - dot(&g_sum, &m);
    let g_lb = g_p + dot(&g_sum, &sub(&t.e_ab, &m));
    // t1 = e_ab / lc, and lc in the mean.
    let g_lc = -dot(&g_t1, &t1) / t.lc + (g_p + dot(&g_sum, &sub(&t.e_ac, &m)));
    // x = e_ab × e_ac, then the edge lengths.
    let g_e_ab = add(&add(&scale(&g_t1, 1.0f32 / t.lc), &cross(&t.e_ac, &g_x)), &scale(&t.e_ab, g_lc / t.lc));
    let g_e_ac = add(&cross(&g_x, &t.e_ab), &scale(&t.e_ac, g_lb / t.lb));
    let g_bc = scale(&sub(&t.b, &t.c), g_la / t.la);
    let g_b = add(&scale(&g_sum, t.lb), &g_bc);
    let g_c = sub(&scale(&g_sum, t.lc), &g_bc);
    // e_ab = b − a, e_ac = c − a.
    let g_a = sub(&sub(&scale(&g_sum, t.la), &g_e_ab), &g_e_ac);
    (g_a, add(&g_b, &g_e_ab), add(&g_c, &g_e_ac))
}

/// What Eqs. 9–11 read of one vertex, as `host::Vertex` (frame and all).
#[derive(CubeType, Clone, Copy)]
struct Vertex {
    position: V3,
    n: V3,
    sum_norm: f32,
    axis: V3,
    t1: V3,
    u_norm: f32,
    nearest: u32,
    edge: V3,
    edge_length: f32,
}

/// Vertex `i`: its normal from the crosses of its faces summed in face order (as
/// `host::cross_sums`), Eq. 10's axis, Eq. 11's shortest one-ring edge (first of equals).
#[cube]
#[allow(clippy::too_many_arguments)]
fn vertex(
    v: &[f32],
    faces: &[u32],
    corner_start: &[u32],
    corners: &[u32],
    ring_start: &[u32],
    rings: &[u32],
    i: usize,
    eps: f32,
) -> Vertex {
    let position = load(v, 3 * i);
    let mut sx = 0.0f32;
    let mut sy = 0.0f32;
    let mut sz = 0.0f32;
    for e in corner_start[i] as usize..corner_start[i + 1] as usize {
        let x = face_cross(v, faces, corners[e] as usize / 3);
        sx += x.x;
        sy += x.y;
        sz += x.z;
    }
    let sum = v3(sx, sy, sz);
    let sum_norm = norm(&sum, eps);
    let n = scale(&sum, 1.0f32 / sum_norm);
    // Eq. 10: the axis least aligned with the normal (first of equals).
    let (ax, ay, az) = (f32::abs(n.x), f32::abs(n.y), f32::abs(n.z));
    let is_y = ay < ax;
    let is_z = az < select(is_y, ay, ax);
    let axis = v3(
        select(!is_y && !is_z, 1.0f32, 0.0f32),
        select(is_y && !is_z, 1.0f32, 0.0f32),
        select(is_z, 1.0f32, 0.0f32),
    );
    let u = cross(&axis, &n);
    let u_norm = norm(&u, eps);
    // Eq. 11: the vertex itself when isolated (a zero edge).
    let mut nearest = u32::cast_from(i);
    let mut best = 0.0f32;
    let first = ring_start[i] as usize;
    for e in first..ring_start[i + 1] as usize {
        let j = rings[e];
        let d = sub(&point(v, j), &position);
        let d2 = dot(&d, &d);
        if e == first || d2 < best {
            best = d2;
            nearest = j;
        }
    }
    let edge = sub(&point(v, nearest), &position);
    let edge_length = norm(&edge, eps);
    Vertex { position, n, sum_norm, axis, t1: scale(&u, 1.0f32 / u_norm), u_norm, nearest, edge, edge_length }
}

/// One unit per face `f`: its Gaussian into row `f` of `out` (Eqs. 5–8).
#[cube(launch)]
pub(crate) fn bind_faces(v: &[f32], faces: &[u32], out: &mut [f32], p: Params) {
    let f = ABSOLUTE_POS;
    if f >= p.faces as usize {
        terminate!();
    }
    let t = face(v, faces, f, p.norm_eps);
    let n = scale(&t.cross, 1.0f32 / t.double_area);
    let t1 = scale(&t.e_ab, 1.0f32 / t.lc);
    let in_plane = p.face_scale * t.double_area / t.perimeter;
    write_row(out, &p, f, &add(&t.a, &incenter_from_a(&t)), &t1, &cross(&n, &t1), &n, in_plane);
}

/// One unit per vertex `i`: its Gaussian into row `split + i` of `out` (Eqs. 9–11).
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn bind_vertices(
    v: &[f32],
    faces: &[u32],
    corner_start: &[u32],
    corners: &[u32],
    ring_start: &[u32],
    rings: &[u32],
    out: &mut [f32],
    p: Params,
) {
    let i = ABSOLUTE_POS;
    if i >= p.vertices as usize {
        terminate!();
    }
    let x = vertex(v, faces, corner_start, corners, ring_start, rings, i, p.norm_eps);
    let row = p.split as usize + i;
    let in_plane = p.vertex_scale * x.edge_length;
    write_row(out, &p, row, &x.position, &x.t1, &cross(&x.n, &x.t1), &x.n, in_plane);
}

/// One unit per vertex `i`, given the output's gradient `grad`: `terms[i]` = (the gradient of
/// its summed face crosses, that of its shortest edge), and that edge's far end in `nearest[i]`,
/// as `host::Vertex::vjp`. The mean's gradient is read from `grad` again by [`gather_vertices`].
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn vertex_terms(
    v: &[f32],
    faces: &[u32],
    corner_start: &[u32],
    corners: &[u32],
    ring_start: &[u32],
    rings: &[u32],
    grad: &[f32],
    terms: &mut [f32],
    nearest: &mut [u32],
    p: Params,
) {
    let i = ABSOLUTE_POS;
    if i >= p.vertices as usize {
        terminate!();
    }
    let x = vertex(v, faces, corner_start, corners, ring_start, rings, i, p.norm_eps);
    let g = read_row(grad, &p, p.split as usize + i);
    let g_n = add(&g.n, &cross(&x.t1, &g.t2));
    let g_t1 = add(&g.t1, &cross(&g.t2, &x.n));
    let g_u = normalise_vjp(&x.t1, x.u_norm, &g_t1);
    // u = axis × n.
    let g_n = add(&g_n, &cross(&g_u, &x.axis));
    store(terms, 6 * i, &normalise_vjp(&x.n, x.sum_norm, &g_n));
    store(terms, 6 * i + 3, &scale(&x.edge, p.vertex_scale * g.s / x.edge_length));
    nearest[i] = x.nearest;
}

/// One unit per face `f`: its corners' gradients into `corner_grads[f]` `[3 · 3]`, from its
/// row of `grad` (with face Gaussians) and its corners' cross gradients in `terms` (with vertex
/// Gaussians).
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn face_terms(
    v: &[f32],
    faces: &[u32],
    grad: &[f32],
    terms: &[f32],
    corner_grads: &mut [f32],
    p: Params,
    #[comptime] face_rows: bool,
    #[comptime] vertex_rows: bool,
) {
    let f = ABSOLUTE_POS;
    if f >= p.faces as usize {
        terminate!();
    }
    let t = face(v, faces, f, p.norm_eps);
    let g = if face_rows { read_row(grad, &p, f) } else { zero_row() };
    let g_cross = if vertex_rows {
        let a = load(terms, 6 * faces[3 * f] as usize);
        let b = load(terms, 6 * faces[3 * f + 1] as usize);
        add(&add(&a, &b), &load(terms, 6 * faces[3 * f + 2] as usize))
    } else {
        zero()
    };
    let (g_a, g_b, g_c) = face_vjp(&t, &g, &g_cross, p.face_scale);
    store(corner_grads, 9 * f, &g_a);
    store(corner_grads, 9 * f + 3, &g_b);
    store(corner_grads, 9 * f + 6, &g_c);
}

/// One unit per vertex `i`: `d[i]` = its corners' gradients, and with vertex Gaussians its
/// mean's gradient less its shortest edge's, plus the edges of the one-ring vertices whose
/// shortest edge ends at `i` (rings are symmetric, so those are all there are; an isolated
/// vertex's edge is zero).
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn gather_vertices(
    corner_start: &[u32],
    corners: &[u32],
    ring_start: &[u32],
    rings: &[u32],
    grad: &[f32],
    corner_grads: &[f32],
    terms: &[f32],
    nearest: &[u32],
    d: &mut [f32],
    p: Params,
    #[comptime] vertex_rows: bool,
) {
    let i = ABSOLUTE_POS;
    if i >= p.vertices as usize {
        terminate!();
    }
    let mut dx = 0.0f32;
    let mut dy = 0.0f32;
    let mut dz = 0.0f32;
    for e in corner_start[i] as usize..corner_start[i + 1] as usize {
        let g = load(corner_grads, 3 * corners[e] as usize);
        dx += g.x;
        dy += g.y;
        dz += g.z;
    }
    if vertex_rows {
        let own = sub(&load(grad, 3 * (p.split as usize + i)), &load(terms, 6 * i + 3));
        dx += own.x;
        dy += own.y;
        dz += own.z;
        let me = u32::cast_from(i);
        for e in ring_start[i] as usize..ring_start[i + 1] as usize {
            let j = rings[e];
            if nearest[j as usize] == me {
                let g = load(terms, 6 * j as usize + 3);
                dx += g.x;
                dy += g.y;
                dz += g.z;
            }
        }
    }
    store(d, 3 * i, &v3(dx, dy, dz));
}
