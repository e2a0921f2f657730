//! Vertex–triangle contacts (Eq. 3.22): a vertex q over a triangle (p₁, p₂, p₃) is kept its gap
//! from the triangle's plane, C = ±(q − p₁)·n − gap ≥ 0, on the side it belongs on.
//!
//! The side is the vertex's side now, unless it passed through the triangle in this substep: when
//! its side at the start of the substep differs, the moment the four particles were coplanar is
//! found, and if the vertex was over the triangle then, it went through and belongs on its old
//! side. Each substep starts from positions where the contacts were resolved, so no side needs
//! remembering across substeps, and a vertex going round the triangle's edge simply changes side.

use glam::Vec3;
use rayon::prelude::*;

use super::crossing::{between, coplanar_time, volume};
use super::neighbours::Neighbours;
use super::push::{Reach, push_apart};
use crate::box_hash::{Aabb, BoxHash};
use mannequin_mesh::barycentric::{at_barycentric, closest_barycentric, plane_barycentric};

/// A vertex counts as over a triangle while its barycentric coordinates stay above this, so it
/// cannot slip between two neighbouring triangles through rounding.
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
    boxes: Vec<Aabb>,
    hash: BoxHash,
}

impl VertexTriangle {
    /// Every pair within reach at `reference`, the triangle not having the vertex as a corner.
    pub fn rebuild(&mut self, reference: &[[f32; 3]], faces: &[[u32; 3]], reach: Reach, near: &Neighbours) {
        let at = |i: u32| Vec3::from(reference[i as usize]);
        self.boxes.clear();
        self.boxes.extend(faces.iter().map(|t| Aabb::around(&t.map(at)).inflated(reach.distance)));
        let extents: f32 = self.boxes.iter().map(|b| b.extent().max_element()).sum();
        self.hash.build(&self.boxes, extents / self.boxes.len().max(1) as f32);
        let (hash, boxes) = (&self.hash, &self.boxes);
        let found: Vec<Vec<Pair>> = (0..reference.len() as u32)
            .into_par_iter()
            .map(|vertex| {
                let q = at(vertex);
                hash.containing(boxes, q)
                    .filter(|&t| !faces[t as usize].contains(&vertex))
                    .filter_map(|triangle| {
                        let tri = faces[triangle as usize];
                        let [a, b, c] = tri.map(at);
                        let closest = at_barycentric(closest_barycentric(q, a, b, c), a, b, c);
                        if (q - closest).length() > reach.distance {
                            return None;
                        }
                        Some(Pair { vertex, triangle, gap: reach.gap(near.touch(&[vertex], &tri)) })
                    })
                    .collect()
            })
            .collect();
        self.pairs.clear();
        self.pairs.extend(found.into_iter().flatten());
    }

    /// One Gauss–Seidel pass over the pairs, in their (vertex, triangle) order; `previous` holds
    /// the positions at the start of the substep.
    pub fn project(
        &self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        faces: &[[u32; 3]],
        most: f32,
    ) {
        for pair in &self.pairs {
            let tri = faces[pair.triangle as usize];
            let particles = [tri[0], tri[1], tri[2], pair.vertex];
            let now = particles.map(|i| Vec3::from(positions[i as usize]));
            let [a, b, c, q] = now;
            let normal = (b - a).cross(c - a).normalize_or_zero();
            if normal == Vec3::ZERO {
                continue;
            }
            let height = (q - a).dot(normal);
            let start = particles.map(|i| Vec3::from(previous[i as usize]));
            let (before, after) = (volume(start), volume(now));
            let crossed = before * after < 0.0 && {
                let [a, b, c, q] = between(start, now, coplanar_time(start, now));
                over(q, a, b, c)
            };
            let side = if crossed { before.signum() } else { height.signum() };
            let bary = plane_barycentric(q - height * normal, a, b, c);
            if !crossed && bary.iter().any(|&x| x < -FOOTPRINT_TOLERANCE) {
                continue;
            }
            let violation = (side * height - pair.gap).max(-most);
            if violation >= 0.0 {
                continue;
            }
            let bary = bary.map(|x| x.clamp(0.0, 1.0));
            let share = [-bary[0], -bary[1], -bary[2], 1.0];
            push_apart(positions, particles, inverse_mass, share, -violation * side * normal);
        }
    }
}

/// Whether `q`, on the plane of (a, b, c), lies over the triangle.
fn over(q: Vec3, a: Vec3, b: Vec3, c: Vec3) -> bool {
    plane_barycentric(q, a, b, c).iter().all(|&x| x >= -FOOTPRINT_TOLERANCE)
}
