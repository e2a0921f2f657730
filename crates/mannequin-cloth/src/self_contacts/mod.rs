//! Self-collision: vertex–triangle contacts (Eq. 3.22) and edge–edge contacts, each keeping the
//! thickness h between the cloth's layers, on the side each pair was on at the start of the
//! substep unless it got there without passing through.
//!
//! Candidate pairs come from spatial hashes of boxes inflated by h + s, rebuilt at the start of
//! every frame and again whenever the cloth has moved enough that a pair left out could have come
//! within h. The slack s bounds, between rebuilds, how far any two particles may move relative to
//! each other (relative to the common motion, so a garment carried fast by the body is not held
//! back): each substep's displacements are clamped to stay within reach of their common centre,
//! and the rebuild check watches the displacement since the last rebuild. Nothing is remembered
//! from one frame to the next, so a saved state of positions and velocities resumes the same run.

mod crossing;
mod edge_edge;
mod neighbours;
mod push;
mod vertex_triangle;

use glam::Vec3;
use rayon::prelude::*;

use crate::box_hash::Aabb;
use edge_edge::EdgeEdge;
use neighbours::Neighbours;
use push::Reach;
use vertex_triangle::VertexTriangle;

/// The slack s per frame is this many thicknesses, plus [`BODY_SLACK`] times the body's travel per
/// substep (the body can push two particles apart by that much within one substep).
const THICKNESS_SLACK: f32 = 2.0;
const BODY_SLACK: f32 = 4.0;
/// Of the slack, this share bounds the clamped prediction and the body's push; the rest covers
/// the small moves of the other constraints.
const SLACK_USE: f32 = 0.9;
#[derive(Debug, Clone)]
pub(crate) struct SelfContacts {
    neighbours: Neighbours,
    edges: Vec<[u32; 2]>,
    vertex_triangle: VertexTriangle,
    edge_edge: EdgeEdge,
    thickness: f32,
    slack: f32,
    /// The body's travel per substep in this frame.
    body_step: f32,
    /// Positions at the last rebuild.
    reference: Vec<[f32; 3]>,
    stale: bool,
}

impl SelfContacts {
    pub fn new(thickness: f32, edges: Vec<[u32; 2]>, vertex_count: usize) -> Self {
        Self {
            neighbours: Neighbours::new(&edges, vertex_count),
            edges,
            vertex_triangle: VertexTriangle::default(),
            edge_edge: EdgeEdge::default(),
            thickness,
            slack: THICKNESS_SLACK * thickness,
            body_step: 0.0,
            reference: Vec::new(),
            stale: true,
        }
    }

    /// Starts a frame in which the body moves up to `body_step` per substep: the slack grows with
    /// it, and the candidates are rebuilt at the first substep with fresh sides.
    pub fn begin_frame(&mut self, body_step: f32) {
        self.body_step = body_step;
        self.slack = THICKNESS_SLACK * self.thickness + BODY_SLACK * body_step;
        self.stale = true;
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
        if !self.stale && spread(positions, &self.reference).extent().length() <= self.budget() {
            return;
        }
        let reach = Reach { distance: self.thickness + self.slack, thickness: self.thickness };
        self.vertex_triangle.rebuild(previous, faces, reach, &self.neighbours);
        self.edge_edge.rebuild(previous, &self.edges, reach, &self.neighbours);
        self.reference.clear();
        self.reference.extend_from_slice(previous);
        self.stale = false;
    }

    /// How far two particles may close between rebuilds, besides the body's push and the other
    /// constraints' moves.
    fn budget(&self) -> f32 {
        SLACK_USE * self.slack - 2.0 * self.body_step
    }

    /// One pass over the vertex–triangle pairs, then one over the edge–edge pairs. A pair deeper
    /// than h on the wrong side is pushed at most h per pass: a full push out of a deep tangle
    /// would throw particles centimetres in one substep.
    pub fn project(
        &self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        faces: &[[u32; 3]],
    ) {
        self.vertex_triangle.project(positions, previous, inverse_mass, faces, self.thickness);
        self.edge_edge.project(positions, previous, inverse_mass, &self.edges, self.thickness);
    }
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
