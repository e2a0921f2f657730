//! Barycentric coordinates on a triangle: of the point closest to a given point (Ericson,
//! *Real-Time Collision Detection*, §5.1.5), where in an edge's or a vertex's Voronoi region the
//! coordinates of the other corners are exactly 0, which tells the caller which feature it hit;
//! and of a point of the triangle's plane.

use glam::Vec3;

/// Barycentric coordinates `[u, v, w]` of the point of triangle (a, b, c) closest to `p`, so that
/// the point is u·a + v·b + w·c.
pub fn closest_barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let t = d1 / (d1 - d3);
        return [1.0 - t, t, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / (d2 - d6);
        return [1.0 - t, 0.0, t];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - t, t];
    }
    let sum = va + vb + vc;
    if sum.is_nan() || sum <= 0.0 {
        // A degenerate triangle whose face region caught p: its first corner will do.
        return [1.0, 0.0, 0.0];
    }
    let (v, w) = (vb / sum, vc / sum);
    [1.0 - v - w, v, w]
}

pub fn at_barycentric([u, v, w]: [f32; 3], a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    u * a + v * b + w * c
}

/// Barycentric coordinates of `p`, a point of the plane of (a, b, c); outside the triangle some
/// are negative. A degenerate triangle gives its first corner.
pub fn plane_barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let (d00, d01, d11, d20, d21) = (v0.dot(v0), v0.dot(v1), v1.dot(v1), v2.dot(v0), v2.dot(v1));
    let denominator = d00 * d11 - d01 * d01;
    if denominator <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let v = (d11 * d20 - d01 * d21) / denominator;
    let w = (d00 * d21 - d01 * d20) / denominator;
    [1.0 - v - w, v, w]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closest(p: [f32; 3]) -> ([f32; 3], Vec3) {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let bary = closest_barycentric(Vec3::from(p), a, b, c);
        (bary, at_barycentric(bary, a, b, c))
    }

    #[test]
    fn each_voronoi_region_gives_its_feature() {
        assert_eq!(closest([-1.0, -1.0, 3.0]).0, [1.0, 0.0, 0.0]);
        assert_eq!(closest([2.0, -0.5, 0.0]).0, [0.0, 1.0, 0.0]);
        assert_eq!(closest([-0.1, 2.0, -1.0]).0, [0.0, 0.0, 1.0]);
        let (bary, point) = closest([0.25, -2.0, 1.0]);
        assert_eq!((bary[2], point), (0.0, Vec3::new(0.25, 0.0, 0.0)));
        let (bary, point) = closest([-3.0, 0.5, 0.0]);
        assert_eq!((bary[1], point), (0.0, Vec3::new(0.0, 0.5, 0.0)));
        let (bary, point) = closest([1.0, 1.0, 0.5]);
        assert_eq!(bary[0], 0.0);
        assert!((point - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6);
    }

    #[test]
    fn above_the_face_it_is_the_foot_of_the_perpendicular() {
        let (bary, point) = closest([0.2, 0.3, -0.7]);
        assert!(bary.iter().all(|&x| x > 0.0));
        assert!((point - Vec3::new(0.2, 0.3, 0.0)).length() < 1e-6);
    }

    #[test]
    fn plane_coordinates_rebuild_the_point() {
        let (a, b, c) = (Vec3::new(0.1, -0.2, 0.3), Vec3::new(1.2, 0.1, -0.4), Vec3::new(0.4, 0.9, 0.2));
        for bary in [[0.2, 0.3, 0.5], [-0.5, 1.2, 0.3], [1.0, 0.0, 0.0]] {
            let got = plane_barycentric(at_barycentric(bary, a, b, c), a, b, c);
            assert!((0..3).all(|k| (got[k] - bary[k]).abs() < 1e-5), "{got:?} vs {bary:?}");
        }
    }

    /// Against brute force: no sampled point of the triangle is closer than the one returned.
    #[test]
    fn nothing_on_the_triangle_is_closer() {
        let (a, b, c) = (Vec3::new(0.1, -0.2, 0.3), Vec3::new(1.2, 0.1, -0.4), Vec3::new(0.4, 0.9, 0.2));
        for k in 0..200 {
            let t = k as f32;
            let p = Vec3::new((t * 0.37).sin() * 2.0, (t * 0.71).cos() * 2.0, (t * 0.13).sin() * 2.0);
            let found = (at_barycentric(closest_barycentric(p, a, b, c), a, b, c) - p).length();
            for i in 0..=40 {
                for j in 0..=(40 - i) {
                    let (v, w) = (i as f32 / 40.0, j as f32 / 40.0);
                    let q = at_barycentric([1.0 - v - w, v, w], a, b, c);
                    assert!(found <= (q - p).length() + 1e-5, "point {p}: {found} vs sample {q}");
                }
            }
        }
    }
}
