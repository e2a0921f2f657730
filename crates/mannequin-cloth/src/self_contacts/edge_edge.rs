//! Edge–edge contacts: two edges whose common perpendicular meets both inside are kept their gap
//! apart along the common normal m = e₁ × e₂. Vertex–triangle contacts miss edges that pass
//! through each other while every vertex stays beside the other triangles, which is how cloth
//! crumpled at the scale of its triangles tangles.
//!
//! As for vertex–triangle contacts, the side is the one at the start of the substep, which the
//! safe step keeps.

use glam::Vec3;
use rayon::prelude::*;

use super::anchor::Anchor;
use super::apart::Apart;
use super::ends::Ends;
use super::orientation::volume;
use super::push::{moved, push_apart};
use super::safe_step::Closing;
use super::search::Search;
use crate::box_hash::Aabb;
use crate::box_tree::{BoxTree, MovingBox};

/// Closest points this close to an edge's end (as a fraction of it) count as at the end.
const END_TOLERANCE: f32 = 1e-3;
/// Edges closer to parallel than this (|ê₁ × ê₂|, about 12°) have no well-conditioned common
/// normal: it swings wildly as they turn, and the side with it. The vertex–triangle contacts of
/// their ends hold them.
const PARALLEL: f32 = 0.2;

#[derive(Debug, Clone, Copy, PartialEq)]
struct Pair {
    /// Indices into the cloth's edge list, first < second.
    first: u32,
    second: u32,
    gap: f32,
}

/// A pair watched through a frame, with its distance d₀ at the anchor.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Watched {
    first: u32,
    second: u32,
    distance: f32,
}

#[derive(Debug, Clone, Default)]
pub(crate) struct EdgeEdge {
    pairs: Vec<Pair>,
    /// How far apart each pair is at the start of the substep.
    start: Vec<Apart>,
    watched: Vec<Watched>,
    /// Each edge's box.
    boxes: Vec<MovingBox>,
    /// The box around each edge's move, grown by half the reach.
    swept: Vec<Aabb>,
    tree: BoxTree,
}

/// The closest points of segments p₁p₂ and q₁q₂, as fractions (s, t) along each (Ericson,
/// *Real-Time Collision Detection*, §5.1.9).
fn closest_fractions(p1: Vec3, p2: Vec3, q1: Vec3, q2: Vec3) -> (f32, f32) {
    let (d1, d2, r) = (p2 - p1, q2 - q1, p1 - q1);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    if a <= f32::MIN_POSITIVE || e <= f32::MIN_POSITIVE {
        return (0.0, 0.0);
    }
    let (b, c) = (d1.dot(d2), d1.dot(r));
    let denominator = a * e - b * b;
    let s = if denominator > 0.0 { ((b * f - c * e) / denominator).clamp(0.0, 1.0) } else { 0.0 };
    let t = (b * s + f) / e;
    if t < 0.0 {
        (((-c) / a).clamp(0.0, 1.0), 0.0)
    } else if t > 1.0 {
        (((b - c) / a).clamp(0.0, 1.0), 1.0)
    } else {
        (s, t)
    }
}

/// Where the lines through p₁p₂ and q₁q₂ pass each other: their signed distance along the unit
/// common normal m̂ = (p₂ − p₁) × (q₂ − q₁) / |…|, the normal, and the fractions (s, t) along each
/// edge of the points where the common perpendicular meets them. `None` for parallel edges.
fn lines_passing(p1: Vec3, p2: Vec3, q1: Vec3, q2: Vec3) -> Option<(f32, Vec3, f32, f32)> {
    let (d1, d2, r) = (p2 - p1, q2 - q1, p1 - q1);
    let m = d1.cross(d2);
    let square = m.length_squared();
    if square.sqrt() <= PARALLEL * d1.length() * d2.length() {
        return None;
    }
    let (a, b, c, e, f) = (d1.dot(d1), d1.dot(d2), d1.dot(r), d2.dot(d2), d2.dot(r));
    let (s, t) = ((b * f - c * e) / square, (a * f - b * c) / square);
    let normal = m / square.sqrt();
    Some((r.dot(normal), normal, s, t))
}

/// A fraction strictly inside its edge.
fn inside(x: f32) -> bool {
    x > END_TOLERANCE && x < 1.0 - END_TOLERANCE
}

/// How far apart edges `e1` and `e2` are at `positions`, `e1` first.
fn edges_apart(positions: &[[f32; 3]], e1: [u32; 2], e2: [u32; 2]) -> Apart {
    let [p1, p2, q1, q2] = [e1[0], e1[1], e2[0], e2[1]].map(|i| Vec3::from(positions[i as usize]));
    let (s, t) = closest_fractions(p1, p2, q1, q2);
    Apart::between(p1 + s * (p2 - p1), q1 + t * (q2 - q1))
}

