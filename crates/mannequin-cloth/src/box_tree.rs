//! A bounding-box tree over a cloth's elements for finding the pairs of elements that can come
//! near each other. The leaves are put in order once, along a Morton curve through the elements'
//! first boxes, and only the boxes are refitted after that: elements next to each other in the
//! cloth stay next to each other however it moves, so the tree stays tight enough.
//!
//! Each node holds a box around its elements' places and one around their velocities, so the walk
//! can ask whether two nodes meet within a time: cloth moving together has a narrow box of
//! velocity differences and stays apart however fast it travels.
//!
//! Elements of the layers under the cloth meet only the cloth's: their leaves come after all of
//! the cloth's, so whole subtrees of them are passed over together when walked against each
//! other (a T-shirt's walk otherwise went down to every pair of neighbouring triangles of the
//! pants under it, to throw them all away).

use glam::Vec3;

use crate::box_hash::Aabb;

/// A box holding nothing, the identity of the union.
const NOTHING: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };
/// A node no walk meets: the padding past the last leaf.
const EMPTY: MovingBox = MovingBox { place: NOTHING, velocity: NOTHING };

/// Where some particles are, and how fast they move: boxes around their places and velocities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MovingBox {
    pub place: Aabb,
    pub velocity: Aabb,
}

impl MovingBox {
    /// Particles somewhere in `place`, not moving.
    pub fn still(place: Aabb) -> Self {
        Self { place, velocity: Aabb { min: Vec3::ZERO, max: Vec3::ZERO } }
    }

    fn union(self, other: Self) -> Self {
        Self { place: self.place.union(other.place), velocity: self.velocity.union(other.velocity) }
    }

    /// Whether a point of `self` and one of `other`, each moving straight at a velocity of its box
    /// for a time in [0, `horizon`], can come within `reach` along every axis. Per axis, their
    /// difference lies in the difference of the place boxes plus a time in [0, horizon] times the
    /// difference of the velocity boxes.
    fn may_meet(&self, other: &Self, horizon: f32, reach: f32) -> bool {
        let closing = horizon * (self.velocity.min - other.velocity.max).min(Vec3::ZERO);
        let opening = horizon * (self.velocity.max - other.velocity.min).max(Vec3::ZERO);
        let low = self.place.min - other.place.max + closing;
        let high = self.place.max - other.place.min + opening;
        low.cmple(Vec3::splat(reach)).all() && high.cmpge(Vec3::splat(-reach)).all()
    }
}

#[derive(Debug, Clone, Default)]
pub(crate) struct BoxTree {
    /// The element at each leaf, in Morton order.
    order: Vec<u32>,
    /// A complete binary tree: node i has children 2i and 2i + 1, the leaves are nodes
    /// `leaves..2 · leaves`, and node 0 is unused.
    nodes: Vec<MovingBox>,
    /// Per node, whether any element under it is the cloth's.
    cloth: Vec<bool>,
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
    pub fn refit(&mut self, boxes: &[MovingBox]) {
        debug_assert_eq!(self.order.len(), boxes.len(), "the leaves are ordered for other elements");
        for (k, &e) in self.order.iter().enumerate() {
            self.nodes[self.leaves + k] = boxes[e as usize];
        }
        for i in (1..self.leaves).rev() {
            self.nodes[i] = self.nodes[2 * i].union(self.nodes[2 * i + 1]);
        }
    }

    /// Orders the leaves along a Morton curve through `boxes`, one per element: a cloth's start
    /// shape, so that a run resumed from a checkpoint walks its pairs in the same order. The
    /// elements `cloth` says are the cloth's come first, those of the layers under it after.
    pub fn order_leaves(&mut self, boxes: &[Aabb], cloth: &[bool]) {
        let centre = |b: &Aabb| 0.5 * (b.min + b.max);
        let all = boxes.iter().fold(NOTHING, |a, b| a.union(*b));
        let scale = 1023.0 / all.extent().max_element().max(f32::MIN_POSITIVE);
        let code = |b: &Aabb| {
            let q = ((centre(b) - all.min) * scale).as_uvec3();
            spread(q.x) | (spread(q.y) << 1) | (spread(q.z) << 2)
        };
        let mut keyed: Vec<(bool, u32, u32)> =
            boxes.iter().enumerate().map(|(k, b)| (!cloth[k], code(b), k as u32)).collect();
        keyed.sort_unstable();
        self.order = keyed.into_iter().map(|(_, _, k)| k).collect();
        self.leaves = boxes.len().next_power_of_two();
        self.nodes = vec![EMPTY; 2 * self.leaves];
        self.cloth = vec![false; 2 * self.leaves];
        for (k, &e) in self.order.iter().enumerate() {
            self.cloth[self.leaves + k] = cloth[e as usize];
        }
        for i in (1..self.leaves).rev() {
            self.cloth[i] = self.cloth[2 * i] || self.cloth[2 * i + 1];
        }
    }

