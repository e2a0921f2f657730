//! Cutting a mesh along the zero set of a field and keeping where it is negative, with the cut
//! triangles split where the field crosses zero on their edges (exactly, for a plane): a
//! garment's waist, hems, cuffs and neckline come out as clean curves instead of the body
//! mesh's staircase of whole triangles.

use std::collections::HashMap;

use glam::Vec3;

use crate::TriMesh;

/// The part of `mesh` where `field(p) ≤ 0`, with crossings placed by linear interpolation of the
/// field along each cut edge. Vertices where |field| ≤ `snap` count as on the cut, so no sliver
/// triangles thinner than that are made; a field that is a signed distance makes `snap` metres.
/// Colours and UVs are dropped: the cut creates corners that have neither.
pub fn clip(mesh: &TriMesh, field: impl Fn(Vec3) -> f32, snap: f32) -> TriMesh {
    let side: Vec<f32> = mesh
        .positions
        .iter()
        .map(|&p| {
            let s = field(Vec3::from(p));
            if s.abs() <= snap { 0.0 } else { s }
        })
        .collect();
    let mut positions = mesh.positions.clone();
    let mut crossings: HashMap<(u32, u32), u32> = HashMap::new();
    let mut crossing = |a: u32, b: u32, positions: &mut Vec<[f32; 3]>| {
        *crossings.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (sa, sb) = (side[a as usize], side[b as usize]);
            let t = sa / (sa - sb);
            let (pa, pb) = (Vec3::from(positions[a as usize]), Vec3::from(positions[b as usize]));
            positions.push(pa.lerp(pb, t).to_array());
            (positions.len() - 1) as u32
        })
    };
    let mut faces = Vec::new();
    for &tri in &mesh.faces {
        let s = tri.map(|v| side[v as usize]);
        let inside = s.iter().filter(|&&x| x <= 0.0).count();
        match inside {
            3 => faces.push(tri),
            0 => {}
            _ => {
                // Walk the corners in winding order, emitting kept corners and edge crossings:
                // the kept part is a convex polygon of 3 or 4 corners, fanned into triangles.
                let mut polygon = Vec::with_capacity(4);
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    let (sa, sb) = (s[k], s[(k + 1) % 3]);
                    if sa <= 0.0 {
                        polygon.push(a);
                    }
                    if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
                        polygon.push(crossing(a, b, &mut positions));
                    }
                }
                for k in 1..polygon.len().saturating_sub(1) {
                    faces.push([polygon[0], polygon[k], polygon[k + 1]]);
                }
            }
        }
    }
    // Drop triangles of zero area (all three corners on the plane) and unused vertices.
    faces.retain(|t: &[u32; 3]| t.iter().any(|&v| (v as usize) >= side.len() || side[v as usize] < 0.0));
    let all: Vec<usize> = (0..faces.len()).collect();
    TriMesh::new(positions, faces).submesh(&all).0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square of two triangles cut at x ≤ 0.25: the kept area is exactly a quarter,
    /// and every new corner lies on the plane.
    #[test]
    fn keeps_the_exact_area_below_the_plane() {
        let mesh = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let cut = clip(&mesh, |p| p.x - 0.25, 1e-6);
        let area: f64 = crate::double_areas(&cut.positions, &cut.faces).iter().sum::<f64>() / 2.0;
        assert!((area - 0.25).abs() < 1e-6, "area {area}");
        assert!(cut.positions.iter().all(|p| p[0] <= 0.25 + 1e-6));
        assert_eq!(cut.positions.iter().filter(|p| (p[0] - 0.25).abs() < 1e-6).count(), 3);
        let kept_normals = crate::normals::face_normals(&cut.positions, &cut.faces);
        assert!(kept_normals.iter().all(|n| n[2] > 0.0), "winding kept");
    }
}
