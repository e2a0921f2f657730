//! NGD's dynamic Jacobian field J^D (§3.1): a multilayer perceptron from a face's place on the
//! base garment and the frame's pose code γ(θ) to a 3×3 matrix added to the static field's M_t,
//! so that the garment can change shape with the pose (a sleeve's folds as the arm rises) where
//! skinning alone cannot. The last layer starts at zero: the fit begins from the static field.
//! A face's place enters as its rest centroid, centred and scaled by the base garment's, with
//! sines and cosines of 2^k π x (k < [`OCTAVES`]) so the network can vary quickly across the
//! garment. Forward and backward are written out (ReLU layers), with Adam on every weight.

use glam::DVec3;
use mannequin_io::rng::SplitMix64;
use mannequin_mesh::poisson::Jacobian;
use rayon::prelude::*;

/// Frequencies of the positional encoding.
const OCTAVES: usize = 4;
/// Positional features per face: the centroid and a sine and cosine per octave and axis.
const PLACE: usize = 3 + 6 * OCTAVES;
const HIDDEN: usize = 64;
const OUT: usize = 9;
const BETA1: f32 = 0.9;
const BETA2: f32 = 0.999;
/// Faces per parallel chunk.
const CHUNK: usize = 256;

/// A dense layer `out × inputs` with Adam's moments.
#[derive(Debug, Clone)]
struct Layer {
    inputs: usize,
    weights: Vec<f32>,
    bias: Vec<f32>,
    first: Vec<f32>,
    second: Vec<f32>,
}

impl Layer {
    /// He-uniform weights, or zeros.
    fn new(inputs: usize, out: usize, rng: Option<&mut SplitMix64>) -> Self {
        let bound = (6.0 / inputs as f64).sqrt();
        let weights = match rng {
            Some(r) => (0..inputs * out).map(|_| r.range(-bound, bound) as f32).collect(),
            None => vec![0.0; inputs * out],
        };
        let n = weights.len() + out;
        Self { inputs, weights, bias: vec![0.0; out], first: vec![0.0; n], second: vec![0.0; n] }
    }

    fn out(&self) -> usize {
        self.bias.len()
    }

    fn apply(&self, x: &[f32], y: &mut [f32]) {
        for (o, y) in y.iter_mut().enumerate() {
            let row = &self.weights[o * self.inputs..(o + 1) * self.inputs];
            *y = self.bias[o] + row.iter().zip(x).map(|(w, v)| w * v).sum::<f32>();
        }
    }

    /// Adds dy xᵀ and dy to `grad` (weights then bias), and returns Wᵀ dy.
    fn back(&self, x: &[f32], dy: &[f32], grad: &mut [f32]) -> Vec<f32> {
        let mut dx = vec![0.0; self.inputs];
        for (o, &g) in dy.iter().enumerate() {
            if g == 0.0 {
                continue;
            }
            let row = &self.weights[o * self.inputs..(o + 1) * self.inputs];
            for i in 0..self.inputs {
                grad[o * self.inputs + i] += g * x[i];
                dx[i] += row[i] * g;
            }
            grad[self.weights.len() + o] += g;
        }
        dx
    }

    fn adam(&mut self, grad: &[f32], rate: f32, step: i32) {
        let (c1, c2) = (1.0 - BETA1.powi(step), 1.0 - BETA2.powi(step));
        let n = self.weights.len();
        for (k, &g) in grad.iter().enumerate() {
            self.first[k] = BETA1 * self.first[k] + (1.0 - BETA1) * g;
            self.second[k] = BETA2 * self.second[k] + (1.0 - BETA2) * g * g;
            let delta = rate * (self.first[k] / c1) / ((self.second[k] / c2).sqrt() + 1e-8);
            if k < n {
                self.weights[k] -= delta;
            } else {
                self.bias[k - n] -= delta;
            }
        }
    }
}

/// What the backward pass needs of one forward pass: per face the inputs and both hidden layers.
pub struct Activations {
    inputs: Vec<f32>,
    hidden: [Vec<f32>; 2],
}

#[derive(Debug, Clone)]
pub struct DynamicField {
    layers: [Layer; 3],
    centre: DVec3,
    scale: f64,
    /// Per face of the current base, its positional features.
    places: Vec<[f32; PLACE]>,
    steps: i32,
}