    /// Every pair (a of `self`, b of `other`), one of them the cloth's, whose boxes may come
    /// within `reach` within `horizon` ([`MovingBox`]), once; with `other` the same tree, every
    /// unordered pair of two elements once, as (a, b) or (b, a). Walks both trees together, so a
    /// pair of subtrees apart is passed over at once; the top of the walk runs in parallel.
    pub fn meeting_pairs(&self, other: &BoxTree, horizon: f32, reach: f32) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        if !self.order.is_empty() && !other.order.is_empty() {
            let walk = Walk { ours: self, theirs: other, same: std::ptr::eq(self, other), horizon, reach };
            walk.visit((1, 1), &mut out);
        }
        out
    }

    /// Every element whose still box comes within `reach` of the still box `query`, into `out`;
    /// only the cloth's with `cloth_only` (the query is a layer's, which meets nothing else).
    pub fn near(&self, query: &MovingBox, reach: f32, cloth_only: bool, out: &mut Vec<u32>) {
        let mut stack = vec![1usize];
        while let Some(node) = stack.pop() {
            if self.order.is_empty()
                || (cloth_only && !self.cloth[node])
                || !self.nodes[node].may_meet(query, 0.0, reach)
            {
                continue;
            }
            if self.is_leaf(node) {
                out.extend(self.order.get(node - self.leaves));
            } else {
                stack.extend([2 * node + 1, 2 * node]);
            }
        }
    }

    fn is_leaf(&self, node: usize) -> bool {
        node >= self.leaves
    }
}

/// One walk of two trees (or one tree against itself) for the pairs that may meet.
struct Walk<'a> {
    ours: &'a BoxTree,
    theirs: &'a BoxTree,
    same: bool,
    horizon: f32,
    reach: f32,
}

