//! Adam (Kingma & Ba 2015) over named parameters, each with its own learning rate, with state
//! that a checkpoint can store and restore exactly, so a resumed run continues bit for bit.

use std::path::Path;

use burn::tensor::{Gradients, Tensor};
use mannequin_io::{NpyArray, Npz, NpzWriter};

use crate::error::AvatarError;
use crate::params::{Param, to_npy};

const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPSILON: f64 = 1e-15;

/// First and second moment estimates per parameter, on the parameters' inner device.
#[derive(Clone, Debug)]
pub struct Adam {
    pub step: usize,
    m: Vec<Tensor<2>>,
    v: Vec<Tensor<2>>,
}

impl Adam {
    pub fn new(params: &[Param]) -> Self {
        let zeros = || params.iter().map(|p| p.value.clone().inner().zeros_like()).collect();
        Self { step: 0, m: zeros(), v: zeros() }
    }

    /// One update of every parameter that received a gradient; the updated values are new
    /// leaves that require gradients again.
    pub fn update(&mut self, params: &mut [Param], grads: &Gradients) {
        self.step += 1;
        let t = self.step as i32;
        let (c1, c2) = (1.0 - BETA1.powi(t), 1.0 - BETA2.powi(t));
        for (k, p) in params.iter_mut().enumerate() {
            let Some(g) = p.value.grad(grads) else { continue };
            self.m[k] = self.m[k].clone() * BETA1 + g.clone() * (1.0 - BETA1);
            self.v[k] = self.v[k].clone() * BETA2 + g.square() * (1.0 - BETA2);
            let step = (self.m[k].clone() / c1) / ((self.v[k].clone() / c2).sqrt() + EPSILON) * p.lr;
            p.value = (p.value.clone().inner() - step).autodiff().require_grad();
        }
    }

    pub fn save(&self, params: &[Param], w: &mut NpzWriter) {
        w.add("adam_step", NpyArray::i64(vec![1], vec![self.step as i64]));
        for (k, p) in params.iter().enumerate() {
            w.add(&format!("adam_m/{}", p.name), to_npy(&self.m[k]));
            w.add(&format!("adam_v/{}", p.name), to_npy(&self.v[k]));
        }
    }

    /// Restores moments saved by [`Adam::save`] for the same parameters.
    pub fn load(params: &[Param], npz: &Npz, path: &Path) -> Result<Self, AvatarError> {
        let (_, step) = npz.f64_with_shape("adam_step", &[Some(1)])?;
        let mut adam = Self::new(params);
        adam.step = step[0] as usize;
        for (k, p) in params.iter().enumerate() {
            for (prefix, slot) in [("adam_m/", &mut adam.m[k]), ("adam_v/", &mut adam.v[k])] {
                let mut moment = Param { name: p.name.clone(), value: slot.clone().autodiff(), lr: 0.0 };
                moment.load(npz, prefix, path)?;
                *slot = moment.value.inner();
            }
        }
        Ok(adam)
    }
}
