//! Face and vertex normals.

use glam::Vec3;

fn corner(p: &[[f32; 3]], i: u32) -> Vec3 {
    Vec3::from(p[i as usize])
}

/// Unnormalised face normal: its length is twice the triangle's area.
pub fn face_area_normal(positions: &[[f32; 3]], tri: [u32; 3]) -> Vec3 {
    let a = corner(positions, tri[0]);
    (corner(positions, tri[1]) - a).cross(corner(positions, tri[2]) - a)
}

/// Unit face normals (zero for degenerate faces).
pub fn face_normals(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Vec<[f32; 3]> {
    faces.iter().map(|&t| face_area_normal(positions, t).normalize_or_zero().to_array()).collect()
}

/// Area-weighted unit vertex normals: the sum of adjacent faces' area normals, normalised.
pub fn vertex_normals(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for &t in faces {
        let n = face_area_normal(positions, t);
        for i in t {
            acc[i as usize] += n;
        }
    }
    acc.into_iter().map(|n| n.normalize_or_zero().to_array()).collect()
}

/// The backward pass of [`vertex_normals`] in f64: given the gradient of a loss with respect to
/// each unit vertex normal, the gradient with respect to each position. A normal n = s/|s| sends
/// back (I − n nᵀ) g / |s| to its sum s of area normals, and each area normal (b − a) × (c − a)
/// sends (b − c) × g' to a, and the like to b and c.
pub fn vertex_normals_backward(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    d_normals: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    use glam::DVec3;
    let p = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
    let mut sums = vec![DVec3::ZERO; positions.len()];
    for &t in faces {
        let n = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
        t.iter().for_each(|&i| sums[i as usize] += n);
    }
    let d_sums: Vec<DVec3> = sums
        .iter()
        .zip(d_normals)
        .map(|(s, g)| {
            let length = s.length();
            if length == 0.0 {
                return DVec3::ZERO;
            }
            let (n, g) = (*s / length, DVec3::from(*g));
            (g - n * n.dot(g)) / length
        })
        .collect();
    let mut d = vec![DVec3::ZERO; positions.len()];
    for &t in faces {
        let g: DVec3 = t.iter().map(|&i| d_sums[i as usize]).sum();
        let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
        // gᵀ((b − a) × (c − a)) = gᵀ(a × b + b × c + c × a), a triple product in each corner.
        d[t[0] as usize] += (b - c).cross(g);
        d[t[1] as usize] += (c - a).cross(g);
        d[t[2] as usize] += (a - b).cross(g);
    }
    d.into_iter().map(|v| v.to_array()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetrahedron_normals_point_outward() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let f = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let fnorm = face_normals(&p, &f);
        assert_eq!(fnorm[0], [0.0, 0.0, -1.0]);
        let vn = vertex_normals(&p, &f);
        // The origin corner's normal is the mean of the three axis faces: -(1,1,1)/sqrt(3).
        let s = -1.0 / 3f32.sqrt();
        for c in vn[0] {
            assert!((c - s).abs() < 1e-6);
        }
    }
    #[test]
    fn vertex_normal_gradients_match_finite_differences() {
        // A bent, irregular patch, so that every vertex normal depends on several faces.
        let p: Vec<[f32; 3]> = vec![
            [0.0, 0.0, 0.1],
            [1.0, 0.1, 0.0],
            [2.1, 0.0, 0.3],
            [0.1, 1.0, 0.2],
            [1.2, 1.1, 0.5],
            [2.0, 0.9, -0.2],
        ];
        let f = [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
        let weights: Vec<[f64; 3]> = (0..p.len()).map(|i| [0.3 + i as f64, -0.7 * i as f64, 1.1]).collect();
        let loss = |q: &[[f32; 3]]| -> f64 {
            vertex_normals(q, &f)
                .iter()
                .zip(&weights)
                .map(|(n, w)| (0..3).map(|c| f64::from(n[c]) * w[c]).sum::<f64>())
                .sum()
        };
        let d = vertex_normals_backward(&p, &f, &weights);
        let h = 1e-3f32;
        for v in 0..p.len() {
            for c in 0..3 {
                let (mut a, mut b) = (p.clone(), p.clone());
                a[v][c] += h;
                b[v][c] -= h;
                let numeric = (loss(&a) - loss(&b)) / (2.0 * f64::from(h));
                assert!((numeric - d[v][c]).abs() < 2e-3, "vertex {v} axis {c}: {numeric} vs {}", d[v][c]);
            }
        }
    }
}
