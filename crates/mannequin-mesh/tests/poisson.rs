//! NGD's Poisson solve (Eq. 8): the integrated positions of known Jacobians, its system against
//! the libigl-checked operators, and its backward pass against finite differences.

use mannequin_mesh::poisson::{Jacobian, PoissonSolve};
use mannequin_mesh::{cotan_laplacian, double_areas, gradient_operator};

/// A bumpy 7×6 grid of triangles in 3D.
fn grid() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let (nx, ny) = (7, 6);
    let positions = (0..ny)
        .flat_map(|j| (0..nx).map(move |i| (i, j)))
        .map(|(i, j)| {
            let (x, y) = (i as f32 * 0.1, j as f32 * 0.12);
            [x, y, 0.03 * (7.0 * x).sin() * (5.0 * y).cos()]
        })
        .collect();
    let mut faces = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let v = (j * nx + i) as u32;
            faces.push([v, v + 1, v + nx as u32]);
            faces.push([v + 1, v + nx as u32 + 1, v + nx as u32]);
        }
    }
    (positions, faces)
}

/// Per face, the gradients of the coordinates of `x` (defined on the rest mesh's vertices).
fn jacobians(rest: &[[f32; 3]], faces: &[[u32; 3]], x: &[[f64; 3]]) -> Vec<Jacobian> {
    let g = gradient_operator(rest, faces);
    let g = g.as_ref();
    let mut out = vec![[[0.0; 3]; 3]; faces.len()];
    for (v, xv) in x.iter().enumerate() {
        for (row, value) in g.row_idx_of_col(v).zip(g.val_of_col(v)) {
            for d in 0..3 {
                out[row / 3][d][row % 3] += value * xv[d];
            }
        }
    }
    out
}

/// A deformation of the grid: bent, stretched and sheared, so no rigid motion explains it.
fn deformed(rest: &[[f32; 3]]) -> Vec<[f64; 3]> {
    rest.iter()
        .map(|p| {
            let (x, y, z) = (p[0] as f64, p[1] as f64, p[2] as f64);
            [1.3 * x + 0.2 * y, 0.9 * y + 0.4 * x * x, z + 0.5 * (x - 0.3).powi(2)]
        })
        .collect()
}

#[test]
fn the_gradients_of_a_mesh_integrate_back_to_it() {
    let (rest, faces) = grid();
    let target = deformed(&rest);
    let solve = PoissonSolve::new(&rest, &faces, 17).unwrap();
    let x = solve.solve(&jacobians(&rest, &faces, &target), target[17]);
    let worst =
        x.iter().zip(&target).flat_map(|(a, b)| (0..3).map(move |d| (a[d] - b[d]).abs())).fold(0.0, f64::max);
    assert!(worst < 1e-9, "integrated positions {worst} from the mesh the Jacobians came from");
}

/// Gᵀ A G, from libigl-checked pieces (`igl_oracle.rs`: grad, doublearea, cotmatrix), is the
/// negative cotangent Laplacian: the system the solver factors.
#[test]
fn the_system_is_the_cotangent_stiffness() {
    let (rest, faces) = grid();
    let n = rest.len();
    let g = gradient_operator(&rest, &faces);
    let areas: Vec<f64> = double_areas(&rest, &faces).into_iter().map(|a| a / 2.0).collect();
    let dense = |m: &faer::sparse::SparseColMat<usize, f64>| {
        let mut out = vec![0.0; m.nrows() * m.ncols()];
        for c in 0..m.ncols() {
            for (r, v) in m.as_ref().row_idx_of_col(c).zip(m.as_ref().val_of_col(c)) {
                out[r * m.ncols() + c] += v;
            }
        }
        out
    };
    let (gd, l) = (dense(&g), dense(&cotan_laplacian(&rest, &faces)));
    let rows = 3 * faces.len();
    let mut worst: f64 = 0.0;
    for i in 0..n {
        for j in 0..n {
            let gtag: f64 = (0..rows).map(|r| gd[r * n + i] * areas[r / 3] * gd[r * n + j]).sum();
            worst = worst.max((gtag + l[i * n + j]).abs());
        }
    }
    assert!(worst < 1e-9, "Gᵀ A G differs from −L by {worst}");
}

