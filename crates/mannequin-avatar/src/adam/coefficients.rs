//! Adam's scalars for one step: the moments' decay rates, the bias corrections and the
//! learning rate.

const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPSILON: f64 = 1e-15;

/// Adam's scalars at step `t`, in f64. Each backend rounds each of them once to the tensors'
/// element type, as Burn's scalar ops do, so on Flex the fused update reproduces the tensor-op
/// chain it replaced bit for bit (and training runs and checkpoints do not change).
#[derive(Clone, Copy, Debug)]
pub struct Coefficients {
    pub beta1: f64,
    pub one_minus_beta1: f64,
    pub beta2: f64,
    pub one_minus_beta2: f64,
    /// Bias corrections `1 − β1^t` and `1 − β2^t`.
    pub c1: f64,
    pub c2: f64,
    pub lr: f64,
    pub epsilon: f64,
}

impl Coefficients {
    /// The scalars of step `t ≥ 1` at learning rate `lr`.
    pub fn new(t: i32, lr: f64) -> Self {
        Self {
            beta1: BETA1,
            one_minus_beta1: 1.0 - BETA1,
            beta2: BETA2,
            one_minus_beta2: 1.0 - BETA2,
            c1: 1.0 - BETA1.powi(t),
            c2: 1.0 - BETA2.powi(t),
            lr,
            epsilon: EPSILON,
        }
    }
}
