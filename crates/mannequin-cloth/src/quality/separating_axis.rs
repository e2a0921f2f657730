//! A fast, sound "certainly apart" answer for two triangles, so the exact predicates run only on
//! pairs that come close. Any direction along which the two triangles' projections do not
//! overlap proves them apart; the candidates are the separating-axis theorem's (both normals,
//! the nine edge–edge cross products, and each triangle's in-plane edge normals, which settle
//! coplanar neighbours such as a flat sheet's). A direction only counts when the gap exceeds
//! what rounding in the f64 projections could reach, so a `true` is never wrong; `false` means
//! "ask the exact test".

use super::triangle_intersection::Point;

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: Point, b: Point) -> Point {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Relative bound on the rounding of one projection a·x (three products and two sums, each
/// within 2⁻⁵³ of its value) with a wide safety factor.
const ROUNDING: f64 = 1e-12;

/// True when some direction provably separates the closed triangles `p` and `q`.
pub(crate) fn certainly_apart(p: [Point; 3], q: [Point; 3]) -> bool {
    let reach = p.iter().chain(&q).flat_map(|x| x.iter()).fold(0.0f64, |m, &v| m.max(v.abs()));
    let edges = |t: [Point; 3]| [sub(t[1], t[0]), sub(t[2], t[1]), sub(t[0], t[2])];
    let (ep, eq) = (edges(p), edges(q));
    let (np, nq) = (cross(ep[0], ep[1]), cross(eq[0], eq[1]));
    let mut axes = vec![np, nq];
    for a in ep {
        axes.extend(eq.iter().map(|&b| cross(a, b)));
        axes.push(cross(np, a));
    }
    axes.extend(eq.iter().map(|&b| cross(nq, b)));
    axes.into_iter().any(|axis| {
        let length = dot(axis, axis).sqrt();
        if !length.is_normal() {
            return false;
        }
        let span = |t: [Point; 3]| {
            let d = t.map(|x| dot(axis, x));
            (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]))
        };
        let ((lo_p, hi_p), (lo_q, hi_q)) = (span(p), span(q));
        let tolerance = ROUNDING * length * reach;
        hi_p + tolerance < lo_q || hi_q + tolerance < lo_p
    })
}
