//! Conservative displacement bounds (after Chen et al. 2025, "Offset Geometric Contact"): in
//! place of continuous collision detection, each particle may move in one substep at most a
//! share under half of its distance to the nearest element it could meet, measured from the
//! common motion of the cloth. A vertex's distance to a triangle, or an edge's to an edge, changes
//! by at most the two sides' largest moves, so with each side moving under half of it no pair
//! reaches zero within the substep: nothing passes through anything, by construction.

use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

use glam::Vec3;
use rayon::prelude::*;

/// Of its distance to the nearest element, the share a particle may move in one substep: under
/// half, so two particles closing on each other never meet.
const SHARE: f32 = 0.45;

/// Per particle, how far it may move in this substep relative to the common motion.
#[derive(Debug, Default)]
pub(super) struct DisplacementBounds {
    /// Per particle, the nearest distance found so far, as f32 bits (non-negative floats order as
    /// their bits do, so an atomic minimum of the bits is the minimum of the values).
    nearest: Vec<AtomicU32>,
}

impl DisplacementBounds {
    /// Starts the substep from `previous`: every particle's nearest distance is set to `outside`
    /// (the nearest any element left out of the contact pairs can be).
    pub fn begin(&mut self, previous: &[[f32; 3]], outside: f32) {
        let start = outside.max(0.0).to_bits();
        self.nearest.clear();
        self.nearest.extend((0..previous.len()).map(|_| AtomicU32::new(start)));
    }

    /// Lowers the nearest distance of each of a pair's `particles` to `distance`.
    pub fn meet(&self, particles: [u32; 4], distance: f32) {
        let bits = distance.max(0.0).to_bits();
        for p in particles {
            self.nearest[p as usize].fetch_min(bits, Relaxed);
        }
    }

    /// Ends the substep: each free particle's move from `previous`, less the `common` motion (the
    /// body's: distances between particles do not change when all move alike, so a garment
    /// carried fast by the body is not held back), is pulled back within a share of its nearest
    /// distance, less twice the farthest a kinematic particle moves from the common motion.
    pub fn limit(
        &self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        common: Vec3,
    ) {
        let displacement = |x: &[f32; 3], p: &[f32; 3]| Vec3::from(*x) - Vec3::from(*p);
        let fastest = (&*positions, previous, inverse_mass)
            .into_par_iter()
            .filter(|(_, _, w)| **w == 0.0)
            .map(|(x, p, _)| (displacement(x, p) - common).length())
            .reduce(|| 0.0, f32::max);
        (positions, previous, inverse_mass, &self.nearest).into_par_iter().for_each(|(x, p, &w, nearest)| {
            if w == 0.0 {
                return;
            }
            let bound = SHARE * (f32::from_bits(nearest.load(Relaxed)) - 2.0 * fastest).max(0.0);
            let p = Vec3::from(*p);
            let own = Vec3::from(*x) - p - common;
            let length = own.length();
            if length > bound {
                *x = (p + common + own * (bound / length)).to_array();
            }
        });
    }
}