impl DynamicField {
    /// A field for pose codes of length `code`, on the base `rest`/`faces`; weights drawn from
    /// `seed`, the output layer zero.
    pub fn new(code: usize, rest: &[[f32; 3]], faces: &[[u32; 3]], seed: u64) -> Self {
        let mut rng = SplitMix64::new(seed);
        let n = rest.len().max(1) as f64;
        let centre = rest.iter().map(|p| DVec3::from(p.map(f64::from))).sum::<DVec3>() / n;
        let scale = rest
            .iter()
            .map(|p| (DVec3::from(p.map(f64::from)) - centre).abs().max_element())
            .fold(1e-6, f64::max);
        let mut field = Self {
            layers: [
                Layer::new(PLACE + code, HIDDEN, Some(&mut rng)),
                Layer::new(HIDDEN, HIDDEN, Some(&mut rng)),
                Layer::new(HIDDEN, OUT, None),
            ],
            centre,
            scale,
            places: Vec::new(),
            steps: 0,
        };
        field.set_base(rest, faces);
        field
    }

    /// The faces' features on a new base (after remeshing): the network itself does not depend
    /// on the triangulation.
    pub fn set_base(&mut self, rest: &[[f32; 3]], faces: &[[u32; 3]]) {
        self.places = faces
            .iter()
            .map(|t| {
                let c = t.iter().map(|&v| DVec3::from(rest[v as usize].map(f64::from))).sum::<DVec3>() / 3.0;
                let x = (c - self.centre) / self.scale;
                let mut f = [0.0f32; PLACE];
                for a in 0..3 {
                    f[a] = x[a] as f32;
                    for k in 0..OCTAVES {
                        let phase = std::f64::consts::PI * f64::from(1u32 << k) * x[a];
                        f[3 + 6 * k + 2 * a] = phase.sin() as f32;
                        f[3 + 6 * k + 2 * a + 1] = phase.cos() as f32;
                    }
                }
                f
            })
            .collect();
    }

    /// Per face, M^D_t for the pose code `code`.
    pub fn forward(&self, code: &[f32]) -> (Vec<Jacobian>, Activations) {
        let width = PLACE + code.len();
        let faces = self.places.len();
        let mut inputs = vec![0.0f32; faces * width];
        let mut hidden = [vec![0.0f32; faces * HIDDEN], vec![0.0f32; faces * HIDDEN]];
        let mut out = vec![[[0.0; 3]; 3]; faces];
        let [h1, h2] = &mut hidden;
        inputs
            .par_chunks_mut(width * CHUNK)
            .zip(h1.par_chunks_mut(HIDDEN * CHUNK))
            .zip(h2.par_chunks_mut(HIDDEN * CHUNK))
            .zip(out.par_chunks_mut(CHUNK))
            .zip(self.places.par_chunks(CHUNK))
            .for_each(|((((x, a), b), m), places)| {
                let mut y = [0.0f32; OUT];
                for (f, place) in places.iter().enumerate() {
                    let x = &mut x[f * width..(f + 1) * width];
                    x[..PLACE].copy_from_slice(place);
                    x[PLACE..].copy_from_slice(code);
                    let a = &mut a[f * HIDDEN..(f + 1) * HIDDEN];
                    self.layers[0].apply(x, a);
                    a.iter_mut().for_each(|v| *v = v.max(0.0));
                    let b = &mut b[f * HIDDEN..(f + 1) * HIDDEN];
                    self.layers[1].apply(a, b);
                    b.iter_mut().for_each(|v| *v = v.max(0.0));
                    self.layers[2].apply(b, &mut y);
                    m[f] = std::array::from_fn(|i| std::array::from_fn(|j| f64::from(y[3 * i + j])));
                }
            });
        (out, Activations { inputs, hidden })
    }

