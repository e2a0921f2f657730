//! Tavatar's binding (Eqs. 5–11) on host memory, forward and its hand-written vector-Jacobian
//! product: the same math as [`crate::mesh_gaussians`], one face or vertex per task instead of
//! ~100 whole-tensor ops, each allocating. Scatters onto vertices run in a fixed sequential order,
//! so gradients are bit-identical from run to run whatever the thread count.

use std::ops::Range;

use rayon::prelude::*;

use super::{BindConfig, PACKED, PLANES, plane_starts};
use crate::mesh_gaussians::{FACE_SCALE, NORM_EPS, NORMAL_SCALE, VERTEX_SCALE};
use crate::one_ring_mesh::OneRingMesh;

type V3 = [f32; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: V3, s: f32) -> V3 {
    a.map(|x| x * s)
}

fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `‖x‖` kept differentiable at zero, as the tensor path's `row_norm`.
fn norm(a: V3) -> f32 {
    (dot(a, a) + NORM_EPS as f32).sqrt()
}

/// The VJP of `x / ‖x‖` at unit `n = x / ‖x‖`: `(g − n (n·g)) / ‖x‖`.
fn normalise_vjp(n: V3, length: f32, g: V3) -> V3 {
    scale(sub(g, scale(n, dot(n, g))), 1.0 / length)
}

fn point(v: &[f32], i: u32) -> V3 {
    let i = 3 * i as usize;
    [v[i], v[i + 1], v[i + 2]]
}

/// One Gaussian's slots in the four [`PLANES`].
type Row<'a> = [&'a mut [f32]; 4];

/// One Gaussian's gradient in the four [`PLANES`].
type RowGrad<'a> = [&'a [f32]; 4];

/// Writes a row: mean, frame (row-major, columns t1, t2, n), disk scales, normal.
fn write_row(row: Row, mean: V3, t1: V3, t2: V3, n: V3, in_plane: f32) {
    let [m, frame, s, normal] = row;
    m.copy_from_slice(&mean);
    for r in 0..3 {
        frame[3 * r..3 * r + 3].copy_from_slice(&[t1[r], t2[r], n[r]]);
    }
    s.copy_from_slice(&[in_plane, in_plane, NORMAL_SCALE as f32]);
    normal.copy_from_slice(&n);
}

/// A row's gradient as (mean, t1, t2, n, in-plane scale); the normal output adds to n.
fn read_row(g: RowGrad) -> (V3, V3, V3, V3, f32) {
    let [m, frame, s, normal] = g;
    let column = |k: usize| [frame[k], frame[3 + k], frame[6 + k]];
    let n = add(column(2), [normal[0], normal[1], normal[2]]);
    ([m[0], m[1], m[2]], column(0), column(1), n, s[0] + s[1])
}

/// Rows `range` of the planes of `out` (`g` Gaussians), in parallel.
fn rows_mut(out: &mut [f32], g: usize, range: Range<usize>) -> impl IndexedParallelIterator<Item = Row<'_>> {
    let mut rest = out;
    let [m, f, s, n] = PLANES.map(|w| {
        let (plane, tail) = std::mem::take(&mut rest).split_at_mut(w * g);
        rest = tail;
        &mut plane[w * range.start..w * range.end]
    });
    let [wm, wf, ws, wn] = PLANES;
    m.par_chunks_mut(wm)
        .zip(f.par_chunks_mut(wf))
        .zip(s.par_chunks_mut(ws))
        .zip(n.par_chunks_mut(wn))
        .map(|(((m, f), s), n)| [m, f, s, n])
}

/// Row `k`'s gradient in the planes of `grad` (`g` Gaussians).
fn row_grad(grad: &[f32], g: usize, k: usize) -> RowGrad<'_> {
    let starts = plane_starts(g);
    std::array::from_fn(|p| &grad[starts[p] + PLANES[p] * k..][..PLANES[p]])
}

/// What Eqs. 5–8 read of one face.
struct Face {
    corners: [V3; 3],
    e_ab: V3,
    e_ac: V3,
    /// Lengths of the edges opposite a, b and c.
    lengths: V3,
    perimeter: f32,
    /// `(b − a) × (c − a)` = 2A·n, and its norm 2A.
    cross: V3,
    double_area: f32,
}

impl Face {
    fn new(v: &[f32], f: [u32; 3]) -> Self {
        let corners = f.map(|i| point(v, i));
        let [a, b, c] = corners;
        let (e_ab, e_ac) = (sub(b, a), sub(c, a));
        let lengths = [norm(sub(b, c)), norm(e_ac), norm(e_ab)];
        let cross = cross(e_ab, e_ac);
        Self {
            corners,
            e_ab,
            e_ac,
            lengths,
            perimeter: lengths[0] + lengths[1] + lengths[2],
            cross,
            double_area: norm(cross),
        }
    }