#[test]
fn the_backward_pass_matches_finite_differences() {
    let (rest, faces) = grid();
    let solve = PoissonSolve::new(&rest, &faces, 0).unwrap();
    let base = jacobians(&rest, &faces, &deformed(&rest));
    let weights: Vec<[f64; 3]> = (0..rest.len())
        .map(|v| [(v as f64 * 0.37).sin(), (v as f64 * 0.71).cos(), 0.3 - (v % 5) as f64 * 0.1])
        .collect();
    let loss = |j: &[Jacobian]| -> f64 {
        solve
            .solve(j, [0.1, 0.2, 0.3])
            .iter()
            .zip(&weights)
            .map(|(x, w)| x[0] * w[0] + x[1] * w[1] + x[2] * w[2])
            .sum()
    };
    let grads = solve.backward(&weights);
    for f in (0..faces.len()).step_by(7) {
        for d in 0..3 {
            for k in 0..3 {
                let (mut plus, mut minus) = (base.clone(), base.clone());
                plus[f][d][k] += 1e-6;
                minus[f][d][k] -= 1e-6;
                let fd = (loss(&plus) - loss(&minus)) / 2e-6;
                let analytic = grads[f][d][k];
                assert!(
                    (fd - analytic).abs() < 1e-6 * fd.abs().max(1.0),
                    "face {f}, J[{d}][{k}]: {analytic} vs {fd}"
                );
            }
        }
    }
}

#[test]
fn meshes_it_cannot_solve_are_refused() {
    let (rest, faces) = grid();
    let e = PoissonSolve::new(&rest, &faces, rest.len()).err().unwrap().to_string();
    assert!(e.contains("pinned") && e.contains("42 vertices"), "{e}");
    // Two triangles that share nothing: the second is free to float.
    let two = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [5.0, 0.0, 0.0],
        [6.0, 0.0, 0.0],
        [5.0, 1.0, 0.0],
    ];
    let e = PoissonSolve::new(&two, &[[0, 1, 2], [3, 4, 5]], 0).err().unwrap().to_string();
    assert!(e.contains("not connected to the pinned vertex"), "{e}");
}

/// NGD's deformation: M = I integrates back to the rest mesh, a constant M to the rest mesh
/// mapped by M (about the pinned vertex), and the backward pass to M matches differences.
#[test]
fn jacobian_fields_deform_the_rest_mesh() {
    use mannequin_mesh::jacobian_field::{deform, deform_backward, rest_jacobians};
    let (rest, faces) = grid();
    let solve = PoissonSolve::new(&rest, &faces, 10).unwrap();
    let jacobians = rest_jacobians(&rest, &faces);
    let p = |v: usize| rest[v].map(f64::from);
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    // A rotation about (1, 2, 2)/3 by 0.5 rad, scaled by 1.2 along x.
    let turn = glam::DMat3::from_axis_angle(glam::DVec3::new(1.0, 2.0, 2.0) / 3.0, 0.5);
    let m: Jacobian =
        std::array::from_fn(|i| std::array::from_fn(|k| turn.col(k)[i] * if k == 0 { 1.2 } else { 1.0 }));
    for (name, matrix) in [("identity", identity), ("turned and stretched", m)] {
        let field = vec![matrix; faces.len()];
        let x = solve.solve(&deform(&field, &jacobians), p(10));
        let worst = (0..rest.len())
            .map(|v| {
                let want: [f64; 3] = std::array::from_fn(|i| {
                    p(10)[i] + (0..3).map(|k| matrix[i][k] * (p(v)[k] - p(10)[k])).sum::<f64>()
                });
                (0..3).map(|d| (x[v][d] - want[d]).abs()).fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{name}: {worst} from the rest mesh mapped by M");
    }
    let field: Vec<Jacobian> = (0..faces.len())
        .map(|f| {
            std::array::from_fn(|i| {
                std::array::from_fn(|k| {
                    f64::from(u8::from(i == k)) + 0.1 * ((f * 3 + i * 5 + k) as f64).sin()
                })
            })
        })
        .collect();
    let weights: Vec<[f64; 3]> =
        (0..rest.len()).map(|v| [(v as f64).cos(), (2.0 * v as f64).sin(), 0.5]).collect();
    let loss = |field: &[Jacobian]| -> f64 {
        let x = solve.solve(&deform(field, &jacobians), p(10));
        x.iter().zip(&weights).map(|(x, w)| x[0] * w[0] + x[1] * w[1] + x[2] * w[2]).sum()
    };
    let grads = deform_backward(&solve.backward(&weights), &jacobians);
    for f in (0..faces.len()).step_by(11) {
        for (i, k) in [(0, 0), (1, 2), (2, 1)] {
            let (mut plus, mut minus) = (field.clone(), field.clone());
            plus[f][i][k] += 1e-6;
            minus[f][i][k] -= 1e-6;
            let fd = (loss(&plus) - loss(&minus)) / 2e-6;
            assert!(
                (fd - grads[f][i][k]).abs() < 1e-6 * fd.abs().max(1.0),
                "face {f}, M[{i}][{k}]: {} vs {fd}",
                grads[f][i][k]
            );
        }
    }
}
