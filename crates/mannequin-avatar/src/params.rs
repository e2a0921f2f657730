//! Named learnable tensors with a learning rate each: the unit the optimiser updates and a
//! checkpoint stores. Keeping them as plain named arrays makes checkpoints ordinary `.npz`
//! files that numpy can open.

use std::ops::RangeInclusive;

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_io::{NpyArray, Npz, NpzWriter};

use crate::error::AvatarError;

#[derive(Clone, Debug)]
pub struct Param {
    pub name: String,
    /// A leaf tensor on an autodiff device that requires gradients.
    pub value: Tensor<2>,
    pub lr: f64,
}

/// A tensor's values on the host, row-major.
pub fn host<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().iter::<f32>().collect()
}

/// The rows of an `[N, 3]` tensor on the host.
pub fn host_rows(t: Tensor<2>) -> Vec<[f32; 3]> {
    host(t).chunks_exact(3).map(|v| [v[0], v[1], v[2]]).collect()
}

/// Host copy of a tensor, for `.npz`.
pub fn to_npy(t: &Tensor<2>) -> NpyArray {
    let [r, c] = t.dims();
    NpyArray::f32(vec![r, c], t.clone().into_data().iter::<f32>().collect())
}

/// A `[rows, cols]` f32 tensor from host values.
pub fn tensor_from(values: Vec<f32>, rows: usize, cols: usize, device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(values, [rows, cols]), (device, DType::F32))
}

/// Marks a leaf as trainable where the device records gradients; inference devices have none.
pub fn trainable(t: Tensor<2>) -> Tensor<2> {
    if t.is_autodiff() { t.require_grad() } else { t }
}

impl Param {
    pub fn new(name: &str, value: Tensor<2>, lr: f64) -> Self {
        Self { name: name.to_string(), value: trainable(value), lr }
    }

    /// Reads `{prefix}{name}` from `npz`, which must have this parameter's shape and only values
    /// in `allowed` (finite always).
    pub fn load(&mut self, npz: &Npz, prefix: &str, allowed: RangeInclusive<f64>) -> Result<(), AvatarError> {
        let [r, c] = self.value.dims();
        let key = format!("{prefix}{}", self.name);
        let (_, values) = npz.f64_in_range(&key, &[Some(r), Some(c)], allowed)?;
        let device = self.value.device();
        self.value = trainable(tensor_from(values.into_iter().map(|v| v as f32).collect(), r, c, &device));
        Ok(())
    }

    pub fn save(&self, w: &mut NpzWriter, prefix: &str) {
        w.add(&format!("{prefix}{}", self.name), to_npy(&self.value));
    }
}