    /// The incenter relative to corner a, `(lb (b − a) + lc (c − a)) / P`: centimetre-sized
    /// vectors, so its gradient does not cancel metre-sized coordinates in f32.
    fn incenter_from_a(&self) -> V3 {
        let [_, lb, lc] = self.lengths;
        scale(add(scale(self.e_ab, lb), scale(self.e_ac, lc)), 1.0 / self.perimeter)
    }

    /// Eqs. 5–8 into a row.
    fn write(&self, row: Row) {
        let n = scale(self.cross, 1.0 / self.double_area);
        let t1 = scale(self.e_ab, 1.0 / self.lengths[2]);
        let in_plane = FACE_SCALE as f32 * self.double_area / self.perimeter;
        write_row(row, add(self.corners[0], self.incenter_from_a()), t1, cross(n, t1), n, in_plane);
    }

    /// Gradients of the three corners given the row's gradient `g` (none without face
    /// Gaussians) and an extra gradient `g_cross` on the face's cross product (from the vertex
    /// normals).
    fn vjp(&self, g: Option<RowGrad>, g_cross: V3) -> [V3; 3] {
        let [_, b, c] = self.corners;
        let [la, lb, lc] = self.lengths;
        let (p, a2) = (self.perimeter, self.double_area);
        let n = scale(self.cross, 1.0 / a2);
        let t1 = scale(self.e_ab, 1.0 / lc);
        let (g_mean, mut g_t1, g_t2, mut g_n, g_s) = g.map(read_row).unwrap_or_default();
        // t2 = n × t1.
        g_n = add(g_n, cross(t1, g_t2));
        g_t1 = add(g_t1, cross(g_t2, n));
        // s = β r with r = 2A / P.
        let g_r = FACE_SCALE as f32 * g_s;
        let mut g_a2 = g_r / p;
        let g_p = -g_r * (a2 / p) / p;
        // n = x / ‖x‖ and ‖x‖ itself (through r).
        g_a2 -= dot(g_n, n) / a2;
        let g_x = add(add(scale(g_n, 1.0 / a2), scale(n, g_a2)), g_cross);
        // t1 = e_ab / lc.
        let mut g_e_ab = scale(g_t1, 1.0 / lc);
        let mut g_lc = -dot(g_t1, t1) / lc;
        // mean = (a la + b lb + c lc) / P: ∂/∂a = la / P, and ∂/∂la = (a − mean) / P (the same
        // for b and c), written with the incenter's offset from a.
        let g_sum = scale(g_mean, 1.0 / p);
        let (mut g_a, mut g_b, mut g_c) = (scale(g_sum, la), scale(g_sum, lb), scale(g_sum, lc));
        let m = self.incenter_from_a();
        let g_la = g_p - dot(g_sum, m);
        let g_lb = g_p + dot(g_sum, sub(self.e_ab, m));
        g_lc += g_p + dot(g_sum, sub(self.e_ac, m));
        // x = e_ab × e_ac.
        g_e_ab = add(g_e_ab, cross(self.e_ac, g_x));
        let mut g_e_ac = cross(g_x, self.e_ab);
        // Edge lengths.
        let g_bc = scale(sub(b, c), g_la / la);
        g_b = add(g_b, g_bc);
        g_c = sub(g_c, g_bc);
        g_e_ac = add(g_e_ac, scale(self.e_ac, g_lb / lb));
        g_e_ab = add(g_e_ab, scale(self.e_ab, g_lc / lc));
        // e_ab = b − a, e_ac = c − a.
        g_a = sub(sub(g_a, g_e_ab), g_e_ac);
        [g_a, add(g_b, g_e_ab), add(g_c, g_e_ac)]
    }
}

/// Sum of the adjacent faces' cross products per vertex (Eq. 9 before normalising), summed in
/// face order.
fn cross_sums(mesh: &OneRingMesh, faces: &[Face]) -> Vec<V3> {
    let mut sums = vec![[0.0; 3]; mesh.num_vertices];
    for (f, face) in mesh.faces.iter().zip(faces) {
        for &i in f {
            sums[i as usize] = add(sums[i as usize], face.cross);
        }
    }
    sums
}

/// What Eqs. 9–11 read of one vertex.
struct Vertex {
    position: V3,
    sum: V3,
    sum_norm: f32,
    /// Reference axis × normal, and its norm.
    axis: V3,
    u: V3,
    u_norm: f32,
    nearest: u32,
    edge: V3,
    edge_length: f32,
}

impl Vertex {
    fn new(v: &[f32], mesh: &OneRingMesh, sums: &[V3], i: usize) -> Self {
        let position = point(v, i as u32);
        let sum = sums[i];
        let sum_norm = norm(sum);
        let n = scale(sum, 1.0 / sum_norm);
        // Eq. 10: the axis least aligned with the normal (first of equals).
        let k = (1..3).fold(0, |k, j| if n[j].abs() < n[k].abs() { j } else { k });
        let mut axis = [0.0; 3];
        axis[k] = 1.0;
        let u = cross(axis, n);
        // Eq. 11: the shortest one-ring edge (first of equals, the vertex itself when isolated).
        let squared = |j: u32| {
            let d = sub(point(v, j), position);
            dot(d, d)
        };
        let ring = mesh.ring(i).iter().copied();
        let nearest = ring.min_by(|&a, &b| squared(a).total_cmp(&squared(b))).unwrap_or(i as u32);
        let edge = sub(point(v, nearest), position);
        Self { position, sum, sum_norm, axis, u, u_norm: norm(u), nearest, edge, edge_length: norm(edge) }
    }