/// The pair of edges `a` and `b` with its distance at the start of the substep `ends`, if they
/// share no vertex and that distance less what the moves can close is within reach.
fn admit(ends: Ends, search: Search<[u32; 2]>, a: u32, b: u32) -> Option<(Pair, Apart)> {
    let (first, second) = (a.min(b), a.max(b));
    let (e1, e2) = (search.elements[first as usize], search.elements[second as usize]);
    if e2.iter().any(|v| e1.contains(v)) || !search.has_cloth(&[e1[0], e1[1], e2[0], e2[1]]) {
        return None;
    }
    let start = edges_apart(ends.from, e1, e2);
    (start.distance - ends.closing([e1[0], e1[1], e2[0], e2[1]]) < search.reach.distance).then(|| {
        let initial = edges_apart(search.initial, e1, e2).distance;
        let gap = search.reach.gap(search.near.touch(&e1, &e2), initial);
        (Pair { first, second, gap }, start)
    })
}

impl EdgeEdge {
    /// Refits the tree to the edges' boxes, ordering its leaves first ([`Search::order_leaves`]),
    /// and walks it for the pairs that may come within reach within `horizon`.
    fn meeting(&mut self, search: Search<[u32; 2]>, horizon: f32) -> Vec<(u32, u32)> {
        if !self.tree.is_ordered_for(search.elements.len()) {
            search.order_leaves(&mut self.tree, search.elements);
        }
        self.tree.refit(&self.boxes);
        self.tree.meeting_pairs(&self.tree, horizon, search.reach.distance)
    }

    /// Watches, from `anchor` to its horizon, every pair of edges without a common vertex whose
    /// boxes may come within reach while no particle strays farther than the allowance from its
    /// predicted path.
    pub fn watch(&mut self, anchor: &Anchor, search: Search<[u32; 2]>) {
        let edges = search.elements;
        self.boxes.clear();
        self.boxes.extend(edges.iter().map(|e| anchor.moving(e)));
        let pairs = self.meeting(search, anchor.horizon);
        self.watched = pairs
            .into_par_iter()
            .filter_map(|(a, b)| {
                let (first, second) = (a.min(b), a.max(b));
                let (e1, e2) = (edges[first as usize], edges[second as usize]);
                let distance = edges_apart(anchor.places(), e1, e2).distance;
                let mine = search.has_cloth(&[e1[0], e1[1], e2[0], e2[1]]);
                (mine && !e2.iter().any(|v| e1.contains(v))).then_some(Watched { first, second, distance })
            })
            .collect();
    }

    /// The pairs of the substep `ends` that [`admit`] takes among those whose boxes around the
    /// moves come within reach: of those watched from `anchor`, and those with a particle that
    /// strayed, found afresh. A watched pair whose distance at the anchor, less how far its
    /// particles have moved apart since and what the moves can close, is beyond reach is passed
    /// over without its closest points.
    pub fn find(&mut self, ends: Ends, anchor: &Anchor, search: Search<[u32; 2]>) {
        let half = 0.5 * search.reach.distance;
        self.swept.clear();
        self.swept.extend(search.elements.iter().map(|e| ends.swept(e).inflated(half)));
        let swept = &self.swept;
        let near = |w: &&Watched| {
            let (e1, e2) = (search.elements[w.first as usize], search.elements[w.second as usize]);
            let particles = [e1[0], e1[1], e2[0], e2[1]];
            !anchor.strayed(&particles)
                && swept[w.first as usize].overlaps(&swept[w.second as usize])
                && w.distance - anchor.apart(&e1, &e2) - ends.closing(particles) < search.reach.distance
        };
        let mut kept: Vec<(Pair, Apart)> = self
            .watched
            .par_iter()
            .filter(near)
            .filter_map(|w| admit(ends, search, w.first, w.second))
            .collect();
        if anchor.any_strayed() {
            kept.extend(self.strays(ends, anchor, search));
        }
        (self.pairs, self.start) = kept.into_iter().unzip();
    }

    /// The pairs with a particle that strayed from its path, whose boxes around the moves come
    /// within reach, that [`admit`] takes: each edge with a strayed end against every edge, a pair
    /// of two such edges once.
    fn strays(&mut self, ends: Ends, anchor: &Anchor, search: Search<[u32; 2]>) -> Vec<(Pair, Apart)> {
        let edges = search.elements;
        self.boxes.clear();
        self.boxes.extend(edges.iter().map(|e| MovingBox::still(ends.swept(e))));
        self.tree.refit(&self.boxes);
        let (boxes, tree, reach) = (&self.boxes, &self.tree, search.reach.distance);
        let strayed = |e: u32| anchor.strayed(&edges[e as usize]);
        (0..edges.len() as u32)
            .into_par_iter()
            .filter(|&e| strayed(e))
            .flat_map_iter(|e| {
                let mut found = Vec::new();
                // A layer's edge meets only the cloth's.
                tree.near(&boxes[e as usize], reach, !search.has_cloth(&edges[e as usize]), &mut found);
                found.into_iter().filter(move |&f| f != e && (e < f || !strayed(f))).map(move |f| (e, f))
            })
            .filter_map(|(e, f)| admit(ends, search, e, f))
            .collect()
    }

