//! Self-collision: vertex–triangle contacts (Eq. 3.22) and edge–edge contacts, each keeping the
//! thickness h between the cloth's layers on the side each pair was on at the start of the
//! substep, and displacement bounds that keep any pair from passing through in between.
//!
//! Candidate pairs come from spatial hashes of boxes inflated by h + s, rebuilt at the start of
//! every frame and again whenever the cloth has moved enough, relative to itself, that a pair left
//! out could have come within h. Every pair within reach at the start of a substep, and the
//! nearest a left-out pair can be, bound how far each particle may move in it. Nothing is
//! remembered from one frame to the next, so a saved state of positions and velocities resumes
//! the same run.

mod displacement_bounds;
mod edge_edge;
mod neighbours;
mod orientation;
mod push;
mod vertex_triangle;

use glam::Vec3;
use rayon::prelude::*;

use crate::box_hash::Aabb;
use displacement_bounds::DisplacementBounds;
use edge_edge::EdgeEdge;
use neighbours::Neighbours;
use push::Reach;
use vertex_triangle::VertexTriangle;

/// The slack s is this many thicknesses: a wider reach rebuilds less often but holds more pairs.
const THICKNESS_SLACK: f32 = 1.0;
/// The candidates are rebuilt once the cloth has moved, relative to itself, this share of the
/// slack: a left-out pair is then still farther than h.
const SLACK_USE: f32 = 0.9;

#[derive(Debug)]
pub(crate) struct SelfContacts {
    neighbours: Neighbours,
    edges: Vec<[u32; 2]>,
    vertex_triangle: VertexTriangle,
    edge_edge: EdgeEdge,
    bounds: DisplacementBounds,
    thickness: f32,
    slack: f32,
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
            bounds: DisplacementBounds::default(),
            thickness,
            slack: THICKNESS_SLACK * thickness,
            reference: Vec::new(),
            stale: true,
        }
    }

    /// Starts a frame: the candidates are rebuilt at its first substep.
    pub fn begin_frame(&mut self) {
        self.stale = true;
    }

    /// Starts a substep from `previous` (the last resolved positions): rebuilds the candidates if the frame just began or the cloth has moved too far
    /// since, and bounds every particle's move.
    pub fn begin_substep(&mut self, previous: &[[f32; 3]], faces: &[[u32; 3]]) {
        let reach = Reach { distance: self.thickness + self.slack, thickness: self.thickness };
        let mut moved = match self.stale {
            true => f32::INFINITY,
            false => spread(previous, &self.reference).extent().length(),
        };
        if moved > SLACK_USE * self.slack {
            self.vertex_triangle.rebuild(previous, faces, reach, &self.neighbours);
            self.edge_edge.rebuild(previous, &self.edges, reach, &self.neighbours);
            self.reference.clear();
            self.reference.extend_from_slice(previous);
            self.stale = false;
            moved = 0.0;
        } else {
            self.vertex_triangle.measure(previous, faces);
            self.edge_edge.measure(previous, &self.edges);
        }
        self.bounds.begin(previous, reach.distance - moved);
        self.vertex_triangle.meet(faces, &self.bounds);
        self.edge_edge.meet(&self.edges, &self.bounds);
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

    /// Ends the substep: each free particle's move, less the `common` motion, is pulled back
    /// within its bound.
    pub fn end_substep(
        &self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        common: Vec3,
    ) {
        self.bounds.limit(positions, previous, inverse_mass, common);
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
