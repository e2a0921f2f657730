//! NGD's garment geometry (§2–3): a field of per-face 3×3 matrices M_t deforms the base garment's
//! Jacobians (J'_t = M_t J_t), the Poisson solve integrates them into positions, and Adam moves the
//! field down the gradient a loss on those positions sends back, with the Jacobian regulariser
//! λ Σ_t ‖M_t − I‖² pulling toward the base shape. This is NGD's static field J^s; the dynamic
//! field J^D (`dynamic_field.rs`, an MLP on pose) adds to it per pose through
//! [`StaticField::positions_with`], and shares the gradient [`StaticField::step`] returns.

use mannequin_mesh::MeshError;
use mannequin_mesh::jacobian_field::{deform, deform_backward, rest_jacobians};
use mannequin_mesh::poisson::{Jacobian, PoissonSolve};

const IDENTITY: Jacobian = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;

/// The field, its solver and Adam's moments.
pub struct StaticField {
    solve: PoissonSolve,
    jacobians: Vec<Jacobian>,
    pinned: usize,
    pin: [f64; 3],
    pub field: Vec<Jacobian>,
    pub first: Vec<Jacobian>,
    pub second: Vec<Jacobian>,
    steps: i32,
    /// Per face, the sum of the loss gradient's norms ‖∂ℓ/∂M_t‖ since the last
    /// [`Self::take_gradient_norms`] (what adaptive remeshing selects faces by).
    gradient_norms: Vec<f64>,
}

impl StaticField {
    /// The identity field on the base garment `rest`/`faces`; the vertex nearest the centroid is
    /// pinned where it is (the gradients do not fix a translation).
    pub fn new(rest: &[[f32; 3]], faces: &[[u32; 3]]) -> Result<Self, MeshError> {
        let n = rest.len().max(1) as f32;
        let centre: [f32; 3] = std::array::from_fn(|c| rest.iter().map(|p| p[c]).sum::<f32>() / n);
        let distance = |p: &[f32; 3]| (0..3).map(|c| (p[c] - centre[c]).powi(2)).sum::<f32>();
        let pinned =
            (0..rest.len()).min_by(|&a, &b| distance(&rest[a]).total_cmp(&distance(&rest[b]))).unwrap_or(0);
        let f = faces.len();
        Ok(Self {
            solve: PoissonSolve::new(rest, faces, pinned)?,
            jacobians: rest_jacobians(rest, faces),
            pinned,
            pin: rest.get(pinned).map_or([0.0; 3], |p| p.map(f64::from)),
            field: vec![IDENTITY; f],
            first: vec![[[0.0; 3]; 3]; f],
            second: vec![[[0.0; 3]; 3]; f],
            steps: 0,
            gradient_norms: vec![0.0; f],
        })
    }

    /// The fit carried to a new base mesh `rest`/`faces` (a remeshing of the old one, its old
    /// vertices first): the same pinned vertex, with the field and Adam's moments given per new
    /// face, and Adam's step count kept.
    pub fn remeshed(
        &self,
        rest: &[[f32; 3]],
        faces: &[[u32; 3]],
        field: Vec<Jacobian>,
        first: Vec<Jacobian>,
        second: Vec<Jacobian>,
    ) -> Result<Self, MeshError> {
        Ok(Self {
            solve: PoissonSolve::new(rest, faces, self.pinned)?,
            jacobians: rest_jacobians(rest, faces),
            pinned: self.pinned,
            pin: self.pin,
            field,
            first,
            second,
            steps: self.steps,
            gradient_norms: vec![0.0; faces.len()],
        })
    }

    /// The per-face gradient norms summed since the last call, and a fresh start.
    pub fn take_gradient_norms(&mut self) -> Vec<f64> {
        let zero = vec![0.0; self.gradient_norms.len()];
        std::mem::replace(&mut self.gradient_norms, zero)
    }

    /// The garment's rest positions the field integrates to.
    pub fn positions(&self) -> Vec<[f64; 3]> {
        self.solve.solve(&deform(&self.field, &self.jacobians), self.pin)
    }

    /// The positions the field plus `dynamic` (per face, NGD's J^D for one pose) integrates to.
    pub fn positions_with(&self, dynamic: &[Jacobian]) -> Vec<[f64; 3]> {
        let field: Vec<Jacobian> = self
            .field
            .iter()
            .zip(dynamic)
            .map(|(s, d)| std::array::from_fn(|i| std::array::from_fn(|k| s[i][k] + d[i][k])))
            .collect();
        self.solve.solve(&deform(&field, &self.jacobians), self.pin)
    }

    /// λ Σ_t ‖M_t − I‖².
    pub fn regulariser(&self, lambda: f64) -> f64 {
        lambda
            * self
                .field
                .iter()
                .flat_map(|m| (0..9).map(move |k| (m[k / 3][k % 3] - IDENTITY[k / 3][k % 3]).powi(2)))
                .sum::<f64>()
    }

    /// One Adam step of rate `rate` on the loss whose gradient with respect to [`Self::positions`]
    /// is `d_positions`, plus the regulariser at `lambda`. Returns the loss's gradient with
    /// respect to each face's matrix (without the regulariser), which a dynamic field added to
    /// this one shares.
    pub fn step(&mut self, d_positions: &[[f64; 3]], rate: f64, lambda: f64) -> Vec<Jacobian> {
        let d_field = deform_backward(&self.solve.backward(d_positions), &self.jacobians);
        self.steps += 1;
        let (c1, c2) = (1.0 - BETA1.powi(self.steps), 1.0 - BETA2.powi(self.steps));
        for (t, d) in d_field.iter().enumerate() {
            self.gradient_norms[t] += d.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
            for i in 0..3 {
                for k in 0..3 {
                    let g = d[i][k] + 2.0 * lambda * (self.field[t][i][k] - IDENTITY[i][k]);
                    let (m, v) = (&mut self.first[t][i][k], &mut self.second[t][i][k]);
                    *m = BETA1 * *m + (1.0 - BETA1) * g;
                    *v = BETA2 * *v + (1.0 - BETA2) * g * g;
                    self.field[t][i][k] -= rate * (*m / c1) / ((*v / c2).sqrt() + 1e-8);
                }
            }
        }
        d_field
    }
}
