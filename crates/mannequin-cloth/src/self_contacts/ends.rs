//! Where a substep's moves start and end, and what follows from the straight moves between:
//! the box that holds a set of particles all the way, and how far a pair can close.

use glam::Vec3;

use super::safe_step;
use crate::box_hash::Aabb;

/// Where a substep's moves start and end.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ends<'a> {
    pub from: &'a [[f32; 3]],
    pub to: &'a [[f32; 3]],
}

impl Ends<'_> {
    /// The most the distance between two elements of `particles` can fall along their moves.
    pub fn closing(&self, particles: [u32; 4]) -> f32 {
        safe_step::closing(
            particles.map(|p| Vec3::from(self.to[p as usize]) - Vec3::from(self.from[p as usize])),
        )
    }

    /// The box around `particles` at both ends of the move: it holds them all the way.
    pub fn swept(&self, particles: &[u32]) -> Aabb {
        let at = |k: usize| {
            let p = particles[k / 2] as usize;
            Vec3::from(if k.is_multiple_of(2) { self.from[p] } else { self.to[p] })
        };
        (1..2 * particles.len()).fold(Aabb { min: at(0), max: at(0) }, |b, k| {
            let x = at(k);
            Aabb { min: b.min.min(x), max: b.max.max(x) }
        })
    }
}
