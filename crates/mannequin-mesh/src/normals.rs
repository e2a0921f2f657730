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
}
