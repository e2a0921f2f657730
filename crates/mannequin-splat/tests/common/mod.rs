//! Scenes and helpers shared by the integration tests.
#![allow(dead_code)]

use mannequin_splat::{Camera, Colors, Gaussians, Real, Rotations};

/// SplitMix64: a tiny seeded generator so tests need no extra crates.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    pub fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(1e-12, 1.0), self.uniform(0.0, 1.0));
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// How a scene hands rotations and colours to the renderer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RotForm {
    Quaternion,
    Matrix,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorForm {
    Sh(usize),
    Features(usize),
}

/// Owned Gaussians in f64 with every input form available.
#[derive(Clone, Debug)]
pub struct Scene {
    pub means: Vec<f64>,
    pub quats: Vec<f64>,
    pub matrices: Vec<f64>,
    pub scales: Vec<f64>,
    pub opacities: Vec<f64>,
    pub sh: Vec<f64>,
    pub sh_degree: usize,
    pub features: Vec<f64>,
    pub channels: usize,
}

pub fn quat_to_matrix(q: &[f64]) -> [f64; 9] {
    let n = (q.iter().map(|v| v * v).sum::<f64>()).sqrt();
    let [w, x, y, z] = [q[0] / n, q[1] / n, q[2] / n, q[3] / n];
    [
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    ]
}

impl Scene {
    /// `n` Gaussians in a box in front of `look_at([0,0,3] → origin)` cameras, with moderate
    /// sizes and opacities and SH colours that stay positive.
    pub fn random(n: usize, seed: u64, sh_degree: usize, channels: usize) -> Self {
        let mut rng = Rng::new(seed);
        let mut s = Scene {
            means: vec![],
            quats: vec![],
            matrices: vec![],
            scales: vec![],
            opacities: vec![],
            sh: vec![],
            sh_degree,
            features: vec![],
            channels,
        };
        let k = (sh_degree + 1) * (sh_degree + 1);
        for _ in 0..n {
            s.means.extend([rng.uniform(-0.5, 0.5), rng.uniform(-0.4, 0.4), rng.uniform(-0.5, 0.5)]);
            let q: Vec<f64> = (0..4).map(|_| rng.normal()).collect();
            s.quats.extend(&q);
            s.matrices.extend(quat_to_matrix(&q));
            s.scales.extend((0..3).map(|_| rng.uniform(0.03, 0.15)));
            s.opacities.push(rng.uniform(0.3, 0.9));
            for b in 0..k {
                for _ in 0..3 {
                    s.sh.push(if b == 0 { rng.uniform(0.2, 1.2) } else { rng.uniform(-0.15, 0.15) });
                }
            }
            s.features.extend((0..channels).map(|_| rng.uniform(-1.0, 1.0)));
        }
        s
    }

    pub fn len(&self) -> usize {
        self.opacities.len()
    }

    /// Converts every array to `T`.
    pub fn cast<T: Real>(&self) -> SceneT<T> {
        let c = |v: &Vec<f64>| v.iter().map(|&x| T::from_f64(x)).collect();
        SceneT {
            means: c(&self.means),
            quats: c(&self.quats),
            matrices: c(&self.matrices),
            scales: c(&self.scales),
            opacities: c(&self.opacities),
            sh: c(&self.sh),
            sh_degree: self.sh_degree,
            features: c(&self.features),
            channels: self.channels,
        }
    }
}

pub struct SceneT<T> {
    pub means: Vec<T>,
    pub quats: Vec<T>,
    pub matrices: Vec<T>,
    pub scales: Vec<T>,
    pub opacities: Vec<T>,
    pub sh: Vec<T>,
    pub sh_degree: usize,
    pub features: Vec<T>,
    pub channels: usize,
}

impl<T: Real> SceneT<T> {
    pub fn gaussians(&self, rot: RotForm, col: ColorForm) -> Gaussians<'_, T> {
        Gaussians {
            means: &self.means,
            rotations: match rot {
                RotForm::Quaternion => Rotations::Quaternions(&self.quats),
                RotForm::Matrix => Rotations::Matrices(&self.matrices),
            },
            scales: &self.scales,
            opacities: &self.opacities,
            colors: match col {
                ColorForm::Sh(d) => {
                    assert_eq!(d, self.sh_degree, "the scene was made for another SH degree");
                    Colors::Sh { degree: d, coeffs: &self.sh }
                }
                ColorForm::Features(c) => Colors::Features { channels: c, values: &self.features },
            },
        }
    }
}

/// A camera on +z looking at the origin, y up.
pub fn camera(width: usize, height: usize) -> Camera {
    Camera::look_at([0.3, -0.2, 3.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.5, width, height)
}
