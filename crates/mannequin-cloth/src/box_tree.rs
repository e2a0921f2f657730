//! A bounding-box tree over a cloth's elements for finding the boxes a query box overlaps. The
//! leaves are put in order once, along a Morton curve through the elements' first boxes, and only
//! the boxes are refitted after that: elements next to each other in the cloth stay next to each
//! other however it moves, so the tree stays tight enough, and a query walks a few dozen nodes
//! where a grid walks every box listed in the cells it covers.

use glam::Vec3;

use crate::box_hash::Aabb;

/// A box no query overlaps: the padding past the last leaf.
const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

#[derive(Debug, Clone, Default)]
pub(crate) struct BoxTree {
    /// The element at each leaf, in Morton order.
    order: Vec<u32>,
    /// A complete binary tree: node i has children 2i and 2i + 1, the leaves are nodes
    /// `leaves..2 · leaves`, and node 0 is unused.
    nodes: Vec<Aabb>,
    leaves: usize,
}

/// Spreads the low 10 bits of `x` to every third bit.
fn spread(x: u32) -> u32 {
    let mut x = x & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    (x | (x << 2)) & 0x0924_9249
}

impl BoxTree {
    /// Whether the leaves are in order for `elements` elements.
    pub fn is_ordered_for(&self, elements: usize) -> bool {
        self.order.len() == elements && elements > 0
    }

    /// Refits the tree to `boxes`, one per element of those the leaves were ordered for.
    pub fn refit(&mut self, boxes: &[Aabb]) {
        debug_assert_eq!(self.order.len(), boxes.len(), "the leaves are ordered for other elements");
        for (k, &e) in self.order.iter().enumerate() {
            self.nodes[self.leaves + k] = boxes[e as usize];
        }
        for i in (1..self.leaves).rev() {
            self.nodes[i] = self.nodes[2 * i].union(self.nodes[2 * i + 1]);
        }
    }

    /// Orders the leaves along a Morton curve through `boxes`, one per element: a cloth's start
    /// shape, so that a run resumed from a checkpoint walks its pairs in the same order.
    pub fn order_leaves(&mut self, boxes: &[Aabb]) {
        let centre = |b: &Aabb| 0.5 * (b.min + b.max);
        let all = boxes.iter().fold(EMPTY, |a, b| a.union(*b));
        let scale = 1023.0 / all.extent().max_element().max(f32::MIN_POSITIVE);
        let code = |b: &Aabb| {
            let q = ((centre(b) - all.min) * scale).as_uvec3();
            spread(q.x) | (spread(q.y) << 1) | (spread(q.z) << 2)
        };
        let mut keyed: Vec<(u32, u32)> = boxes.iter().enumerate().map(|(k, b)| (code(b), k as u32)).collect();
        keyed.sort_unstable();
        self.order = keyed.into_iter().map(|(_, k)| k).collect();
        self.leaves = boxes.len().next_power_of_two();
        self.nodes = vec![EMPTY; 2 * self.leaves];
    }

    /// Every pair (a of `self`, b of `other`) whose boxes overlap, once; with `other` the same
    /// tree, every unordered pair of two elements once, as (a, b) or (b, a). Walks both trees
    /// together, so a pair of subtrees apart is passed over at once; the top of the walk runs in
    /// parallel.
    pub fn overlapping_pairs(&self, other: &BoxTree) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        if !self.order.is_empty() && !other.order.is_empty() {
            self.walk(other, std::ptr::eq(self, other), (1, 1), &mut out);
        }
        out
    }

    fn is_leaf(&self, node: usize) -> bool {
        node >= self.leaves
    }

    fn walk(&self, other: &BoxTree, same: bool, (a, b): (usize, usize), out: &mut Vec<(u32, u32)>) {
        if !self.nodes[a].overlaps(&other.nodes[b]) {
            return;
        }
        let split = |x: (usize, usize), y: (usize, usize), out: &mut Vec<(u32, u32)>| {
            // Near the root each half is a large share of the work: run the two in parallel.
            if a.max(b) < PARALLEL_ABOVE {
                let mut more = Vec::new();
                rayon::join(|| self.walk(other, same, x, out), || self.walk(other, same, y, &mut more));
                out.append(&mut more);
            } else {
                self.walk(other, same, x, out);
                self.walk(other, same, y, out);
            }
        };
        if same && a == b {
            if !self.is_leaf(a) {
                let mut inner = Vec::new();
                split((2 * a, 2 * a), (2 * a + 1, 2 * a + 1), out);
                self.walk(other, same, (2 * a, 2 * a + 1), &mut inner);
                out.append(&mut inner);
            }
            return;
        }
        match (self.is_leaf(a), other.is_leaf(b)) {
            (true, true) => {
                if let (Some(&x), Some(&y)) =
                    (self.order.get(a - self.leaves), other.order.get(b - other.leaves))
                {
                    out.push((x, y));
                }
            }
            (false, true) => split((2 * a, b), (2 * a + 1, b), out),
            (true, false) => split((a, 2 * b), (a, 2 * b + 1), out),
            (false, false) if a.ilog2() <= b.ilog2() => split((2 * a, b), (2 * a + 1, b), out),
            (false, false) => split((a, 2 * b), (a, 2 * b + 1), out),
        }
    }
}

/// Nodes above this index (the top six levels) split their walk in two parallel tasks.
const PARALLEL_ABOVE: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;

    fn scattered(count: usize, shift: f32) -> Vec<Aabb> {
        (0..count)
            .map(|k| {
                let f = k as f32;
                let min = Vec3::new((f * 0.37 + shift).sin(), (f * 0.91).cos(), (f * 0.13).sin()) * 0.5;
                let size = Vec3::new(0.01 + 0.1 * (f * 0.7).sin().abs(), 0.05, 0.02 * (k % 5) as f32);
                Aabb { min, max: min + size }
            })
            .collect()
    }

    /// Against every pair tested directly, before and after the boxes move (the leaves keep
    /// their first order): each overlapping pair of one tree once, and each across two trees.
    #[test]
    fn finds_exactly_the_overlapping_pairs_once() {
        let (mut tree, mut other) = (BoxTree::default(), BoxTree::default());
        for shift in [0.0, 1.3] {
            let (boxes, others) = (scattered(403, shift), scattered(77, shift + 0.4));
            if shift == 0.0 {
                tree.order_leaves(&boxes);
                other.order_leaves(&others);
            }
            tree.refit(&boxes);
            other.refit(&others);
            let mut found: Vec<(u32, u32)> =
                tree.overlapping_pairs(&tree).into_iter().map(|(a, b)| (a.min(b), a.max(b))).collect();
            found.sort_unstable();
            let n = boxes.len() as u32;
            let direct: Vec<(u32, u32)> = (0..n)
                .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
                .filter(|&(a, b)| boxes[a as usize].overlaps(&boxes[b as usize]))
                .collect();
            assert_eq!(found, direct);
            let mut found = tree.overlapping_pairs(&other);
            found.sort_unstable();
            let direct: Vec<(u32, u32)> = (0..n)
                .flat_map(|a| (0..others.len() as u32).map(move |b| (a, b)))
                .filter(|&(a, b)| boxes[a as usize].overlaps(&others[b as usize]))
                .collect();
            assert_eq!(found, direct);
        }
    }
}
