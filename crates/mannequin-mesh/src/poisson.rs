//! NGD's Poisson solve (Eq. 8): the vertex positions whose per-face gradients best match given
//! per-face Jacobians, min_x Σ_f A_f ‖∇_f x − J_f‖², that is (Gᵀ A G) x = Gᵀ A J, with G the
//! gradient operator and A the face areas of the rest mesh. Gᵀ A G is the cotangent stiffness
//! matrix (−L, `cotan_laplacian`); one vertex is pinned, since gradients do not fix a
//! translation. The matrix depends only on the rest mesh, so it is factored once (sparse
//! Cholesky), and the backward pass reuses the factor: x is linear in J, and ∂ℓ/∂J =
//! A G L_ff⁻¹ ∂ℓ/∂x_free.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

use crate::{MeshError, cotan_laplacian, double_areas, gradient_operator};

/// The factored system of one rest mesh.
pub struct PoissonSolve {
    /// 3F×V, face-major rows.
    gradient: SparseColMat<usize, f64>,
    areas: Vec<f64>,
    /// Each vertex's index among the free ones (None for the pinned one).
    slot: Vec<Option<usize>>,
    llt: Llt<usize, f64>,
    /// L_fp: the stiffness coupling each free vertex to the pinned one.
    coupling: Vec<f64>,
}

/// Per face, the Jacobian of the map: row d is the gradient of coordinate d on the face.
pub type Jacobian = [[f64; 3]; 3];

impl PoissonSolve {
    /// Factors the system of the mesh `rest`/`faces` with vertex `pinned` held.
    pub fn new(rest: &[[f32; 3]], faces: &[[u32; 3]], pinned: usize) -> Result<Self, MeshError> {
        let n = rest.len();
        if pinned >= n {
            return Err(MeshError::PinnedVertex { pinned, count: n });
        }
        let stiffness = cotan_laplacian(rest, faces);
        let mut slot = vec![None; n];
        let mut next = 0;
        for (v, s) in slot.iter_mut().enumerate() {
            if v != pinned {
                *s = Some(next);
                next += 1;
            }
        }
        let mut triplets = Vec::new();
        let mut coupling = vec![0.0; n - 1];
        for col in 0..n {
            for (row, value) in stiffness.as_ref().row_idx_of_col(col).zip(stiffness.as_ref().val_of_col(col))
            {
                // −L: the positive semi-definite stiffness.
                match (slot[row], slot[col]) {
                    (Some(r), Some(c)) => triplets.push(Triplet::new(r, c, -value)),
                    (Some(r), None) => coupling[r] -= value,
                    _ => {}
                }
            }
        }
        let free = SparseColMat::try_new_from_triplets(n - 1, n - 1, &triplets)
            .map_err(|e| MeshError::Poisson(format!("{e:?}")))?;
        let llt = free.sp_cholesky(Side::Lower).map_err(|e| MeshError::Poisson(format!("{e:?}")))?;
        let areas = double_areas(rest, faces).into_iter().map(|a| a / 2.0).collect();
        Ok(Self { gradient: gradient_operator(rest, faces), areas, slot, llt, coupling })
    }

    /// The positions whose gradients best match `jacobians` (one per face), with the pinned
    /// vertex at `pin`.
    pub fn solve(&self, jacobians: &[Jacobian], pin: [f64; 3]) -> Vec<[f64; 3]> {
        let n = self.slot.len();
        // b = Gᵀ A J per coordinate, then b_f − L_fp x_p.
        let mut rhs = Mat::<f64>::zeros(n - 1, 3);
        for (r, f, dim, weight) in self.weighted_gradient() {
            for d in 0..3 {
                rhs[(r, d)] += weight * jacobians[f][d][dim];
            }
        }
        for (r, c) in self.coupling.iter().enumerate() {
            for d in 0..3 {
                rhs[(r, d)] -= c * pin[d];
            }
        }
        self.llt.solve_in_place(rhs.as_mut());
        (0..n)
            .map(|v| match self.slot[v] {
                Some(r) => [rhs[(r, 0)], rhs[(r, 1)], rhs[(r, 2)]],
                None => pin,
            })
            .collect()
    }

    /// ∂ℓ/∂J for a loss whose gradient with respect to the solved positions is `d_positions`
    /// (the pinned vertex's entry is ignored: it does not depend on J).
    pub fn backward(&self, d_positions: &[[f64; 3]]) -> Vec<Jacobian> {
        let n = self.slot.len();
        let mut y = Mat::<f64>::zeros(n - 1, 3);
        for (slot, d_x) in self.slot.iter().zip(d_positions) {
            if let Some(r) = *slot {
                (0..3).for_each(|d| y[(r, d)] = d_x[d]);
            }
        }
        self.llt.solve_in_place(y.as_mut());
        let mut out = vec![[[0.0; 3]; 3]; self.areas.len()];
        for (r, f, dim, weight) in self.weighted_gradient() {
            for d in 0..3 {
                out[f][d][dim] += weight * y[(r, d)];
            }
        }
        out
    }

    /// The entries of A G on the free vertices: (free vertex, face, dimension, A_f G value).
    fn weighted_gradient(&self) -> impl Iterator<Item = (usize, usize, usize, f64)> + '_ {
        let g = self.gradient.as_ref();
        self.slot.iter().enumerate().filter_map(|(v, s)| s.map(|r| (v, r))).flat_map(move |(v, r)| {
            g.row_idx_of_col(v)
                .zip(g.val_of_col(v))
                .map(move |(row, value)| (r, row / 3, row % 3, self.areas[row / 3] * value))
        })
    }
}
