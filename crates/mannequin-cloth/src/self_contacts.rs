//! Self-collision (Eq. 3.22): a vertex q is kept at distance h (the thickness) from the plane of
//! any triangle (p₁, p₂, p₃) it lies over, C = ±(q − p₁)·n − h ≥ 0, on the side it came from.
//!
//! Candidate pairs come from a spatial hash of the triangles' boxes inflated by h + s, rebuilt at
//! the start of every frame and again whenever the cloth has moved enough that a pair it left out
//! could have come within h. The slack s bounds, between rebuilds, how far any two particles may
//! move relative to each other (relative to the common motion, so a garment carried fast by the
//! body is not held back): each substep's displacements are clamped to stay within s/2 of their
//! common centre, and the rebuild check watches the displacement since the last rebuild.
//!
//! A pair remembers which side of the triangle its vertex is on. While the vertex is over the
//! triangle, the side never changes, so a vertex pushed through in one substep is pushed back to
//! its own side; when it is beside the triangle (where passing the plane is no crossing) the side
//! follows it. At a mid-frame rebuild, pairs that persist keep their sides. The sides are taken
//! afresh from the positions at the start of each frame, so a saved state of positions and
//! velocities resumes the same run.

use glam::Vec3;
use rayon::prelude::*;

use crate::barycentric::{at_barycentric, closest_barycentric, plane_barycentric};
use crate::box_hash::{Aabb, BoxHash};

/// The slack s per frame is this many thicknesses, plus [`BODY_SLACK`] times the body's travel per
/// substep (the body can push two particles apart by that much within one substep).
const THICKNESS_SLACK: f32 = 2.0;
const BODY_SLACK: f32 = 4.0;
/// Of the slack, this share bounds the clamped prediction and the body's push; the rest covers
/// the small moves of the other constraints.
const SLACK_USE: f32 = 0.9;
/// A vertex counts as over a triangle while its barycentric coordinates stay above this, so it
/// cannot slip between two neighbouring triangles through rounding.
const FOOTPRINT_TOLERANCE: f32 = 1e-3;

#[derive(Debug, Clone, Copy, PartialEq)]
struct Pair {
    vertex: u32,
    triangle: u32,
    /// +1 or −1: the side of the triangle's normal the vertex belongs on.
    side: f32,
}

#[derive(Debug, Clone, Default)]
pub(crate) struct SelfContacts {
    /// Each vertex's neighbours along edges, sorted: `neighbours[starts[v]..starts[v + 1]]`.
    starts: Vec<u32>,
    neighbours: Vec<u32>,
    thickness: f32,
    slack: f32,
    /// The body's travel per substep in this frame.
    body_step: f32,
    /// Positions at the last rebuild.
    reference: Vec<[f32; 3]>,
    pairs: Vec<Pair>,
    stale: bool,
    boxes: Vec<Aabb>,
    hash: BoxHash,
}

impl SelfContacts {
    pub fn new(thickness: f32, edges: &[[u32; 2]], vertex_count: usize) -> Self {
        let mut starts = vec![0u32; vertex_count + 1];
        for &[a, b] in edges {
            starts[a as usize + 1] += 1;
            starts[b as usize + 1] += 1;
        }
        for v in 0..vertex_count {
            starts[v + 1] += starts[v];
        }
        let mut next = starts.clone();
        let mut neighbours = vec![0u32; 2 * edges.len()];
        for &[a, b] in edges {
            for (from, to) in [(a, b), (b, a)] {
                neighbours[next[from as usize] as usize] = to;
                next[from as usize] += 1;
            }
        }
        for v in 0..vertex_count {
            neighbours[starts[v] as usize..starts[v + 1] as usize].sort_unstable();
        }
        Self { starts, neighbours, thickness, stale: true, ..Self::default() }
    }

    /// Whether triangle `tri` has `vertex` or one of its neighbours as a corner. Such pairs are
    /// left to the stretch and bending constraints: within one layer, a little compression brings
    /// a vertex over its neighbours' triangles with no side to tell apart.
    fn adjacent(&self, vertex: u32, tri: [u32; 3]) -> bool {
        let ring = &self.neighbours
            [self.starts[vertex as usize] as usize..self.starts[vertex as usize + 1] as usize];
        tri.iter().any(|&v| v == vertex || ring.binary_search(&v).is_ok())
    }

    /// Starts a frame in which the body moves up to `body_step` per substep: the slack grows with
    /// it, and the candidates are rebuilt at the first substep with fresh sides.
    pub fn begin_frame(&mut self, body_step: f32) {
        self.body_step = body_step;
        self.slack = THICKNESS_SLACK * self.thickness + BODY_SLACK * body_step;
        self.stale = true;
        self.pairs.clear();
    }

    /// Clamps this substep's predicted displacements (free particles only) to within d of their
    /// common centre on each axis, with d chosen so that, with the body's push, no two particles
    /// close by more than the slack in one substep.
    pub fn bound_displacements(
        &self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
    ) {
        let limit = self.budget() / (2.0 * 3f32.sqrt());
        let moved = spread(positions, previous);
        if moved.extent().max_element() <= 2.0 * limit {
            return;
        }
        let centre = 0.5 * (moved.min + moved.max);
        let (lo, hi) = (centre - limit, centre + limit);
        (positions, previous, inverse_mass).into_par_iter().for_each(|(x, p, &w)| {
            if w > 0.0 {
                let p = Vec3::from(*p);
                *x = (p + (Vec3::from(*x) - p).clamp(lo, hi)).to_array();
            }
        });
    }

