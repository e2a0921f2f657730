//! Body collision: the body interpolated linearly across the substeps of a frame (as many as keep
//! its every vertex within a margin a substep), and every free particle pushed out to `margin`
//! from its surface, with Coulomb friction against the body's own motion there (the
//! position-level friction of Macklin et al. 2014, "Unified particle physics").
//!
//! Candidate triangles come from a hash of each triangle's box swept over a window of substeps:
//! the body's motion is known for the whole frame, so the swept box holds the triangle at every
//! moment of the window, and a particle only has to look in its own cell.

use glam::Vec3;
use rayon::prelude::*;

use crate::body::Body;
use crate::box_hash::{Aabb, BoxHash};
use crate::error::ClothError;
use mannequin_mesh::barycentric::{at_barycentric, closest_barycentric};

/// A window of substeps shares one hash while the body moves less than this fraction of a cell
/// in it, so the swept boxes stay about a cell in size.
const WINDOW_TRAVEL: f32 = 0.5;

/// The farthest a body vertex may move in one substep, in body margins: a body that moves farther
/// pushes a particle deeper than the margin it keeps in one go, and the cloth contacts, which have
/// the last word, can then hold it inside. A frame where the body moves faster takes more substeps.
const MAX_STEP_IN_MARGINS: f32 = 1.0;

/// The most substeps a fast frame takes, as a multiple of the settings' count: a body turning
/// 75° in 1/30 s asks for 10 times as many; past this, a frame where the body jumps (a cut in
/// the motion) would cost minutes.
const MAX_SUBSTEP_FACTOR: u32 = 16;

#[derive(Debug, Clone)]
pub(crate) struct BodyCollider {
    pub body: Body,
    start: Vec<Vec3>,
    end: Vec<Vec3>,
    /// Body vertices at the start and the end of the current substep.
    before: Vec<Vec3>,
    pub now: Vec<Vec3>,
    /// Unit face normals at `now`.
    pub normals: Vec<Vec3>,
    boxes: Vec<Aabb>,
    hash: BoxHash,
    substeps: u32,
    /// Substeps per hash window, and the substep where the current window ends.
    window: u32,
    window_end: u32,
    cell: f32,
    /// How far beyond a triangle's swept box a particle can need it: the margin plus the body's
    /// travel in one substep, which is how deep a moving body can push into a particle.
    reach: f32,
}

impl BodyCollider {
    pub fn new(body: Body) -> Self {
        Self {
            body,
            start: Vec::new(),
            end: Vec::new(),
            before: Vec::new(),
            now: Vec::new(),
            normals: Vec::new(),
            boxes: Vec::new(),
            hash: BoxHash::default(),
            substeps: 1,
            window: 1,
            window_end: 0,
            cell: 1.0,
            reach: 0.0,
        }
    }

