//! Uniform random points on a triangle mesh's surface: a face chosen with probability
//! proportional to its area, then a uniform point in it by the square-root warp
//! (Osada et al. 2002, eq. 1), each with the face's unit normal.

use glam::DVec3;

use mannequin_io::rng::SplitMix64;

#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSamples {
    pub points: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    pub faces: Vec<u32>,
}

/// A point with barycentric warp inputs `r1, r2` in [0, 1).
pub fn warp(a: DVec3, b: DVec3, c: DVec3, r1: f64, r2: f64) -> DVec3 {
    let s = r1.sqrt();
    a * (1.0 - s) + b * (s * (1.0 - r2)) + c * (s * r2)
}

/// The corners of face `f` in f64.
pub fn corners(positions: &[[f32; 3]], f: [u32; 3]) -> [DVec3; 3] {
    f.map(|i| DVec3::from(positions[i as usize].map(f64::from)))
}

/// Samples points on faces given by index, with their face normals.
pub fn samples_on_faces(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    points: Vec<DVec3>,
    on: Vec<u32>,
) -> SurfaceSamples {
    let normals = on
        .iter()
        .map(|&f| {
            let [a, b, c] = corners(positions, faces[f as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    SurfaceSamples { points, normals, faces: on }
}

/// `count` uniform samples of the surface, reproducible from `seed`. A mesh without area gives
/// no samples.
pub fn sample_surface(positions: &[[f32; 3]], faces: &[[u32; 3]], count: usize, seed: u64) -> SurfaceSamples {
    let mut cumulative = Vec::with_capacity(faces.len());
    let mut total = 0.0;
    for &f in faces {
        let [a, b, c] = corners(positions, f);
        total += 0.5 * (b - a).cross(c - a).length();
        cumulative.push(total);
    }
    if total <= 0.0 {
        return SurfaceSamples { points: Vec::new(), normals: Vec::new(), faces: Vec::new() };
    }
    let mut rng = SplitMix64::new(seed);
    let mut points = Vec::with_capacity(count);
    let mut on = Vec::with_capacity(count);
    for _ in 0..count {
        let t = rng.uniform() * total;
        let f = cumulative.partition_point(|&c| c <= t).min(faces.len() - 1);
        let [a, b, c] = corners(positions, faces[f]);
        points.push(warp(a, b, c, rng.uniform(), rng.uniform()));
        on.push(f as u32);
    }
    samples_on_faces(positions, faces, points, on)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_are_hit_in_proportion_to_area_and_points_lie_on_them() {
        // Two triangles with areas 0.5 and 1 in the z = 0 plane.
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [3.0, 0.0, 0.0], [3.0, 1.0, 0.0]];
        let faces = [[0, 1, 2], [1, 3, 4]];
        let s = sample_surface(&positions, &faces, 40_000, 1);
        let share = s.faces.iter().filter(|&&f| f == 0).count() as f64 / 40_000.0;
        assert!((share - 1.0 / 3.0).abs() < 0.01, "{share}");
        for (p, &f) in s.points.iter().zip(&s.faces) {
            assert_eq!(p.z, 0.0);
            if f == 0 {
                assert!(p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 1.0 + 1e-12);
            } else {
                assert!(p.x >= 1.0 && p.y >= 0.0 && p.y <= (p.x - 1.0) / 2.0 + 1e-12);
            }
        }
        // Within the first triangle, the mean of uniform points is the centroid (1/3, 1/3).
        let inside: Vec<&DVec3> =
            s.points.iter().zip(&s.faces).filter(|(_, f)| **f == 0).map(|(p, _)| p).collect();
        let mean = inside.iter().fold(DVec3::ZERO, |a, p| a + **p) / inside.len() as f64;
        assert!((mean.x - 1.0 / 3.0).abs() < 0.01 && (mean.y - 1.0 / 3.0).abs() < 0.01, "{mean}");
        assert_eq!(s.normals[0], DVec3::Z);
        assert_eq!(sample_surface(&positions, &faces, 10, 1), sample_surface(&positions, &faces, 10, 1));
    }
}
