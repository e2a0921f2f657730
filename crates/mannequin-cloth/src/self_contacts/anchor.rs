//! Where the cloth was at the start of a frame and how it was moving, so one walk of the trees
//! serves every substep of the frame: a Verlet list, with each particle's reach bounded by how
//! far it strays from its straight path rather than by how far it travels.
//!
//! Each particle is predicted to go on at its velocity, x̂(τ) = x₀ + v₀τ. While every particle
//! stays within [`ALLOWANCE`] of its prediction, two elements whose predicted boxes, each grown by
//! the allowance and by its own move over one substep, never come within reach of each other
//! ([`crate::box_tree::MovingBox`]) cannot have overlapping boxes around a substep's moves: the
//! pairs the walk finds are all a substep can need. Cloth carried along together has close
//! velocities, so it stays apart however fast it travels.
//!
//! A watched pair's distance at a substep's start is at least its distance d₀ at the anchor less
//! the largest difference between its particles' displacements since: cloth carried along
//! together keeps its d₀, and most pairs are passed over without their closest points.

use glam::Vec3;

use super::ends::Ends;
use crate::box_hash::Aabb;
use crate::box_tree::MovingBox;

/// The most a particle may stray from its predicted path, in metres, before the trees are walked
/// again: a wider allowance watches more pairs every substep, a narrower one walks more often.
pub(super) const ALLOWANCE: f32 = 0.001;
/// Substeps one anchor serves at most: over a longer span the velocities part further, so more
/// pairs are watched and more particles stray.
pub(super) const SPAN: u32 = 5;

#[derive(Debug, Clone, Default)]
pub(super) struct Anchor {
    place: Vec<[f32; 3]>,
    velocity: Vec<Vec3>,
    /// Each particle's displacement from the anchor at the start of the current substep.
    shift: Vec<Vec3>,
    /// Whether each particle has strayed beyond the allowance since the anchor: its pairs are
    /// looked for afresh until the next anchor.
    strayed: Vec<bool>,
    /// Whether any particle has.
    any_strayed: bool,
    /// The time from the anchor to the end of the last substep.
    elapsed: f32,
    /// How long after the anchor its pairs hold.
    pub horizon: f32,
    /// The length of a substep.
    dt: f32,
}

impl Anchor {
    /// Anchors at `positions` moving at `velocities`, for [`SPAN`] substeps of `dt` or the
    /// `remaining` time of the frame, whichever is shorter.
    pub fn set(&mut self, positions: &[[f32; 3]], velocities: &[[f32; 3]], remaining: f32, dt: f32) {
        self.place.clear();
        self.place.extend_from_slice(positions);
        self.velocity.clear();
        self.velocity.extend(velocities.iter().map(|&v| Vec3::from(v)));
        self.shift.clear();
        self.shift.resize(positions.len(), Vec3::ZERO);
        self.strayed.clear();
        self.strayed.resize(positions.len(), false);
        self.any_strayed = false;
        (self.elapsed, self.horizon, self.dt) = (0.0, remaining.min(SPAN as f32 * dt), dt);
    }

    /// Whether the anchor's span is over.
    pub fn is_spent(&self) -> bool {
        self.elapsed + 0.5 * self.dt > self.horizon
    }

    pub fn places(&self) -> &[[f32; 3]] {
        &self.place
    }

    /// The boxes around `particles`' places at the anchor, grown by the allowance and along each
    /// axis by their fastest move along it over a substep, and around their velocities.
    pub fn moving(&self, particles: &[u32]) -> MovingBox {
        let first = self.velocity[particles[0] as usize];
        let velocity = particles.iter().fold(Aabb { min: first, max: first }, |b, &p| {
            let v = self.velocity[p as usize];
            Aabb { min: b.min.min(v), max: b.max.max(v) }
        });
        let step = self.dt * velocity.min.abs().max(velocity.max.abs()) + Vec3::splat(ALLOWANCE);
        let place = Ends { from: &self.place, to: &self.place }.swept(particles);
        MovingBox { place: Aabb { min: place.min - step, max: place.max + step }, velocity }
    }

    /// Moves on by the substep `ends`: notes each particle's displacement at its start, and
    /// which particles are farther than the allowance from their predictions at either end (the
    /// safe step may have held a particle back from where the last substep checked it).
    pub fn advance(&mut self, ends: Ends) {
        let (start, end) = (self.elapsed, self.elapsed + self.dt);
        self.elapsed = end;
        for (p, (shift, strayed)) in self.shift.iter_mut().zip(&mut self.strayed).enumerate() {
            let (x, v) = (Vec3::from(self.place[p]), self.velocity[p]);
            let (from, to) = (Vec3::from(ends.from[p]), Vec3::from(ends.to[p]));
            *shift = from - x;
            let farthest = from.distance(x + start * v).max(to.distance(x + end * v));
            *strayed |= farthest > ALLOWANCE;
            self.any_strayed |= *strayed;
        }
    }

    /// Whether any of `particles` has strayed.
    pub fn strayed(&self, particles: &[u32]) -> bool {
        particles.iter().any(|&p| self.strayed[p as usize])
    }

    /// Whether any particle has strayed.
    pub fn any_strayed(&self) -> bool {
        self.any_strayed
    }

    /// The largest difference between the displacements of a particle of `a` and one of `b` at
    /// the start of the substep: the most their distance can have fallen since the anchor.
    pub fn apart(&self, a: &[u32], b: &[u32]) -> f32 {
        let s = |p: &u32| self.shift[*p as usize];
        a.iter().flat_map(|p| b.iter().map(move |q| s(p).distance(s(q)))).fold(0.0, f32::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Particles going on at their velocities stay on their paths; one pushed 2 cm aside strays. Two particles carried 10 cm together are not brought closer; one held still
    /// while the other moves 10 cm may have come 10 cm closer.
    #[test]
    fn strays_from_the_straight_path_and_displacements_apart() {
        let dt = 0.01;
        let start = [[0.0, 1.0, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 0.0]];
        let velocity = [[10.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let mut anchor = Anchor::default();
        anchor.set(&start, &velocity, 0.1, dt);
        let at = |p: usize, t: f32| (Vec3::from(start[p]) + t * Vec3::from(velocity[p])).to_array();
        let from = [at(0, 0.0), at(1, 0.0), at(2, 0.0)];
        let to = [at(0, dt), at(1, dt), at(2, dt)];
        anchor.advance(Ends { from: &from, to: &to });
        assert!(!anchor.any_strayed());
        let mut pushed = [at(0, 2.0 * dt), at(1, 2.0 * dt), at(2, 2.0 * dt)];
        pushed[2][2] += 0.02;
        anchor.advance(Ends { from: &to, to: &pushed });
        assert!(anchor.strayed(&[2]) && !anchor.strayed(&[0, 1]) && anchor.any_strayed());
        assert!(anchor.apart(&[0], &[1]) < 1e-6);
        assert!((anchor.apart(&[0, 1], &[2]) - 0.1).abs() < 1e-6, "{}", anchor.apart(&[0, 1], &[2]));
    }
}
