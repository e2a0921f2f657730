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
}

impl<'a, E> Search<'a, E> {
    /// The same search over other elements.
    pub fn over<F>(self, elements: &'a [F]) -> Search<'a, F> {
        Search { initial: self.initial, elements, reach: self.reach, near: self.near }
    }
}
