//! Whether two closed triangles share a point, decided exactly with orientation predicates. Two
//! triangles meet exactly when an edge of one meets the other: the ends of their common segment
//! (or the corners of their common polygon, when coplanar) lie on edges.

use std::cmp::Ordering::{self, Equal, Greater, Less};

use super::exact::{Point, orient2d, orient3d};
use super::separating_axis::certainly_apart;

/// True when the closed triangles `p` and `q` intersect (touching counts). A degenerate triangle
/// (its corners on one line) meets nothing.
pub(crate) fn triangles_intersect(p: [Point; 3], q: [Point; 3]) -> bool {
    !certainly_apart(p, q) && exactly_intersect(p, q)
}

/// [`triangles_intersect`] with the exact predicates alone.
fn exactly_intersect(p: [Point; 3], q: [Point; 3]) -> bool {
    if degenerate(p) || degenerate(q) {
        return false;
    }
    if strictly_one_side(q, p) || strictly_one_side(p, q) {
        return false;
    }
    let edges = |t: [Point; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    edges(p).iter().any(|&(a, b)| segment_meets_triangle(a, b, q))
        || edges(q).iter().any(|&(a, b)| segment_meets_triangle(a, b, p))
}

fn degenerate(t: [Point; 3]) -> bool {
    [(0, 1), (1, 2), (2, 0)].iter().all(|&(i, j)| {
        let flat = |p: Point| [p[i], p[j]];
        orient2d(flat(t[0]), flat(t[1]), flat(t[2])) == Equal
    })
}

/// Every corner of `t` strictly on the same side of `plane`'s plane.
fn strictly_one_side(plane: [Point; 3], t: [Point; 3]) -> bool {
    let side = t.map(|p| orient3d(plane[0], plane[1], plane[2], p));
    side[0] != Equal && side.iter().all(|&s| s == side[0])
}

fn segment_meets_triangle(a: Point, b: Point, t: [Point; 3]) -> bool {
    let (sa, sb) = (orient3d(t[0], t[1], t[2], a), orient3d(t[0], t[1], t[2], b));
    if sa == Equal && sb == Equal {
        return coplanar_segment_meets_triangle(a, b, t);
    }
    if sa == sb {
        return false;
    }
    // The segment reaches the plane; its line passes through the triangle when it turns the same
    // way (or not at all) about each of the triangle's edges.
    let turns = [(0, 1), (1, 2), (2, 0)].map(|(i, j)| orient3d(a, b, t[i], t[j]));
    agree(&turns)
}

/// All signs the same, zeros allowed.
fn agree(signs: &[Ordering]) -> bool {
    !(signs.contains(&Greater) && signs.contains(&Less))
}

/// Both in one plane: compare them in 2D, on the coordinate plane the triangle faces most.
fn coplanar_segment_meets_triangle(a: Point, b: Point, t: [Point; 3]) -> bool {
    let (u, v) = (sub(t[1], t[0]), sub(t[2], t[0]));
    let normal = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let drop = (0..3).max_by(|&i, &j| normal[i].abs().total_cmp(&normal[j].abs())).unwrap_or(2);
    let (i, j) = ((drop + 1) % 3, (drop + 2) % 3);
    let flat = |p: Point| [p[i], p[j]];
    let (a, b, t) = (flat(a), flat(b), t.map(flat));
    if orient2d(t[0], t[1], t[2]) == Equal {
        return false;
    }
    let inside =
        |p: [f64; 2]| agree(&[orient2d(t[0], t[1], p), orient2d(t[1], t[2], p), orient2d(t[2], t[0], p)]);
    inside(a) || inside(b) || [(0, 1), (1, 2), (2, 0)].iter().any(|&(k, l)| segments_meet(a, b, t[k], t[l]))
}

/// Closed 2D segments a–b and c–d share a point.
fn segments_meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (d1, d2) = (orient2d(c, d, a), orient2d(c, d, b));
    let (d3, d4) = (orient2d(a, b, c), orient2d(a, b, d));
    if d1 != d2 && d1 != Equal && d2 != Equal && d3 != d4 && d3 != Equal && d4 != Equal {
        return true;
    }
    let within = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (0..2).all(|k| r[k] >= p[k].min(q[k]) && r[k] <= p[k].max(q[k]))
    };
    (d1 == Equal && within(c, d, a))
        || (d2 == Equal && within(c, d, b))
        || (d3 == Equal && within(a, b, c))
        || (d4 == Equal && within(a, b, d))
}

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    const FLOOR: [Point; 3] = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];

    #[test]
    fn a_triangle_piercing_another_crosses_it() {
        let upright = [[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [1.5, -1.0, 0.0]];
        assert!(triangles_intersect(FLOOR, upright));
        assert!(triangles_intersect(upright, FLOOR));
    }

    #[test]
    fn two_rings_linked_through_each_others_edges_cross() {
        // Neither has a corner inside the other; their edges pass through each other's interior.
        let a = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 2.0, 0.0]];
        let b = [[1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [1.0, -1.0, 0.0]];
        assert!(triangles_intersect(a, b));
    }

    #[test]
    fn touching_counts_and_a_hair_apart_does_not() {
        let resting = [[0.5, 0.5, 0.0], [0.5, 0.5, 1.0], [0.7, 0.5, 1.0]];
        assert!(triangles_intersect(FLOOR, resting), "a corner touching the interior");
        let lifted = resting.map(|p| [p[0], p[1], p[2] + 1e-9]);
        assert!(!triangles_intersect(FLOOR, lifted), "a corner a nanometre above");
        let edge_on_edge = [[1.0, -1.0, 1.0], [1.0, 1.0, -1.0], [3.0, 0.0, 0.0]];
        assert!(triangles_intersect(FLOOR, edge_on_edge));
    }

    #[test]
    fn parallel_triangles_never_meet() {
        let above = FLOOR.map(|p| [p[0] + 0.3, p[1] + 0.1, 0.001]);
        assert!(!triangles_intersect(FLOOR, above));
        let tilted_away = [[3.0, 3.0, 0.0], [4.0, 3.0, 1.0], [3.0, 4.0, 1.0]];
        assert!(!triangles_intersect(FLOOR, tilted_away));
    }

    #[test]
    fn coplanar_triangles_meet_only_when_they_overlap() {
        let disjoint = [[2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [2.0, 3.0, 0.0]];
        assert!(!triangles_intersect(FLOOR, disjoint), "beyond the hypotenuse");
        let overlapping = [[1.0, 1.0, 0.0], [3.0, 1.0, 0.0], [1.0, 3.0, 0.0]];
        assert!(triangles_intersect(FLOOR, overlapping));
        let inside = [[0.2, 0.2, 0.0], [0.5, 0.2, 0.0], [0.2, 0.5, 0.0]];
        assert!(triangles_intersect(FLOOR, inside), "one inside the other");
        assert!(triangles_intersect(inside, FLOOR));
        let sharing_an_edge_line = [[2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [2.5, -1.0, 0.0]];
        assert!(triangles_intersect(FLOOR, sharing_an_edge_line), "corners touch at (2, 0)");
    }

    #[test]
    fn degenerate_triangles_meet_nothing() {
        let sliver = [[0.5, 0.5, -1.0], [0.5, 0.5, 0.0], [0.5, 0.5, 1.0]];
        assert!(!triangles_intersect(FLOOR, sliver));
    }

    /// The fast separation test never changes an answer: on pairs built to touch, nearly touch,
    /// share a plane or cross, the filtered and the exact-only tests agree.
    #[test]
    fn the_separation_filter_agrees_with_the_exact_test() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (mut crossing, mut apart) = (0, 0);
        for k in 0..20_000 {
            let p: [Point; 3] = std::array::from_fn(|_| [next(), next(), next()]);
            let mut q: [Point; 3] = std::array::from_fn(|_| [next(), next(), next()]);
            match k % 4 {
                // In p's plane (z flattened), as a flat sheet's triangles are.
                0 => {
                    let flat = |t: [Point; 3]| t.map(|x| [x[0], x[1], 0.25]);
                    let (p, q) = (flat(p), flat(q));
                    assert_eq!(triangles_intersect(p, q), exactly_intersect(p, q), "{p:?} {q:?}");
                    continue;
                }
                // Sharing a corner's position, or one a hair away from it.
                1 => q[0] = p[1],
                2 => q[0] = [p[1][0] + 1e-13, p[1][1], p[1][2]],
                _ => {}
            }
            let exact = exactly_intersect(p, q);
            assert_eq!(triangles_intersect(p, q), exact, "{p:?} {q:?}");
            if exact { crossing += 1 } else { apart += 1 }
        }
        assert!(crossing > 1000 && apart > 1000, "{crossing} crossing, {apart} apart");
    }
}
