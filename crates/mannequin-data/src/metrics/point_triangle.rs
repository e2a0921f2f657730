//! The closest point of a triangle to a point (Ericson, *Real-Time Collision Detection*, 5.1.5):
//! classify the point against the triangle's Voronoi regions (3 vertices, 3 edges, interior).

use glam::DVec3;

/// `n / d`, or 0 where a degenerate (zero-area) triangle makes `d` vanish.
fn ratio(n: f64, d: f64) -> f64 {
    if d != 0.0 { n / d } else { 0.0 }
}

pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * ratio(d1, d1 - d3);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * ratio(d2, d2 - d6);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ratio(d4 - d3, (d4 - d3) + (d5 - d6));
    }
    let sum = va + vb + vc;
    a + ab * ratio(vb, sum) + ac * ratio(vc, sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the minimum over a fine barycentric grid is never closer than the answer,
    /// and the answer is within the grid spacing of it.
    #[test]
    fn agrees_with_a_dense_search_in_every_region() {
        let (a, b, c) = (DVec3::new(0.0, 0.0, 0.0), DVec3::new(2.0, 0.1, 0.0), DVec3::new(0.4, 1.5, 0.3));
        let mut r = mannequin_io::rng::SplitMix64::new(11);
        for _ in 0..200 {
            let p = DVec3::new(r.range(-2.0, 4.0), r.range(-2.0, 3.0), r.range(-1.0, 1.0));
            let q = closest_point_on_triangle(p, a, b, c);
            let d = (p - q).length();
            let n = 200;
            let mut best = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    best = best.min((p - (a + (b - a) * u + (c - a) * v)).length());
                }
            }
            assert!(d <= best + 1e-12 && best - d < 0.02, "{p}: {d} vs grid {best}");
        }
    }
}
