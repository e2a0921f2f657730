//! Dihedral bending constraints (Eq. 3.21) on every interior edge, C = θ − φ₀ wrapped into
//! (−π, π], with θ from [`crate::dihedral`].
//!
//! A hinge's compliance is the material's 1/B (B the bending rigidity, N·m) times (A₁+A₂)/|e|²,
//! A the areas of its two triangles and e its edge at rest. That makes the stiffness k = B|e|²/(A₁+A₂)
//! and the energy ½kθ² per hinge: a square grid rolled around a grid axis into a cylinder of
//! radius R folds one hinge per cell by θ = s/R, storing ½·B·s²/R² per cell, which is the plate's
//! ½·B·κ²·area. So a material bends alike at any mesh resolution.

use std::ops::Range;

use glam::Vec3;

use crate::coloured_sweep::sweep;
use crate::colouring::greedy_colouring;
use crate::dihedral::{Hinge, wrap_angle};
use crate::rest_shape::HingeRest;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BendingConstraint {
    pub particles: [u32; 4],
    pub rest_angle: f32,
    /// α of this hinge, in 1/(N·m).
    pub compliance: f32,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BendingConstraints {
    /// Hinges in colour order.
    pub hinges: Vec<BendingConstraint>,
    pub colours: Vec<Range<usize>>,
}

impl BendingConstraints {
    /// Constraints on `hinges` of `particles` particles, at their `rest` angles and with
    /// compliances from their rest areas and edges.
    pub fn new(hinges: &[[u32; 4]], rest: &[HingeRest], particles: usize, bend_compliance: f32) -> Self {
        let colouring = greedy_colouring(hinges, particles);
        let hinges = colouring
            .order
            .iter()
            .map(|&k| BendingConstraint {
                particles: hinges[k],
                rest_angle: rest[k].angle,
                compliance: bend_compliance * rest[k].areas / rest[k].edge_squared.max(f32::MIN_POSITIVE),
            })
            .collect();
        Self { hinges, colours: colouring.colours }
    }

    pub fn len(&self) -> usize {
        self.hinges.len()
    }

    /// One sweep over every hinge; `lambda` holds the multipliers of this substep, in colour order.
    pub fn project(&self, positions: &mut [[f32; 3]], inverse_mass: &[f32], lambda: &mut [f32], dt: f32) {
        let inv_dt2 = 1.0 / (dt * dt);
        sweep(&self.colours, &self.hinges, lambda, positions, |hinge, lambda, x| {
            let w = hinge.particles.map(|i| inverse_mass[i as usize]);
            if w == [0.0; 4] {
                return;
            }
            // SAFETY: the hinge's four particles belong to it alone within its colour.
            let p = hinge.particles.map(|i| unsafe { x.get(i) });
            let Some((angle, grad)) = (Hinge { a: p[0], b: p[1], c: p[2], d: p[3] }).angle_and_gradient()
            else {
                return;
            };
            let alpha = hinge.compliance * inv_dt2;
            let weighted: f32 = (0..4).map(|k| w[k] * grad[k].length_squared()).sum();
            let denominator = weighted + alpha;
            if !(denominator > 0.0 && denominator.is_finite()) {
                return;
            }
            let c = wrap_angle(angle - hinge.rest_angle);
            let delta = (-c - alpha * *lambda) / denominator;
            *lambda += delta;
            for k in 0..4 {
                let moved: Vec3 = p[k] + w[k] * delta * grad[k];
                // SAFETY: as above.
                unsafe { x.set(hinge.particles[k], moved) };
            }
        });
    }
}
