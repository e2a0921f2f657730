//! Vertex–triangle contacts (Eq. 3.22): a vertex q over a triangle (p₁, p₂, p₃) is kept its gap
//! from the triangle's plane, C = ±(q − p₁)·n − gap ≥ 0, on the side it belongs on.
//!
//! The side is the vertex's side at the start of the substep: the safe step keeps it from
//! passing through, so no side needs remembering across substeps, and a vertex going round the
//! triangle's edge simply changes side.

use glam::Vec3;
use rayon::prelude::*;

use super::ends::Ends;
use super::neighbours::Neighbours;
use super::orientation::volume;
use super::push::{Reach, moved, push_apart};
use super::safe_step::Closing;
use crate::box_hash::Aabb;
use crate::box_tree::BoxTree;
use mannequin_mesh::barycentric::{at_barycentric, closest_barycentric, plane_barycentric};

/// A vertex counts as over a triangle while its barycentric coordinates stay above this, so it
/// is pushed by both neighbouring triangles at their common edge.
const FOOTPRINT_TOLERANCE: f32 = 1e-3;

#[derive(Debug, Clone, Copy, PartialEq)]
struct Pair {
    vertex: u32,
    triangle: u32,
    gap: f32,
}

#[derive(Debug, Clone, Default)]
pub(crate) struct VertexTriangle {
    pairs: Vec<Pair>,
    /// Each pair's distance at the start of the substep.
    start: Vec<f32>,
    boxes: Vec<Aabb>,
    /// Each vertex's box around its move, inflated by half the reach.
    swept: Vec<Aabb>,
    /// Trees over the triangles' and the vertices' boxes.
    tree: BoxTree,
    vertices: BoxTree,
}

/// The distance from `vertex` to the triangle `tri` at `positions`.
fn distance(positions: &[[f32; 3]], vertex: u32, tri: [u32; 3]) -> f32 {
    let ([a, b, c], q) =
        (tri.map(|i| Vec3::from(positions[i as usize])), Vec3::from(positions[vertex as usize]));
    (q - at_barycentric(closest_barycentric(q, a, b, c), a, b, c)).length()
}

impl VertexTriangle {
    /// Every pair, the triangle not having the vertex as a corner, that can come within reach
    /// while moving straight from `from` to `to` (their boxes around both, inflated by half the
    /// reach, overlap, and its distance at `from` less what its moves can close is within
    /// reach), with its distance at `from`; `initial` is the cloth's start shape, which
    /// caps each pair's gap.
    pub fn rebuild(
        &mut self,
        ends: Ends,
        initial: &[[f32; 3]],
        faces: &[[u32; 3]],
        reach: Reach,
        near: &Neighbours,
    ) {
        let half = 0.5 * reach.distance;
        self.swept.clear();
        self.swept.extend((0..ends.from.len() as u32).map(|v| ends.swept(&[v]).inflated(half)));
        self.boxes.clear();
        self.boxes.extend(faces.iter().map(|t| ends.swept(t).inflated(half)));
        if !self.tree.is_ordered_for(faces.len()) {
            let start = Ends { from: initial, to: initial };
            self.tree.order_leaves(&faces.iter().map(|t| start.swept(t)).collect::<Vec<_>>());
            self.vertices
                .order_leaves(&(0..initial.len() as u32).map(|v| start.swept(&[v])).collect::<Vec<_>>());
        }
        self.tree.refit(&self.boxes);
        self.vertices.refit(&self.swept);
        let found: Vec<(Pair, f32)> = self
            .vertices
            .overlapping_pairs(&self.tree)
            .into_par_iter()
            .filter_map(|(vertex, triangle)| {
                let tri = faces[triangle as usize];
                if tri.contains(&vertex) {
                    return None;
                }
                let start = distance(ends.from, vertex, tri);
                (start - ends.closing([tri[0], tri[1], tri[2], vertex]) < reach.distance).then(|| {
                    let gap = reach.gap(near.touch(&[vertex], &tri), distance(initial, vertex, tri));
                    (Pair { vertex, triangle, gap }, start)
                })
            })
            .collect();
        (self.pairs, self.start) = found.into_iter().unzip();
    }

    /// Notes each pair's distance at `positions`, the start of the substep.
    pub fn measure(&mut self, positions: &[[f32; 3]], faces: &[[u32; 3]]) {
        self.start.clear();
        self.start.par_extend(
            self.pairs.par_iter().map(|pair| distance(positions, pair.vertex, faces[pair.triangle as usize])),
        );
    }

    /// Each pair's particles, the triangle's corners then the vertex, with its distance at the
    /// start of the substep.
    pub fn closing(&self, faces: &[[u32; 3]], out: &mut Vec<Closing>) {
        out.extend(self.pairs.iter().zip(&self.start).map(|(pair, &distance)| {
            let [a, b, c] = faces[pair.triangle as usize];
            ([a, b, c, pair.vertex], distance)
        }));
    }

    /// One Gauss–Seidel pass over the pairs, in their (vertex, triangle) order; `previous` holds
    /// the positions at the start of the substep, which say each vertex's side. A vertex over the
    /// triangle is kept its gap from the plane on its side; one beside it, from the nearest
    /// point of the triangle's rim, so no pair closes in unseen through its edges.
    pub fn project(
        &self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        faces: &[[u32; 3]],
        most: f32,
    ) {
        for (pair, &start) in self.pairs.iter().zip(&self.start) {
            let tri = faces[pair.triangle as usize];
            let particles = [tri[0], tri[1], tri[2], pair.vertex];
            // A pair that cannot be within its gap is skipped before the cost of its closest points.
            if start - moved(positions, previous, &tri) - moved(positions, previous, &[pair.vertex])
                >= pair.gap
            {
                continue;
            }
            let [a, b, c, q] = particles.map(|i| Vec3::from(positions[i as usize]));
            let normal = (b - a).cross(c - a).normalize_or_zero();
            if normal == Vec3::ZERO {
                continue;
            }
            let height = (q - a).dot(normal);
            let over = plane_barycentric(q - height * normal, a, b, c);
            let (bary, direction, distance) = if over.iter().all(|&x| x >= -FOOTPRINT_TOLERANCE) {
                let side = volume(particles.map(|i| Vec3::from(previous[i as usize]))).signum();
                (over.map(|x| x.clamp(0.0, 1.0)), side * normal, side * height)
            } else {
                let bary = closest_barycentric(q, a, b, c);
                let away = q - at_barycentric(bary, a, b, c);
                let distance = away.length();
                if distance <= f32::MIN_POSITIVE {
                    continue;
                }
                (bary, away / distance, distance)
            };
            let violation = (distance - pair.gap).max(-most);
            if violation >= 0.0 {
                continue;
            }
            let share = [-bary[0], -bary[1], -bary[2], 1.0];
            push_apart(positions, particles, inverse_mass, share, -violation * direction);
        }
    }
}
