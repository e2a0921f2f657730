//! Clothing as smooth offsets of the body surface in garment regions.
//!
//! A garment covers each joint's region by a fraction `c_j`; a vertex's membership is
//! `g(v) = Σ_j w_vj c_j` with the skinning weights `w`, which are smooth over the surface, so
//! garment edges fall off smoothly around joints (cuffs at the elbow, hems at the knee). The
//! offset pushes the rest-pose surface out along its normal by the garment's thickness, with
//! low-frequency folds.

use glam::Vec3;

use crate::subject::Outfit;
use mannequin_data::rng::SplitMix64;

use mannequin_body::smpl_joint as joint;

/// One garment's coverage of the joint regions and its geometry.
#[derive(Debug, Clone)]
pub struct GarmentSpec {
    pub coverage: Vec<(usize, f32)>,
    /// Offset along the normal, metres.
    pub thickness: f32,
    /// Fold amplitude, metres.
    pub folds: f32,
}

/// The top and bottom garments drawn on the body for an outfit (a skirt comes on top of this).
pub fn garment_specs(outfit: Outfit) -> (GarmentSpec, GarmentSpec) {
    use joint::*;
    let torso =
        [(SPINE1, 1.0), (SPINE2, 1.0), (SPINE3, 1.0), (L_COLLAR, 1.0), (R_COLLAR, 1.0), (PELVIS, 0.55)];
    let upper_arms = [(L_SHOULDER, 1.0), (R_SHOULDER, 1.0)];
    let forearms = [(L_ELBOW, 1.0), (R_ELBOW, 1.0)];
    let legs = [(PELVIS, 1.0), (L_HIP, 1.0), (R_HIP, 1.0), (L_KNEE, 1.0), (R_KNEE, 1.0)];
    let shorts = [(PELVIS, 1.0), (L_HIP, 1.0), (R_HIP, 1.0)];
    match outfit {
        Outfit::TightShirtTrousers => (
            GarmentSpec {
                coverage: [&torso[..], &upper_arms, &forearms].concat(),
                thickness: 0.006,
                folds: 0.002,
            },
            GarmentSpec { coverage: legs.to_vec(), thickness: 0.01, folds: 0.004 },
        ),
        Outfit::LooseShirtTrousers => (
            GarmentSpec { coverage: [&torso[..], &upper_arms].concat(), thickness: 0.025, folds: 0.012 },
            GarmentSpec { coverage: legs.to_vec(), thickness: 0.014, folds: 0.006 },
        ),
        Outfit::ShirtSkirt => (
            GarmentSpec { coverage: [&torso[..], &upper_arms].concat(), thickness: 0.012, folds: 0.006 },
            GarmentSpec { coverage: shorts.to_vec(), thickness: 0.004, folds: 0.0 },
        ),
        Outfit::Dress => (
            GarmentSpec { coverage: torso.to_vec(), thickness: 0.008, folds: 0.003 },
            GarmentSpec { coverage: shorts.to_vec(), thickness: 0.004, folds: 0.0 },
        ),
    }
}

/// `g(v) = Σ_j w_vj c_j` for every vertex; `weights` is V × J row-major.
pub fn membership(weights: &[f32], num_joints: usize, coverage: &[(usize, f32)]) -> Vec<f32> {
    weights
        .chunks_exact(num_joints)
        .map(|w| coverage.iter().map(|&(j, c)| w.get(j).copied().unwrap_or(0.0) * c).sum::<f32>().min(1.0))
        .collect()
}

/// Hermite smoothstep from 0 at `a` to 1 at `b`.
pub fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A sum of a few random plane waves: smooth, zero-mean folds over the rest surface.
pub struct Folds {
    waves: Vec<(Vec3, f32)>,
}

impl Folds {
    pub fn new(rng: &mut SplitMix64, count: usize) -> Self {
        let waves = (0..count)
            .map(|_| {
                let dir = Vec3::new(rng.normal() as f32, rng.normal() as f32 * 2.0, rng.normal() as f32)
                    .normalize_or_zero();
                // Wavelengths of 8–25 cm, like fabric folds.
                let k = std::f32::consts::TAU / rng.range(0.08, 0.25) as f32;
                (dir * k, rng.range(0.0, std::f64::consts::TAU) as f32)
            })
            .collect();
        Self { waves }
    }

    /// In [−1, 1].
    pub fn at(&self, p: Vec3) -> f32 {
        let n = self.waves.len().max(1) as f32;
        self.waves.iter().map(|(k, phase)| (k.dot(p) + phase).sin()).sum::<f32>() / n.sqrt() / 1.5
    }
}

/// Rest-pose vertices pushed out along their normals by each garment where it covers them.
pub fn clothe(
    rest: &[[f32; 3]],
    normals: &[[f32; 3]],
    garments: &[(&GarmentSpec, &[f32], &Folds)],
) -> Vec<[f32; 3]> {
    rest.iter()
        .zip(normals)
        .enumerate()
        .map(|(v, (p, n))| {
            let p3 = Vec3::from(*p);
            let offset = garments
                .iter()
                .map(|(spec, g, folds)| {
                    let m = smoothstep(0.3, 0.7, g[v]);
                    m * (spec.thickness + spec.folds * folds.at(p3)).max(0.0)
                })
                .fold(0.0f32, f32::max);
            (p3 + Vec3::from(*n) * offset).to_array()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn membership_blends_coverage_by_weight() {
        // Two vertices, three joints: fully on joint 1, and half on joints 1 and 2.
        let w = [0.0, 1.0, 0.0, 0.0, 0.5, 0.5];
        let g = membership(&w, 3, &[(1, 1.0), (2, 0.4)]);
        assert_eq!(g, vec![1.0, 0.7]);
    }

    #[test]
    fn offsets_follow_normals_and_vanish_outside_the_garment() {
        let rest = [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]];
        let normals = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
        let spec = GarmentSpec { coverage: vec![], thickness: 0.02, folds: 0.0 };
        let folds = Folds::new(&mut SplitMix64::new(1), 3);
        let out = clothe(&rest, &normals, &[(&spec, &[1.0, 0.1], &folds)]);
        assert_eq!(out[0], [0.0, 1.0, 0.02]);
        assert_eq!(out[1], [0.0, 0.0, 0.0]);
    }
}
