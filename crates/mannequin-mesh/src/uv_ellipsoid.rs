//! A UV ellipsoid: the test and benchmark mesh whose every normal and silhouette is known in
//! closed form. Rows of vertices from pole to pole (each pole a row of coincident points, so the
//! mesh is simple to index, not closed), split into two counter-clockwise triangles per quad.

/// `rings` + 1 rows of `segments` points on the ellipsoid with `centre` and semi-axes `radii`,
/// and 2 · `rings` · `segments` triangles facing out.
pub fn uv_ellipsoid(
    centre: [f32; 3],
    radii: [f32; 3],
    rings: usize,
    segments: usize,
) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut positions = Vec::with_capacity((rings + 1) * segments);
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let unit = [theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()];
            positions.push(std::array::from_fn(|k| centre[k] + radii[k] * unit[k]));
        }
    }
    let index = |i: usize, j: usize| (i * segments + j % segments) as u32;
    let faces = (0..rings)
        .flat_map(|i| {
            (0..segments).flat_map(move |j| {
                [
                    [index(i, j), index(i + 1, j + 1), index(i + 1, j)],
                    [index(i, j), index(i, j + 1), index(i + 1, j + 1)],
                ]
            })
        })
        .collect();
    (positions, faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every vertex lies on the ellipsoid, and every face's normal points away from the centre.
    #[test]
    fn points_lie_on_the_ellipsoid_and_faces_face_out() {
        let (centre, radii) = ([0.1, -0.2, 0.3], [0.3, 0.9, 0.2]);
        let (p, f) = uv_ellipsoid(centre, radii, 12, 16);
        assert_eq!((p.len(), f.len()), (13 * 16, 2 * 12 * 16));
        for q in &p {
            let s: f32 = (0..3).map(|k| ((q[k] - centre[k]) / radii[k]).powi(2)).sum();
            assert!((s - 1.0).abs() < 1e-5, "{q:?}");
        }
        let sub = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        for t in f {
            let [a, b, c] = t.map(|i| p[i as usize]);
            let (u, v) = (sub(b, a), sub(c, a));
            let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            let mid = sub(
                [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0, (a[2] + b[2] + c[2]) / 3.0],
                centre,
            );
            let out = n[0] * mid[0] + n[1] * mid[1] + n[2] * mid[2];
            // The triangles with two corners on a pole are degenerate: they have no normal.
            let twice_area = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!(twice_area < 1e-6 || out > 0.0, "face {t:?} faces in: {out}");
        }
    }
}
