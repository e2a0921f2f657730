//! Self-collision: vertex–triangle contacts (Eq. 3.22) and edge–edge contacts, each keeping the
//! thickness h between the cloth's layers on the side each pair was on at the start of the
//! substep, and a safe step that keeps any pair from passing through in between.
//!
//! Candidate pairs come from trees over the boxes of the elements: a pair left out stays farther
//! apart than the reach h + s over the whole move, so only candidates need holding
//! ([`SafeStep`]), and their distances at the end of one substep are the next substep's contacts.
//! The trees are walked once every few substeps, for every pair that can come within reach while
//! each particle keeps near its predicted path ([`Anchor`]), and each substep takes from those the
//! pairs its moves bring within reach; the pairs of a particle that strayed from its path are
//! looked for afresh in the trees until the next anchor. Every frame anchors first where the
//! cloth is and how it moves, so a saved state of positions and velocities resumes the same run.

mod anchor;
mod apart;
mod edge_edge;
mod ends;
mod neighbours;
mod orientation;
mod push;
mod safe_step;
mod search;
mod vertex_triangle;

use crate::box_hash::Aabb;
use anchor::Anchor;
use edge_edge::EdgeEdge;
use ends::Ends;
use neighbours::Neighbours;
use push::Reach;
use safe_step::{Closing, SafeStep};
use search::Search;
use vertex_triangle::VertexTriangle;

/// The slack s is this many thicknesses: the contacts of one substep are the pairs that came
/// within h + s in the one before, so a wider reach catches faster pairs but holds more.
const THICKNESS_SLACK: f32 = 0.2;

#[derive(Debug)]
pub(crate) struct SelfContacts {
    neighbours: Neighbours,
    /// The cloth's start shape, uncrossed: what caps each pair's gap.
    start: Vec<[f32; 3]>,
    edges: Vec<[u32; 2]>,
    vertex_triangle: VertexTriangle,
    edge_edge: EdgeEdge,
    step: SafeStep,
    closing: Vec<Closing>,
    room: Vec<Aabb>,
    reach: Reach,
    anchor: Anchor,
    stale: bool,
    /// The cloth's particles come first, then the layers' under it.
    cloth: u32,
}

impl SelfContacts {
    /// Contacts of thickness h = `thickness` for a cloth of `edges` starting at `start`, whose
    /// particles past the first `cloth` are the layers' under it.
    pub fn new(thickness: f32, edges: Vec<[u32; 2]>, start: Vec<[f32; 3]>, cloth: u32) -> Self {
        Self {
            neighbours: Neighbours::new(&edges, start.len()),
            start,
            edges,
            vertex_triangle: VertexTriangle::default(),
            edge_edge: EdgeEdge::default(),
            step: SafeStep::default(),
            closing: Vec::new(),
            room: Vec::new(),
            reach: Reach { distance: (1.0 + THICKNESS_SLACK) * thickness, thickness },
            anchor: Anchor::default(),
            stale: true,
            cloth,
        }
    }

    /// Starts a frame: it anchors afresh at its first substep.
    pub fn begin_frame(&mut self) {
        self.stale = true;
    }

    /// Starts a substep of `dt` from `positions`, moving at `velocities`, with `remaining` of the
    /// frame left (this substep's included): anchors there if due. At a frame's start it finds
    /// the pairs within reach; else it notes the distances of the pairs the last substep found,
    /// which include those its moves were bringing near.
    pub fn begin_substep(
        &mut self,
        positions: &[[f32; 3]],
        velocities: &[[f32; 3]],
        (dt, remaining): (f32, f32),
        faces: &[[u32; 3]],
    ) {
        let search = Search::new(&self.start, faces, self.reach, &self.neighbours, self.cloth);
        if self.stale || self.anchor.is_spent() {
            self.anchor.set(positions, velocities, remaining, dt);
            self.vertex_triangle.watch(&self.anchor, search);
            self.edge_edge.watch(&self.anchor, search.over(&self.edges));
        }
        if self.stale {
            let still = Ends { from: positions, to: positions };
            self.vertex_triangle.find(still, &self.anchor, search);
            self.edge_edge.find(still, &self.anchor, search.over(&self.edges));
            self.stale = false;
        } else {
            self.vertex_triangle.measure(positions, faces);
            self.edge_edge.measure(positions, &self.edges);
        }
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
        self.vertex_triangle.project(positions, previous, inverse_mass, faces, self.reach.thickness);
        self.edge_edge.project(positions, previous, inverse_mass, &self.edges, self.reach.thickness);
    }

    /// Ends the substep, first: finds the pairs that can come within reach on the moves from
    /// `previous` to `positions`, among those watched, and afresh for the particles that strayed
    /// from their predicted paths.
    pub fn find_candidates(&mut self, positions: &[[f32; 3]], previous: &[[f32; 3]], faces: &[[u32; 3]]) {
        let ends = Ends { from: previous, to: positions };
        let search = Search::new(&self.start, faces, self.reach, &self.neighbours, self.cloth);
        self.anchor.advance(ends);
        self.vertex_triangle.find(ends, &self.anchor, search);
        self.edge_edge.find(ends, &self.anchor, search.over(&self.edges));
    }

    /// Ends the substep, second: holds the moves from `previous` to `positions` pair by pair
    /// ([`SafeStep`]), each particle kept within the box around its own move: the moves of
    /// pairs left out of the candidates then stay within what they were checked for, and a
    /// particle stays on the side of a flat floor that both ends of its move are on.
    pub fn hold(
        &mut self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        faces: &[[u32; 3]],
    ) {
        let ends = Ends { from: previous, to: positions };
        self.room.clear();
        self.room.extend((0..previous.len() as u32).map(|p| ends.swept(&[p])));
        self.closing.clear();
        self.vertex_triangle.closing(faces, &mut self.closing);
        self.edge_edge.closing(&self.edges, &mut self.closing);
        self.step.hold(positions, previous, inverse_mass, &self.closing, &self.room);
    }
}