    /// The gradient of every weight (per layer: weights, then bias) of a loss whose gradient
    /// with respect to the forward pass's output is `d_out`.
    fn gradients(&self, acts: &Activations, d_out: &[Jacobian]) -> [Vec<f32>; 3] {
        let width = self.layers[0].inputs;
        let sizes = self.layers.each_ref().map(|l| l.weights.len() + l.out());
        let zero = || sizes.map(|n| vec![0.0f32; n]);
        // Per chunk, then summed in chunk order: the same sums whatever the threads did.
        let partial: Vec<[Vec<f32>; 3]> = d_out
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(chunk, d)| {
                let mut g = zero();
                for (k, d) in d.iter().enumerate() {
                    let f = chunk * CHUNK + k;
                    let dy: Vec<f32> = d.iter().flatten().map(|&v| v as f32).collect();
                    let (x, a, b) = (
                        &acts.inputs[f * width..(f + 1) * width],
                        &acts.hidden[0][f * HIDDEN..(f + 1) * HIDDEN],
                        &acts.hidden[1][f * HIDDEN..(f + 1) * HIDDEN],
                    );
                    let mut db = self.layers[2].back(b, &dy, &mut g[2]);
                    db.iter_mut().zip(b).for_each(|(d, &v)| *d = if v > 0.0 { *d } else { 0.0 });
                    let mut da = self.layers[1].back(a, &db, &mut g[1]);
                    da.iter_mut().zip(a).for_each(|(d, &v)| *d = if v > 0.0 { *d } else { 0.0 });
                    self.layers[0].back(x, &da, &mut g[0]);
                }
                g
            })
            .collect();
        partial.into_iter().fold(zero(), |mut a, b| {
            a.iter_mut().zip(&b).for_each(|(x, y)| x.iter_mut().zip(y).for_each(|(u, v)| *u += v));
            a
        })
    }

    /// One Adam step of rate `rate` down the gradient `d_out` of the forward pass `acts`.
    pub fn step(&mut self, acts: &Activations, d_out: &[Jacobian], rate: f64) {
        let grads = self.gradients(acts, d_out);
        self.steps += 1;
        for (layer, g) in self.layers.iter_mut().zip(&grads) {
            layer.adam(g, rate as f32, self.steps);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every layer's gradient against central differences of ℓ = Σ c · M^D (the output layer
    /// made nonzero first, so that the gradient reaches the inner layers).
    #[test]
    fn gradients_match_finite_differences() {
        let rest = vec![[0.0, 0.0, 0.0], [0.3, 0.0, 0.1], [0.0, 0.4, 0.0], [0.2, 0.5, 0.3]];
        let faces = [[0, 1, 2], [1, 3, 2]];
        let mut field = DynamicField::new(2, &rest, &faces, 3);
        let mut rng = SplitMix64::new(9);
        field.layers[2].weights.iter_mut().for_each(|w| *w = rng.range(-0.3, 0.3) as f32);
        let code = [0.7, -1.2];
        let weights: Vec<Jacobian> =
            (0..2).map(|_| std::array::from_fn(|_| std::array::from_fn(|_| rng.range(-1.0, 1.0)))).collect();
        let loss = |f: &DynamicField| -> f64 {
            let (m, _) = f.forward(&code);
            m.iter()
                .zip(&weights)
                .map(|(a, b)| (0..9).map(|k| a[k / 3][k % 3] * b[k / 3][k % 3]).sum::<f64>())
                .sum()
        };
        let (_, acts) = field.forward(&code);
        let grads = field.gradients(&acts, &weights);
        let (mut checked, mut kinks) = (0, 0);
        for (layer, grad) in grads.iter().enumerate() {
            for k in (0..grad.len()).step_by(37) {
                let n = field.layers[layer].weights.len();
                let nudge = |f: &mut DynamicField, h: f32| {
                    if k < n {
                        f.layers[layer].weights[k] += h;
                    } else {
                        f.layers[layer].bias[k - n] += h;
                    }
                };
                let (mut a, mut b) = (field.clone(), field.clone());
                nudge(&mut a, 1e-2);
                nudge(&mut b, -1e-2);
                // A ReLU switching between the two nudges puts a kink inside the difference.
                let pattern = |f: &DynamicField| -> Vec<bool> {
                    let (_, acts) = f.forward(&code);
                    acts.hidden.iter().flatten().map(|&v| v > 0.0).collect()
                };
                if pattern(&a) != pattern(&b) {
                    kinks += 1;
                    continue;
                }
                checked += 1;
                let numeric = (loss(&a) - loss(&b)) / 2e-2;
                let analytic = f64::from(grad[k]);
                assert!(
                    (numeric - analytic).abs() < 1e-3 * (1.0 + analytic.abs()),
                    "layer {layer} parameter {k}: {numeric} vs {analytic}"
                );
            }
        }
        assert!(kinks * 10 < checked, "{kinks} parameters skipped at kinks, {checked} checked");
    }
}