    /// Notes how far apart each pair is at `positions`, the start of the substep.
    pub fn measure(&mut self, positions: &[[f32; 3]], edges: &[[u32; 2]]) {
        self.start.clear();
        self.start.par_extend(
            self.pairs
                .par_iter()
                .map(|pair| edges_apart(positions, edges[pair.first as usize], edges[pair.second as usize])),
        );
    }

    /// Each pair's particles, the first edge's ends then the second's, with how far apart they
    /// are at the start of the substep.
    pub fn closing(&self, edges: &[[u32; 2]], out: &mut Vec<Closing>) {
        out.extend(self.pairs.iter().zip(&self.start).map(|(pair, &apart)| {
            let ([a, b], [c, d]) = (edges[pair.first as usize], edges[pair.second as usize]);
            Closing { particles: [a, b, c, d], split: 2, apart }
        }));
    }

    /// One Gauss–Seidel pass over the pairs, in their (first, second) order; `previous` holds the
    /// positions at the start of the substep, which say each pair's side. Edges passing each
    /// other inside both are kept their gap apart along the common normal on their side; others
    /// (near an end, or near parallel) along the line between their closest points.
    pub fn project(
        &self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        edges: &[[u32; 2]],
        most: f32,
    ) {
        for (pair, start) in self.pairs.iter().zip(&self.start) {
            let (first, second) = (edges[pair.first as usize], edges[pair.second as usize]);
            // A pair that cannot be within its gap is skipped before the cost of its closest points.
            if start.distance - moved(positions, previous, &first) - moved(positions, previous, &second)
                >= pair.gap
            {
                continue;
            }
            let ([a, b], [c, d]) = (first, second);
            let particles = [a, b, c, d];
            let [p1, p2, q1, q2] = particles.map(|i| Vec3::from(positions[i as usize]));
            let ((s, t), direction, distance) = match lines_passing(p1, p2, q1, q2) {
                Some((separation, normal, s, t)) if inside(s) && inside(t) => {
                    // The volume of (q₁, p₁, p₂, q₂) is m·(p₁ − q₁): the separation times |m|.
                    let [p1, p2, q1, q2] = particles.map(|i| Vec3::from(previous[i as usize]));
                    let side = volume([q1, p1, p2, q2]).signum();
                    ((s, t), side * normal, side * separation)
                }
                _ => {
                    let (s, t) = closest_fractions(p1, p2, q1, q2);
                    let away = (p1 + s * (p2 - p1)) - (q1 + t * (q2 - q1));
                    let distance = away.length();
                    if distance <= f32::MIN_POSITIVE {
                        continue;
                    }
                    ((s, t), away / distance, distance)
                }
            };
            let violation = (distance - pair.gap).max(-most);
            if violation >= 0.0 {
                continue;
            }
            let share = [1.0 - s, s, t - 1.0, -t];
            push_apart(positions, particles, inverse_mass, share, -violation * direction);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_points_of_crossing_and_offset_segments() {
        let (s, t) =
            closest_fractions(Vec3::ZERO, Vec3::X, Vec3::new(0.25, -1.0, 1.0), Vec3::new(0.25, 1.0, 1.0));
        assert!((s - 0.25).abs() < 1e-6 && (t - 0.5).abs() < 1e-6, "{s} {t}");
        let (s, t) =
            closest_fractions(Vec3::ZERO, Vec3::X, Vec3::new(2.0, -1.0, 0.5), Vec3::new(2.0, 1.0, 0.5));
        assert!((s - 1.0).abs() < 1e-6 && (t - 0.5).abs() < 1e-6, "{s} {t}");
    }

    #[test]
    fn the_separation_changes_sign_when_edges_pass_through_each_other() {
        let (q1, q2) = (Vec3::new(0.3, -1.0, 0.0), Vec3::new(0.3, 1.0, 0.0));
        let lift = |z: f32| lines_passing(Vec3::ZERO, Vec3::X, q1 + z * Vec3::Z, q2 + z * Vec3::Z).unwrap();
        let (above, below) = (lift(0.1), lift(-0.1));
        assert!((above.0 + 0.1).abs() < 1e-6 && (below.0 - 0.1).abs() < 1e-6, "{above:?} {below:?}");
        assert!((above.2 - 0.3).abs() < 1e-6 && (above.3 - 0.5).abs() < 1e-6, "{above:?}");
    }

    /// Nearly parallel edges side by side in one plane: their lines pass far beyond the edges,
    /// so the pair is no contact, however close the edges.
    #[test]
    fn side_by_side_edges_are_not_crossing() {
        // Nearly parallel: no common normal at all, or one whose feet miss the edges' insides.
        let passing =
            lines_passing(Vec3::ZERO, Vec3::X, Vec3::new(0.0, 0.01, 0.0), Vec3::new(1.0, 0.012, 0.0));
        assert!(passing.is_none_or(|(_, _, s, t)| !(inside(s) && inside(t))), "{passing:?}");
    }
}
