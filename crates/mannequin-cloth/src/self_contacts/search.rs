//! What deciding whether a pair of elements is a substep's contact needs to know.

use super::neighbours::Neighbours;
use super::push::Reach;

#[derive(Debug, Clone, Copy)]
pub(super) struct Search<'a, E> {
    /// The cloth's start shape, uncrossed: what caps each pair's gap.
    pub initial: &'a [[f32; 3]],
    /// The elements: triangles, or edges.
    pub elements: &'a [E],
    pub reach: Reach,
    pub near: &'a Neighbours,
    /// Particles below this are the cloth's; the rest are the layers' under it, which meet only
    /// the cloth: a pair of the layers' particles alone is none of its contacts.
    pub cloth: u32,
}

impl<'a, E> Search<'a, E> {
    pub fn new(
        initial: &'a [[f32; 3]],
        elements: &'a [E],
        reach: Reach,
        near: &'a Neighbours,
        cloth: u32,
    ) -> Self {
        Search { initial, elements, reach, near, cloth }
    }

    /// The same search over other elements.
    pub fn over<F>(self, elements: &'a [F]) -> Search<'a, F> {
        Search { initial: self.initial, elements, reach: self.reach, near: self.near, cloth: self.cloth }
    }

    /// Whether a pair of these particles has one of the cloth's.
    pub fn has_cloth(&self, particles: &[u32]) -> bool {
        particles.iter().any(|&p| p < self.cloth)
    }
}