impl Walk<'_> {
    fn visit(&self, (a, b): (usize, usize), out: &mut Vec<(u32, u32)>) {
        let (ours, theirs) = (self.ours, self.theirs);
        if !(ours.cloth[a] || theirs.cloth[b])
            || !ours.nodes[a].may_meet(&theirs.nodes[b], self.horizon, self.reach)
        {
            return;
        }
        let split = |x: (usize, usize), y: (usize, usize), out: &mut Vec<(u32, u32)>| {
            // Near the root each half is a large share of the work: run the two in parallel.
            if a.max(b) < PARALLEL_ABOVE {
                let mut more = Vec::new();
                rayon::join(|| self.visit(x, out), || self.visit(y, &mut more));
                out.append(&mut more);
            } else {
                self.visit(x, out);
                self.visit(y, out);
            }
        };
        if self.same && a == b {
            if !ours.is_leaf(a) {
                let mut inner = Vec::new();
                split((2 * a, 2 * a), (2 * a + 1, 2 * a + 1), out);
                self.visit((2 * a, 2 * a + 1), &mut inner);
                out.append(&mut inner);
            }
            return;
        }
        match (ours.is_leaf(a), theirs.is_leaf(b)) {
            (true, true) => {
                if let (Some(&x), Some(&y)) =
                    (ours.order.get(a - ours.leaves), theirs.order.get(b - theirs.leaves))
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
    /// their first order): each overlapping pair of one tree once, and each across two trees,
    /// but those of two layer elements (every third of one tree, every fourth of the other).
    #[test]
    fn finds_exactly_the_overlapping_pairs_once() {
        let (mut tree, mut other) = (BoxTree::default(), BoxTree::default());
        let cloth: Vec<bool> = (0..403).map(|k| k % 3 != 0).collect();
        let others_cloth: Vec<bool> = (0..77).map(|k| k % 4 != 0).collect();
        for shift in [0.0, 1.3] {
            let (boxes, others) = (scattered(403, shift), scattered(77, shift + 0.4));
            if shift == 0.0 {
                tree.order_leaves(&boxes, &cloth);
                other.order_leaves(&others, &others_cloth);
            }
            tree.refit(&boxes.iter().map(|&b| MovingBox::still(b)).collect::<Vec<_>>());
            other.refit(&others.iter().map(|&b| MovingBox::still(b)).collect::<Vec<_>>());
            let mut found: Vec<(u32, u32)> =
                tree.meeting_pairs(&tree, 0.0, 0.0).into_iter().map(|(a, b)| (a.min(b), a.max(b))).collect();
            found.sort_unstable();
            let n = boxes.len() as u32;
            let direct: Vec<(u32, u32)> = (0..n)
                .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
                .filter(|&(a, b)| boxes[a as usize].overlaps(&boxes[b as usize]))
                .filter(|&(a, b)| cloth[a as usize] || cloth[b as usize])
                .collect();
            assert_eq!(found, direct);
            let mut found = tree.meeting_pairs(&other, 0.0, 0.0);
            found.sort_unstable();
            let mut queried = Vec::new();
            for (b, query) in others.iter().enumerate() {
                let mut near = Vec::new();
                tree.near(&MovingBox::still(*query), 0.0, !others_cloth[b], &mut near);
                queried.extend(near.into_iter().map(|a| (a, b as u32)));
            }
            queried.sort_unstable();
            assert_eq!(queried, found);
            let direct: Vec<(u32, u32)> = (0..n)
                .flat_map(|a| (0..others.len() as u32).map(move |b| (a, b)))
                .filter(|&(a, b)| boxes[a as usize].overlaps(&others[b as usize]))
                .filter(|&(a, b)| cloth[a as usize] || others_cloth[b as usize])
                .collect();
            assert_eq!(found, direct);
        }
    }

    /// Points moving straight: every pair that comes within reach at some time (sampled finely)
    /// is found; points carried together at 10 m/s, 1 cm apart, are never within 2 mm.
    #[test]
    fn finds_the_moving_points_that_meet() {
        let point = |k: usize, shift: f32| {
            let f = k as f32 + shift;
            Vec3::new((f * 0.37).sin(), (f * 0.91).cos(), (f * 0.13).sin()) * 0.3
        };
        let (places, velocities): (Vec<Vec3>, Vec<Vec3>) =
            (0..300).map(|k| (point(k, 0.0), point(k, 7.0))).unzip();
        let moving: Vec<MovingBox> = places
            .iter()
            .zip(&velocities)
            .map(|(&p, &v)| MovingBox { place: Aabb { min: p, max: p }, velocity: Aabb { min: v, max: v } })
            .collect();
        let mut tree = BoxTree::default();
        tree.order_leaves(&moving.iter().map(|m| m.place).collect::<Vec<_>>(), &[true; 300]);
        tree.refit(&moving);
        let (horizon, reach) = (0.5, 0.02);
        let found: std::collections::HashSet<(u32, u32)> = tree
            .meeting_pairs(&tree, horizon, reach)
            .into_iter()
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        let n = places.len();
        let mut met = 0;
        for a in 0..n {
            for b in a + 1..n {
                let meets = (0..=1000).any(|k| {
                    let t = horizon * k as f32 / 1000.0;
                    let gap = (places[a] + t * velocities[a]) - (places[b] + t * velocities[b]);
                    gap.abs().max_element() <= reach
                });
                if meets {
                    met += 1;
                    assert!(found.contains(&(a as u32, b as u32)), "{a} and {b} meet but were not found");
                }
            }
        }
        assert!(met > 10, "only {met} pairs meet: the case tests little");
        let grid: Vec<MovingBox> = (0..400)
            .map(|k| {
                let p = Vec3::new((k % 20) as f32, (k / 20) as f32, 0.0) * 0.01;
                MovingBox {
                    place: Aabb { min: p, max: p },
                    velocity: Aabb { min: Vec3::X * 10.0, max: Vec3::X * 10.0 },
                }
            })
            .collect();
        tree.order_leaves(&grid.iter().map(|m| m.place).collect::<Vec<_>>(), &[true; 400]);
        tree.refit(&grid);
        assert!(tree.meeting_pairs(&tree, 1.0, 0.002).is_empty());
    }
}
