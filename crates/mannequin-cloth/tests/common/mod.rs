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