    /// Rebuilds the candidates from `previous` (the last resolved positions) if the frame just
    /// began or if the motion since the last rebuild, up to `positions`, could have brought a
    /// left-out pair within h.
    pub fn refresh(&mut self, positions: &[[f32; 3]], previous: &[[f32; 3]], faces: &[[u32; 3]]) {
        if self.stale || spread(positions, &self.reference).extent().length() > self.budget() {
            self.rebuild(previous, faces);
        }
    }

    /// How far two particles may close between rebuilds, besides the body's push and the other
    /// constraints' moves.
    fn budget(&self) -> f32 {
        SLACK_USE * self.slack - 2.0 * self.body_step
    }

    /// Lists every (vertex, triangle) pair within h + s at `reference`, the triangle not
    /// [adjacent](Self::adjacent) to the vertex, with the vertex's side: kept from the current list for pairs already
    /// in it (unless the frame just began), else taken from `reference`.
    fn rebuild(&mut self, reference: &[[f32; 3]], faces: &[[u32; 3]]) {
        let reach = self.thickness + self.slack;
        let at = |i: u32| Vec3::from(reference[i as usize]);
        self.boxes.clear();
        self.boxes.extend(faces.iter().map(|t| Aabb::around(&t.map(at)).inflated(reach)));
        let extents: f32 = self.boxes.iter().map(|b| b.extent().max_element()).sum();
        self.hash.build(&self.boxes, extents / self.boxes.len().max(1) as f32);
        let old = if self.stale { Vec::new() } else { std::mem::take(&mut self.pairs) };
        let (hash, boxes, this) = (&self.hash, &self.boxes, &*self);
        let found: Vec<Vec<Pair>> = (0..reference.len() as u32)
            .into_par_iter()
            .map(|vertex| {
                let q = at(vertex);
                let mut near: Vec<u32> = hash
                    .query(q)
                    .iter()
                    .copied()
                    .filter(|&t| boxes[t as usize].contains(q) && !this.adjacent(vertex, faces[t as usize]))
                    .collect();
                near.sort_unstable();
                near.dedup();
                near.into_iter()
                    .filter_map(|triangle| {
                        let [a, b, c] = faces[triangle as usize].map(at);
                        let closest = at_barycentric(closest_barycentric(q, a, b, c), a, b, c);
                        if (q - closest).length() > reach {
                            return None;
                        }
                        let side =
                            match old.binary_search_by_key(&(vertex, triangle), |p| (p.vertex, p.triangle)) {
                                Ok(k) => old[k].side,
                                Err(_) => side_of(q, a, b, c),
                            };
                        Some(Pair { vertex, triangle, side })
                    })
                    .collect()
            })
            .collect();
        self.pairs.clear();
        self.pairs.extend(found.into_iter().flatten());
        self.reference.clear();
        self.reference.extend_from_slice(reference);
        self.stale = false;
    }

    /// One Gauss–Seidel pass over the candidate pairs, in their (vertex, triangle) order.
    pub fn project(&mut self, positions: &mut [[f32; 3]], inverse_mass: &[f32], faces: &[[u32; 3]]) {
        let h = self.thickness;
        for pair in &mut self.pairs {
            let tri = faces[pair.triangle as usize];
            let q = Vec3::from(positions[pair.vertex as usize]);
            let [a, b, c] = tri.map(|i| Vec3::from(positions[i as usize]));
            let normal = (b - a).cross(c - a).normalize_or_zero();
            if normal == Vec3::ZERO {
                continue;
            }
            let height = (q - a).dot(normal);
            let bary = plane_barycentric(q - height * normal, a, b, c);
            if bary.iter().any(|&x| x < -FOOTPRINT_TOLERANCE) {
                if height != 0.0 {
                    pair.side = height.signum();
                }
                continue;
            }
            // A vertex deeper than h on the wrong side is pushed at most h per pass: the full
            // push, from a side remembered across a fold, threw particles centimetres in one
            // substep and the pile blew up (the strip test, about frame 35).
            let violation = (pair.side * height - h).max(-h);
            if violation >= 0.0 {
                continue;
            }
            let wq = inverse_mass[pair.vertex as usize];
            let w = tri.map(|i| inverse_mass[i as usize]);
            let weight = wq + (0..3).map(|k| w[k] * bary[k] * bary[k]).sum::<f32>();
            if weight == 0.0 {
                continue;
            }
            // No particle moves farther than the violation itself: where only a triangle corner
            // near the foot's far side is free (bary ≈ 0), the exact projection would throw it
            // by violation / bary and blow up the state.
            let largest = wq.max((0..3).map(|k| w[k] * bary[k]).fold(0.0, f32::max));
            let push = -violation / weight.max(largest) * pair.side * normal;
            positions[pair.vertex as usize] = (q + wq * push).to_array();
            for k in 0..3 {
                let p = Vec3::from(positions[tri[k] as usize]);
                positions[tri[k] as usize] = (p - w[k] * bary[k] * push).to_array();
            }
        }
    }
}

/// The side of triangle (a, b, c)'s plane that `q` is on; +1 on the plane.
fn side_of(q: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    if (q - a).dot((b - a).cross(c - a)) < 0.0 { -1.0 } else { 1.0 }
}

/// The box around every particle's displacement from `from` to `to`.
fn spread(to: &[[f32; 3]], from: &[[f32; 3]]) -> Aabb {
    let empty = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };
    (to, from)
        .into_par_iter()
        .map(|(x, p)| {
            let d = Vec3::from(*x) - Vec3::from(*p);
            Aabb { min: d, max: d }
        })
        .reduce(|| empty, Aabb::union)
}
