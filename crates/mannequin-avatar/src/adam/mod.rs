//! Adam (Kingma & Ba 2015) over named parameters, each with its own learning rate, with state
//! that a checkpoint can store and restore exactly, so a resumed run continues bit for bit.
//! The update is fused (`fused.rs`): one backend op a parameter on Flex (`flex.rs`), one kernel
//! launch for all of them on CubeCL (`cube.rs` and `kernels.rs`).

mod coefficients;
mod cube;
mod flex;
mod fused;
mod kernels;

use burn::tensor::{Gradients, Tensor};
use mannequin_io::limits::FLOAT32;
use mannequin_io::{NpyArray, Npz, NpzWriter};

use crate::error::AvatarError;
use crate::params::{Param, to_npy};
use coefficients::Coefficients;
use fused::Update;

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
    /// leaves that require gradients again. The value and moments are moved into the op, so
    /// where nothing else holds their buffers they are updated in place.
    pub fn update(&mut self, params: &mut [Param], grads: &Gradients) {
        self.step += 1;
        let mut updated = Vec::new();
        let mut updates = Vec::new();
        for (k, p) in params.iter_mut().enumerate() {
            let Some(grad) = p.value.grad(grads) else { continue };
            updates.push(Update {
                param: take(&mut p.value).inner(),
                grad,
                m: take(&mut self.m[k]),
                v: take(&mut self.v[k]),
                coefficients: Coefficients::new(self.step as i32, p.lr),
            });
            updated.push(k);
        }
        for (k, (value, m, v)) in updated.into_iter().zip(fused::steps(updates)) {
            (params[k].value, self.m[k], self.v[k]) = (value.autodiff().require_grad(), m, v);
        }
    }

    /// Writes the step and moments as `{prefix}adam_step`, `{prefix}adam_m/<name>` and
    /// `{prefix}adam_v/<name>`: a prefix keeps two optimisers apart in one checkpoint.
    pub fn save(&self, params: &[Param], w: &mut NpzWriter, prefix: &str) {
        w.add(&format!("{prefix}adam_step"), NpyArray::i64(vec![1], vec![self.step as i64]));
        for (k, p) in params.iter().enumerate() {
            w.add(&format!("{prefix}adam_m/{}", p.name), to_npy(&self.m[k]));
            w.add(&format!("{prefix}adam_v/{}", p.name), to_npy(&self.v[k]));
        }
    }

    /// Restores moments saved by [`Adam::save`] for the same parameters, `step` steps in (the
    /// caller checks it against the run). Second moments are averages of squares: a negative one
    /// is refused, as its square root would turn the next update into NaN.
    pub fn load(params: &[Param], npz: &Npz, step: usize, prefix: &str) -> Result<Self, AvatarError> {
        let mut adam = Self::new(params);
        adam.step = step;
        for (k, p) in params.iter().enumerate() {
            for (moment, slot, allowed) in
                [("adam_m/", &mut adam.m[k], FLOAT32), ("adam_v/", &mut adam.v[k], 0.0..=*FLOAT32.end())]
            {
                let mut moment_param =
                    Param { name: p.name.clone(), value: slot.clone().autodiff(), lr: 0.0 };
                moment_param.load(npz, &format!("{prefix}{moment}"), allowed)?;
                // Checkpoints store f32; the op wants the parameter's dtype.
                *slot = moment_param.value.inner().cast(p.value.dtype());
            }
        }
        Ok(adam)
    }
}

/// Moves `t` out, leaving an empty tensor of its kind, so the caller holds the only handle.
fn take(t: &mut Tensor<2>) -> Tensor<2> {
    let empty = Tensor::empty([0, 0], (&t.device(), t.dtype()));
    std::mem::replace(t, empty)
}
