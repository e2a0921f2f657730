//! A fast, sound "certainly apart" answer for two triangles, so the exact predicates run only on
//! pairs that come close. Any direction along which the two triangles' projections do not
//! overlap proves them apart; the candidates are the separating-axis theorem's (both normals,
//! the nine edge–edge cross products, and each triangle's in-plane edge normals, which settle
//! coplanar neighbours such as a flat sheet's). A direction only counts when the gap exceeds
//! what rounding in the f64 projections could reach, so a `true` is never wrong; `false` means
//! "ask the exact test".

use glam::DVec3;

use super::exact::Point;

/// Relative bound on the rounding of one projection a·x (three products and two sums, each
/// within 2⁻⁵³ of its value) with a wide safety factor.
const ROUNDING: f64 = 1e-12;

/// True when some direction provably separates the closed triangles `p` and `q`.
pub(crate) fn certainly_apart(p: [Point; 3], q: [Point; 3]) -> bool {
    let (p, q) = (p.map(DVec3::from), q.map(DVec3::from));
    let reach = p.iter().chain(&q).map(|x| x.abs().max_element()).fold(0.0, f64::max);
    let edges = |t: [DVec3; 3]| [t[1] - t[0], t[2] - t[1], t[0] - t[2]];
    let (ep, eq) = (edges(p), edges(q));
    let (np, nq) = (ep[0].cross(ep[1]), eq[0].cross(eq[1]));
    let mut axes = vec![np, nq];
    for a in ep {
        axes.extend(eq.iter().map(|&b| a.cross(b)));
        axes.push(np.cross(a));
    }
    axes.extend(eq.iter().map(|&b| nq.cross(b)));
    axes.into_iter().any(|axis| {
        let length = axis.length();
        if !length.is_normal() {
            return false;
        }
        let span = |t: [DVec3; 3]| {
            let d = t.map(|x| axis.dot(x));
            (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]))
        };
        let ((lo_p, hi_p), (lo_q, hi_q)) = (span(p), span(q));
        let tolerance = ROUNDING * length * reach;
        hi_p + tolerance < lo_q || hi_q + tolerance < lo_p
    })
}
