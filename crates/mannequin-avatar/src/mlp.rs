//! A small fully connected ReLU network over named parameters (the MLP heads of E_s and of
//! iHuman's colour encoder).

use burn::tensor::{Device, Tensor, activation::relu};

use crate::fused_mlp;
use crate::params::{Param, tensor_from};
use mannequin_io::rng::SplitMix64;

#[derive(Clone, Debug)]
pub struct Mlp {
    /// Indices of (weight [in, out], bias [1, out]) in the owner's parameter list.
    pub layers: Vec<(usize, usize)>,
}

impl Mlp {
    /// Input width, then each layer's output width.
    pub fn widths(&self, params: &[Param]) -> Vec<usize> {
        let dims = |l: &(usize, usize)| params[l.0].value.dims();
        self.layers
            .first()
            .map(|l| dims(l)[0])
            .into_iter()
            .chain(self.layers.iter().map(|l| dims(l)[1]))
            .collect()
    }

    /// Appends the layers' parameters to `params`: He-uniform weights from `rng`, zero biases,
    /// and a zero last layer so the network starts as the zero function (no offsets, grey).
    pub fn new(
        name: &str,
        widths: &[usize],
        lr: f64,
        rng: &mut SplitMix64,
        device: &Device,
        params: &mut Vec<Param>,
    ) -> Self {
        let mut layers = Vec::new();
        for (l, w) in widths.windows(2).enumerate() {
            let (fan_in, fan_out) = (w[0], w[1]);
            let last = l + 2 == widths.len();
            let bound = (6.0 / fan_in as f64).sqrt();
            let weights: Vec<f32> = (0..fan_in * fan_out)
                .map(|_| if last { 0.0 } else { rng.range(-bound, bound) as f32 })
                .collect();
            params.push(Param::new(
                &format!("{name}/w{l}"),
                tensor_from(weights, fan_in, fan_out, device),
                lr,
            ));
            params.push(Param::new(
                &format!("{name}/b{l}"),
                tensor_from(vec![0.0; fan_out], 1, fan_out, device),
                lr,
            ));
            layers.push((params.len() - 2, params.len() - 1));
        }
        Self { layers }
    }

    pub fn forward(&self, params: &[Param], x: Tensor<2>) -> Tensor<2> {
        if crate::host_ops::supported(&x.device()) && fused_mlp::supports(&self.widths(params)) {
            let [w0, w1, w2] = [0, 1, 2].map(|l| params[self.layers[l].0].value.clone());
            let [b0, b1, b2] = [0, 1, 2].map(|l| params[self.layers[l].1].value.clone());
            return fused_mlp::mlp(x, [w0, w1, w2], [b0, b1, b2]);
        }
        mlp_tensors(x, self.layers.iter().map(|&(w, b)| (params[w].value.clone(), params[b].value.clone())))
    }
}

/// The network composed from Burn's ops, any depth: ReLU after every layer but the last. It runs
/// where the fused op does not, and is the reference the fused op is held to.
pub fn mlp_tensors(x: Tensor<2>, layers: impl ExactSizeIterator<Item = (Tensor<2>, Tensor<2>)>) -> Tensor<2> {
    let depth = layers.len();
    layers.enumerate().fold(x, |h, (l, (w, b))| {
        let h = h.matmul(w) + b;
        if l + 1 < depth { relu(h) } else { h }
    })
}
