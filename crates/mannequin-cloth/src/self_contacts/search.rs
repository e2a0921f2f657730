//! What deciding whether a pair of elements is a substep's contact needs to know.

use super::ends::Ends;
use super::neighbours::Neighbours;
use super::push::Reach;
use crate::box_tree::BoxTree;

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

    /// Orders `tree`'s leaves for `elements` (each a few particles) by where they are in the
    /// cloth's start shape, the cloth's elements before the layers'.
    pub fn order_leaves<const K: usize>(&self, tree: &mut BoxTree, elements: &[[u32; K]]) {
        let start = Ends { from: self.initial, to: self.initial };
        let boxes: Vec<_> = elements.iter().map(|e| start.swept(e)).collect();
        let cloth: Vec<bool> = elements.iter().map(|e| self.has_cloth(e)).collect();
        tree.order_leaves(&boxes, &cloth);
    }
}
