//! Vertex–triangle contacts (Eq. 3.22): a vertex q over a triangle (p₁, p₂, p₃) is kept its gap
//! from the triangle's plane, C = ±(q − p₁)·n − gap ≥ 0, on the side it belongs on.
//!
//! The side is the vertex's side at the start of the substep: the safe step keeps it from
//! passing through, so no side needs remembering across substeps, and a vertex going round the
//! triangle's edge simply changes side.

use glam::Vec3;
use rayon::prelude::*;

use super::anchor::Anchor;
use super::apart::Apart;
use super::ends::Ends;
use super::orientation::volume;
use super::push::{moved, push_apart};
use super::safe_step::Closing;
use super::search::Search;
use crate::box_hash::Aabb;
use crate::box_tree::{BoxTree, MovingBox};
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

/// A pair watched through a frame, with its distance d₀ at the anchor.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Watched {
    vertex: u32,
    triangle: u32,
    distance: f32,
}

#[derive(Debug, Clone, Default)]
pub(crate) struct VertexTriangle {
    pairs: Vec<Pair>,
    /// How far apart each pair is at the start of the substep.
    start: Vec<Apart>,
    watched: Vec<Watched>,
    boxes: Vec<MovingBox>,
    /// Each vertex's box.
    points: Vec<MovingBox>,
    /// The boxes around each triangle's and each vertex's move, grown by half the reach.
    swept: Vec<Aabb>,
    swept_points: Vec<Aabb>,
    /// Trees over the triangles' and the vertices' boxes.
    tree: BoxTree,
    vertices: BoxTree,
}

/// How far `vertex` is from the triangle `tri` at `positions`, the triangle first.
fn apart(positions: &[[f32; 3]], vertex: u32, tri: [u32; 3]) -> Apart {
    let ([a, b, c], q) =
        (tri.map(|i| Vec3::from(positions[i as usize])), Vec3::from(positions[vertex as usize]));
    Apart::between(at_barycentric(closest_barycentric(q, a, b, c), a, b, c), q)
}

/// The pair of `vertex` and `triangle` with its distance at the start of the substep `ends`, if
/// that distance less what the moves can close is within reach.
fn admit(ends: Ends, search: Search<[u32; 3]>, vertex: u32, triangle: u32) -> Option<(Pair, Apart)> {
    let tri = search.elements[triangle as usize];
    if !search.has_cloth(&[tri[0], tri[1], tri[2], vertex]) {
        return None;
    }
    let start = apart(ends.from, vertex, tri);
    (start.distance - ends.closing([tri[0], tri[1], tri[2], vertex]) < search.reach.distance).then(|| {
        let near = search.near.touch(&[vertex], &tri);
        let gap = search.reach.gap(near, apart(search.initial, vertex, tri).distance);
        (Pair { vertex, triangle, gap }, start)
    })
}

impl VertexTriangle {
    /// Refits the trees to the triangles' `boxes` and the vertices' `points`, ordering their
    /// leaves first ([`Search::order_leaves`]), and walks them for the pairs that may come
    /// within reach within `horizon`, the triangle not having the vertex as a corner.
    fn meeting(&mut self, search: Search<[u32; 3]>, horizon: f32) -> Vec<(u32, u32)> {
        let faces = search.elements;
        if !self.tree.is_ordered_for(faces.len()) {
            search.order_leaves(&mut self.tree, faces);
            let vertices: Vec<[u32; 1]> = (0..search.initial.len() as u32).map(|v| [v]).collect();
            search.order_leaves(&mut self.vertices, &vertices);
        }
        self.tree.refit(&self.boxes);
        self.vertices.refit(&self.points);
        let mut pairs = self.vertices.meeting_pairs(&self.tree, horizon, search.reach.distance);
        pairs.retain(|&(vertex, triangle)| !faces[triangle as usize].contains(&vertex));
        pairs
    }

    /// Watches, from `anchor` to its horizon, every pair whose boxes may come within reach
    /// while no particle strays farther than the allowance from its predicted path.
    pub fn watch(&mut self, anchor: &Anchor, search: Search<[u32; 3]>) {
        let (initial, faces) = (search.initial, search.elements);
        self.boxes.clear();
        self.boxes.extend(faces.iter().map(|t| anchor.moving(t)));
        self.points.clear();
        self.points.extend((0..initial.len() as u32).map(|v| anchor.moving(&[v])));
        let pairs = self.meeting(search, anchor.horizon);
        self.watched = pairs
            .into_par_iter()
            .filter_map(|(vertex, triangle)| {
                let tri = faces[triangle as usize];
                let distance = apart(anchor.places(), vertex, tri).distance;
                search.has_cloth(&[tri[0], tri[1], tri[2], vertex]).then_some(Watched {
                    vertex,
                    triangle,
                    distance,
                })
            })
            .collect();
    }

