//! The blur under autodiff. It is linear with a symmetric window, so the backward pass is the
//! same blur of the output gradient with the complementary padding, `10 − p`: no state beyond
//! `p` is kept.

use burn::backend::Autodiff;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::{BlurBackend, TAPS};

#[derive(Debug)]
struct BlurStep;

impl<B: BlurBackend> Backward<B, 1> for BlurStep {
    /// The forward padding.
    type State = usize;

    fn backward(self, ops: Ops<Self::State, 1>, grads: &mut Gradients, _checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let [parent] = ops.parents;
        if let Some(node) = parent {
            grads.register::<B>(node.id, B::gaussian_blur(grad, TAPS - 1 - ops.state));
        }
    }
}

impl<B: BlurBackend, C: CheckpointStrategy> BlurBackend for Autodiff<B, C> {
    fn gaussian_blur(x: FloatTensor<Self>, padding: usize) -> FloatTensor<Self> {
        match BlurStep.prepare::<C>([x.node()]).compute_bound().stateful() {
            OpsKind::Tracked(prep) => prep.finish(padding, B::gaussian_blur(x.into_primitive(), padding)),
            OpsKind::UnTracked(prep) => prep.finish(B::gaussian_blur(x.into_primitive(), padding)),
        }
    }
}
