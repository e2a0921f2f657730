//! NGD's deformation in the gradient domain (§2, Eqs. 5–8): each face of the rest mesh carries
//! the Jacobian of the identity map, J_t (its rows the gradients of x, y and z on the face: the
//! projector onto the face's plane, I − n nᵀ); a field of 3×3 matrices M_t deforms them,
//! J'_t = M_t J_t, and the Poisson solve (`poisson.rs`) finds the positions whose gradients best
//! match J'. M_t = I gives back the rest mesh; a constant M gives the rest mesh mapped by M.

use crate::poisson::Jacobian;

/// Per face, the Jacobian of the identity map on the rest mesh; zero on degenerate faces.
pub fn rest_jacobians(rest: &[[f32; 3]], faces: &[[u32; 3]]) -> Vec<Jacobian> {
    faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| glam::DVec3::from(rest[v as usize].map(f64::from)));
            let n = (b - a).cross(c - a);
            if n.length_squared() == 0.0 {
                return [[0.0; 3]; 3];
            }
            let n = n.normalize();
            std::array::from_fn(|i| std::array::from_fn(|j| f64::from(u8::from(i == j)) - n[i] * n[j]))
        })
        .collect()
}

/// J'_t = M_t J_t for every face.
pub fn deform(matrices: &[Jacobian], rest: &[Jacobian]) -> Vec<Jacobian> {
    matrices.iter().zip(rest).map(|(m, j)| product(m, j)).collect()
}

/// ∂ℓ/∂M_t = ∂ℓ/∂J'_t J_tᵀ, from the gradient with respect to the deformed Jacobians.
pub fn deform_backward(d_deformed: &[Jacobian], rest: &[Jacobian]) -> Vec<Jacobian> {
    d_deformed
        .iter()
        .zip(rest)
        .map(|(g, j)| {
            std::array::from_fn(|i| std::array::from_fn(|k| (0..3).map(|l| g[i][l] * j[k][l]).sum()))
        })
        .collect()
}

fn product(a: &Jacobian, b: &Jacobian) -> Jacobian {
    std::array::from_fn(|i| std::array::from_fn(|k| (0..3).map(|l| a[i][l] * b[l][k]).sum()))
}