    fn frame(&self) -> (V3, V3, V3) {
        let n = scale(self.sum, 1.0 / self.sum_norm);
        let t1 = scale(self.u, 1.0 / self.u_norm);
        (n, t1, cross(n, t1))
    }

    fn write(&self, row: Row) {
        let (n, t1, t2) = self.frame();
        write_row(row, self.position, t1, t2, n, VERTEX_SCALE as f32 * self.edge_length);
    }

    /// Gradients of (the summed face crosses, the vertex, the shortest edge) given the row's
    /// gradient.
    fn vjp(&self, g: RowGrad) -> (V3, V3, V3) {
        let (n, t1, _) = self.frame();
        let (g_mean, g_t1, g_t2, g_n, g_s) = read_row(g);
        let g_n = add(g_n, cross(t1, g_t2));
        let g_t1 = add(g_t1, cross(g_t2, n));
        let g_u = normalise_vjp(t1, self.u_norm, g_t1);
        // u = axis × n.
        let g_n = add(g_n, cross(g_u, self.axis));
        let g_sum = normalise_vjp(n, self.sum_norm, g_n);
        let g_edge = scale(self.edge, VERTEX_SCALE as f32 * g_s / self.edge_length);
        (g_sum, g_mean, g_edge)
    }
}

fn faces_of(v: &[f32], mesh: &OneRingMesh) -> Vec<Face> {
    mesh.faces.par_iter().map(|&f| Face::new(v, f)).collect()
}

fn vertices_of(v: &[f32], mesh: &OneRingMesh, sums: &[V3]) -> Vec<Vertex> {
    (0..mesh.num_vertices).into_par_iter().map(|i| Vertex::new(v, mesh, sums, i)).collect()
}

/// Gaussians `[G · PACKED]` of vertices `[V · 3]` as [`PLANES`]: face Gaussians first, then
/// vertex ones.
pub(crate) fn forward(v: &[f32], config: &BindConfig) -> Vec<f32> {
    let t = &config.mesh;
    let faces = faces_of(v, t);
    let g = config.num_gaussians();
    let mut out = vec![0.0; PACKED * g];
    let split = if config.face_gaussians { faces.len() } else { 0 };
    rows_mut(&mut out, g, 0..split).zip(&faces).for_each(|(row, face)| face.write(row));
    if config.vertex_gaussians {
        let vertices = vertices_of(v, t, &cross_sums(t, &faces));
        rows_mut(&mut out, g, split..g).zip(&vertices).for_each(|(row, vertex)| vertex.write(row));
    }
    out
}

/// The gradient `[V · 3]` of the vertices given the gradient `grad` of [`forward`]'s output.
pub(crate) fn backward(v: &[f32], grad: &[f32], config: &BindConfig) -> Vec<f32> {
    let t = &config.mesh;
    let faces = faces_of(v, t);
    let g = config.num_gaussians();
    let mut d = vec![0.0f32; 3 * t.num_vertices];
    let mut add_to = |i: u32, g: V3| {
        for k in 0..3 {
            d[3 * i as usize + k] += g[k];
        }
    };
    let split = if config.face_gaussians { faces.len() } else { 0 };
    // Vertex Gaussians first: their normals' gradient lands on the adjacent faces' crosses.
    let mut g_sums = vec![[0.0; 3]; t.num_vertices];
    if config.vertex_gaussians {
        let vertices = vertices_of(v, t, &cross_sums(t, &faces));
        let grads: Vec<(V3, V3, V3)> =
            vertices.par_iter().enumerate().map(|(i, x)| x.vjp(row_grad(grad, g, split + i))).collect();
        for (i, (x, (g_sum, g_mean, g_edge))) in vertices.iter().zip(grads).enumerate() {
            g_sums[i] = g_sum;
            add_to(i as u32, sub(g_mean, g_edge));
            add_to(x.nearest, g_edge);
        }
    }
    let corner_grads: Vec<[V3; 3]> = faces
        .par_iter()
        .zip(&t.faces)
        .enumerate()
        .map(|(k, (face, f))| {
            let row = config.face_gaussians.then(|| row_grad(grad, g, k));
            let g_cross = f.iter().fold([0.0; 3], |s, &i| add(s, g_sums[i as usize]));
            face.vjp(row, g_cross)
        })
        .collect();
    for (f, g) in t.faces.iter().zip(corner_grads) {
        for (&i, g) in f.iter().zip(g) {
            add_to(i, g);
        }
    }
    d
}