    /// The pairs of the substep `ends` that [`admit`] takes among those whose boxes around the
    /// moves come within reach: of those watched from `anchor`, and those with a particle that
    /// strayed, found afresh. A watched pair whose distance at the anchor, less how far its
    /// particles have moved apart since and what the moves can close, is beyond reach is passed
    /// over without its closest points.
    pub fn find(&mut self, ends: Ends, anchor: &Anchor, search: Search<[u32; 3]>) {
        let half = 0.5 * search.reach.distance;
        self.swept.clear();
        self.swept.extend(search.elements.iter().map(|t| ends.swept(t).inflated(half)));
        self.swept_points.clear();
        self.swept_points.extend((0..ends.from.len() as u32).map(|v| ends.swept(&[v]).inflated(half)));
        let (swept, points) = (&self.swept, &self.swept_points);
        let near = |w: &&Watched| {
            let tri = search.elements[w.triangle as usize];
            let [a, b, c] = tri;
            !anchor.strayed(&[a, b, c, w.vertex])
                && points[w.vertex as usize].overlaps(&swept[w.triangle as usize])
                && w.distance - anchor.apart(&[w.vertex], &tri) - ends.closing([a, b, c, w.vertex])
                    < search.reach.distance
        };
        let mut kept: Vec<(Pair, Apart)> = self
            .watched
            .par_iter()
            .filter(near)
            .filter_map(|w| admit(ends, search, w.vertex, w.triangle))
            .collect();
        if anchor.any_strayed() {
            kept.extend(self.strays(ends, anchor, search));
        }
        (self.pairs, self.start) = kept.into_iter().unzip();
    }

    /// The pairs with a particle that strayed from its path, whose boxes around the moves come
    /// within reach, that [`admit`] takes: each strayed vertex against every triangle, and each
    /// triangle with a strayed corner against every vertex that did not stray.
    fn strays(&mut self, ends: Ends, anchor: &Anchor, search: Search<[u32; 3]>) -> Vec<(Pair, Apart)> {
        let faces = search.elements;
        self.boxes.clear();
        self.boxes.extend(faces.iter().map(|t| MovingBox::still(ends.swept(t))));
        self.points.clear();
        self.points.extend((0..ends.from.len() as u32).map(|v| MovingBox::still(ends.swept(&[v]))));
        self.tree.refit(&self.boxes);
        self.vertices.refit(&self.points);
        let (boxes, points, reach) = (&self.boxes, &self.points, search.reach.distance);
        let (triangles, vertices) = (&self.tree, &self.vertices);
        // A layer's element meets only the cloth's.
        let near = |tree: &BoxTree, query: &MovingBox, particles: &[u32]| {
            let mut found = Vec::new();
            tree.near(query, reach, !search.has_cloth(particles), &mut found);
            found
        };
        let from_vertices = (0..points.len() as u32)
            .into_par_iter()
            .filter(|&v| anchor.strayed(&[v]))
            .flat_map_iter(|v| near(triangles, &points[v as usize], &[v]).into_iter().map(move |t| (v, t)));
        let from_triangles = (0..faces.len() as u32)
            .into_par_iter()
            .filter(|&t| anchor.strayed(&faces[t as usize]))
            .flat_map_iter(|t| {
                let others = near(vertices, &boxes[t as usize], &faces[t as usize])
                    .into_iter()
                    .filter(|&v| !anchor.strayed(&[v]));
                others.map(move |v| (v, t))
            });
        from_vertices
            .chain(from_triangles)
            .filter(|&(v, t)| !faces[t as usize].contains(&v))
            .filter_map(|(v, t)| admit(ends, search, v, t))
            .collect()
    }

    /// Notes how far apart each pair is at `positions`, the start of the substep.
    pub fn measure(&mut self, positions: &[[f32; 3]], faces: &[[u32; 3]]) {
        self.start.clear();
        self.start.par_extend(
            self.pairs.par_iter().map(|pair| apart(positions, pair.vertex, faces[pair.triangle as usize])),
        );
    }

    /// Each pair's particles, the triangle's corners then the vertex, with how far apart they are
    /// at the start of the substep.
    pub fn closing(&self, faces: &[[u32; 3]], out: &mut Vec<Closing>) {
        out.extend(self.pairs.iter().zip(&self.start).map(|(pair, &apart)| {
            let [a, b, c] = faces[pair.triangle as usize];
            Closing { particles: [a, b, c, pair.vertex], split: 3, apart }
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
        for (pair, start) in self.pairs.iter().zip(&self.start) {
            let tri = faces[pair.triangle as usize];
            let particles = [tri[0], tri[1], tri[2], pair.vertex];
            // A pair that cannot be within its gap is skipped before the cost of its closest points.
            if start.distance - moved(positions, previous, &tri) - moved(positions, previous, &[pair.vertex])
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