    /// Takes the body's vertices at the start and the end of the frame, and returns the substeps
    /// the frame takes: at least `substeps`, and enough that no body vertex moves farther than
    /// [`MAX_STEP_IN_MARGINS`] margins in one (up to [`MAX_SUBSTEP_FACTOR`] times `substeps`).
    pub fn begin_frame(
        &mut self,
        start: &[[f32; 3]],
        end: &[[f32; 3]],
        substeps: u32,
        margin: f32,
    ) -> Result<u32, ClothError> {
        for (field, values) in [("body_start", start), ("body_end", end)] {
            if values.len() < self.body.vertices_needed || values.len() != start.len() {
                let reason = format!(
                    "{} vertices, but the body's faces need {} (and body_start and body_end must match)",
                    values.len(),
                    self.body.vertices_needed
                );
                return Err(ClothError::invalid(field, reason));
            }
            if let Some(index) = values.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
                return Err(ClothError::NonFiniteInput { field, index });
            }
        }
        self.start.clear();
        self.start.extend(start.iter().map(|&p| Vec3::from(p)));
        self.end.clear();
        self.end.extend(end.iter().map(|&p| Vec3::from(p)));
        let travel = self.start.iter().zip(&self.end).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
        let needed = (travel / (MAX_STEP_IN_MARGINS * margin)).ceil() as u32;
        let substeps = needed.clamp(substeps, MAX_SUBSTEP_FACTOR * substeps);
        self.substeps = substeps;
        let step = travel / substeps as f32;
        self.reach = margin + 2.0 * step;
        let extents: f32 = self
            .body
            .faces
            .iter()
            .map(|tri| Aabb::around(&tri.map(|i| self.start[i as usize])).extent().max_element())
            .sum();
        let mean_extent = extents / self.body.faces.len().max(1) as f32;
        self.cell = (mean_extent + 2.0 * self.reach).max(1e-4);
        self.window = match step > 0.0 {
            true => ((WINDOW_TRAVEL * self.cell / step) as u32).clamp(1, substeps),
            false => substeps,
        };
        self.window_end = 0;
        self.now.clone_from(&self.start);
        Ok(substeps)
    }

    /// Moves the body to the end of substep `k`; the positions at its start become `before`.
    pub fn advance(&mut self, k: u32) {
        std::mem::swap(&mut self.before, &mut self.now);
        let t = (k + 1) as f32 / self.substeps as f32;
        self.now.clear();
        self.now.extend(self.start.iter().zip(&self.end).map(|(&a, &b)| (1.0 - t) * a + t * b));
        self.normals.clear();
        let now = &self.now;
        self.normals.extend(self.body.faces.iter().map(|tri| {
            let [a, b, c] = tri.map(|i| now[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        }));
    }

    /// Rebuilds the hash when substep `k` starts a new window; says whether it did.
    pub fn rebuild_if_due(&mut self, k: u32) -> bool {
        if k < self.window_end {
            return false;
        }
        self.window_end = (k + self.window).min(self.substeps);
        let t = self.window_end as f32 / self.substeps as f32;
        let (start, end, before) = (&self.start, &self.end, &self.before);
        self.boxes.clear();
        self.boxes.extend(self.body.faces.iter().map(|tri| {
            let first = tri.map(|i| before[i as usize]);
            let last = tri.map(|i| (1.0 - t) * start[i as usize] + t * end[i as usize]);
            Aabb::around(&first).union(Aabb::around(&last)).inflated(self.reach)
        }));
        self.hash.build(&self.boxes, self.cell);
        true
    }

    /// Pushes every free particle out to `margin` from the body, with friction coefficient
    /// `friction` against the body's motion over the substep.
    pub fn project(
        &self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        margin: f32,
        friction: f32,
    ) {
        (positions, previous, inverse_mass).into_par_iter().for_each(|(x, &previous, &w)| {
            if w == 0.0 {
                return;
            }
            if let Some(moved) = self.push_out(Vec3::from(*x), Vec3::from(previous), margin, friction) {
                *x = moved.to_array();
            }
        });
    }

    /// Where a particle at `p` (at `previous` when the substep began) goes, if the body is nearer
    /// than `margin`.
    fn push_out(&self, p: Vec3, previous: Vec3, margin: f32, friction: f32) -> Option<Vec3> {
        let faces = &self.body.faces;
        let mut best: Option<(f32, usize, [f32; 3], Vec3)> = None;
        for &f in self.hash.query(p) {
            let f = f as usize;
            if !self.boxes[f].contains(p) {
                continue;
            }
            let [a, b, c] = faces[f].map(|i| self.now[i as usize]);
            let bary = closest_barycentric(p, a, b, c);
            let q = at_barycentric(bary, a, b, c);
            let d2 = (p - q).length_squared();
            if best.is_none_or(|(d, ..)| d2 < d) {
                best = Some((d2, f, bary, q));
            }
        }
        let (d2, face, bary, q) = best?;
        let normal = self.body.pseudo_normal(&self.now, &self.normals, face, bary);
        let away = p - q;
        let side = if away.dot(normal) >= 0.0 { 1.0 } else { -1.0 };
        let distance = side * d2.sqrt();
        if distance >= margin {
            return None;
        }
        let direction = match d2 > (1e-4 * margin).powi(2) {
            true => side * away / d2.sqrt(),
            false => normal.normalize_or_zero(),
        };
        let pushed = q + margin * direction;
        let [a, b, c] = faces[face].map(|i| self.before[i as usize]);
        let surface_motion = q - at_barycentric(bary, a, b, c);
        let slip = (pushed - previous) - surface_motion;
        let tangential = slip - slip.dot(direction) * direction;
        let depth = margin - distance;
        let length = tangential.length();
        let keep = match length <= friction * depth {
            true => 0.0,
            false => 1.0 - friction * depth / length,
        };
        Some(pushed - (1.0 - keep) * tangential)
    }
}
