//! Shared helpers for the cloth tests: meshes built from closed forms.

#![allow(dead_code)]

use mannequin_mesh::TriMesh;

/// A grid of `nx` × `ny` vertices with `spacing`, at `origin`, spanning the directions `u` (x index)
/// and `v` (y index); each cell split along the diagonal from (i, j) to (i+1, j+1).
pub fn grid(nx: usize, ny: usize, spacing: f32, origin: [f32; 3], u: [f32; 3], v: [f32; 3]) -> TriMesh {
    let mut positions = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b) = (i as f32 * spacing, j as f32 * spacing);
            positions.push([0, 1, 2].map(|k| origin[k] + a * u[k] + b * v[k]));
        }
    }
    let at = |i: usize, j: usize| (j * nx + i) as u32;
    let mut faces = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    TriMesh::new(positions, faces)
}

/// Index of grid vertex (i, j) in a grid `nx` wide.
pub fn grid_index(nx: usize, i: usize, j: usize) -> u32 {
    (j * nx + i) as u32
}

pub fn distance(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|k| (a[k] - b[k]) * (a[k] - b[k])).sum::<f32>().sqrt()
}

/// A closed box from `min` to `max`, 12 outward-facing triangles.
pub fn box_mesh(min: [f32; 3], max: [f32; 3]) -> TriMesh {
    let corner = |k: usize| [0, 1, 2].map(|a| if k >> a & 1 == 1 { max[a] } else { min[a] });
    let positions = (0..8).map(corner).collect();
    // Corner k has x from bit 0, y from bit 1, z from bit 2.
    let faces = vec![
        [0, 2, 3],
        [0, 3, 1], // z = min
        [4, 5, 7],
        [4, 7, 6], // z = max
        [0, 1, 5],
        [0, 5, 4], // y = min
        [2, 6, 7],
        [2, 7, 3], // y = max
        [0, 4, 6],
        [0, 6, 2], // x = min
        [1, 3, 7],
        [1, 7, 5], // x = max
    ];
    TriMesh::new(positions, faces)
}

/// Signed distance from `p` to the box from `min` to `max` (negative inside).
pub fn box_distance(p: [f32; 3], min: [f32; 3], max: [f32; 3]) -> f32 {
    let q: Vec<f32> = (0..3).map(|k| (min[k] - p[k]).max(p[k] - max[k])).collect();
    let outside = q.iter().map(|&d| d.max(0.0).powi(2)).sum::<f32>().sqrt();
    let inside = q.iter().copied().fold(f32::NEG_INFINITY, f32::max).min(0.0);
    outside + inside
}

/// An icosphere of `radius` at `centre`: an icosahedron's faces split in four `levels` times, the
/// new vertices pushed out to the sphere.
pub fn icosphere(centre: [f32; 3], radius: f32, levels: usize) -> TriMesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut points: Vec<[f32; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |p: [f32; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        p.map(|c| c / l)
    };
    points = points.into_iter().map(unit).collect();
    for _ in 0..levels {
        let mut midpoints = std::collections::HashMap::new();
        let mut split = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let mut mid = |i: u32, j: u32| {
                *midpoints.entry((i.min(j), i.max(j))).or_insert_with(|| {
                    let (p, q) = (points[i as usize], points[j as usize]);
                    points.push(unit([0, 1, 2].map(|k| 0.5 * (p[k] + q[k]))));
                    points.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            split.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = split;
    }
    let positions = points.iter().map(|p| [0, 1, 2].map(|k| centre[k] + radius * p[k])).collect();
    TriMesh::new(positions, faces)
}

/// The radius of the largest ball about `centre` inside a convex mesh: the least distance from
/// the centre to a face's plane.
pub fn inscribed_radius(mesh: &TriMesh, centre: [f32; 3]) -> f32 {
    mesh.faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| mesh.positions[i as usize].map(f64::from));
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            ((0..3).map(|k| (a[k] - centre[k] as f64) * n[k]).sum::<f64>() / l).abs() as f32
        })
        .fold(f32::INFINITY, f32::min)
}
