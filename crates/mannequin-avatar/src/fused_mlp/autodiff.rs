//! The op under autodiff: the backward step recomputes the activations from the saved inputs.

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::MlpBackend;

#[derive(Debug)]
struct MlpStep;

impl<B: MlpBackend> Backward<B, 7> for MlpStep {
    type State = [NodeId; 7];

    fn backward(self, ops: Ops<Self::State, 7>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let [x, w0, b0, w1, b1, w2, b2] =
            ops.state.map(|id| checkpointer.retrieve_node_output::<FloatTensor<B>>(id));
        let (dx, dw0, db0, dw1, db1, dw2, db2) = B::mlp_backward(x, w0, b0, w1, b1, w2, b2, grad);
        for (parent, g) in ops.parents.into_iter().zip([dx, dw0, db0, dw1, db1, dw2, db2]) {
            if let Some(node) = parent {
                grads.register::<B>(node.id, g);
            }
        }
    }
}

impl<B: MlpBackend, C: CheckpointStrategy> MlpBackend for Autodiff<B, C> {
    fn mlp_forward(
        x: FloatTensor<Self>,
        w0: FloatTensor<Self>,
        b0: FloatTensor<Self>,
        w1: FloatTensor<Self>,
        b1: FloatTensor<Self>,
        w2: FloatTensor<Self>,
        b2: FloatTensor<Self>,
    ) -> FloatTensor<Self> {
        let inputs = [x, w0, b0, w1, b1, w2, b2];
        let nodes = inputs.each_ref().map(|t| t.node());
        match MlpStep.prepare::<C>(nodes).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let ids = inputs.each_ref().map(|t| prep.checkpoint(t));
                let [x, w0, b0, w1, b1, w2, b2] = inputs.map(|t| t.into_primitive());
                prep.finish(ids, B::mlp_forward(x, w0, b0, w1, b1, w2, b2))
            }
            OpsKind::UnTracked(prep) => {
                let [x, w0, b0, w1, b1, w2, b2] = inputs.map(|t| t.into_primitive());
                prep.finish(B::mlp_forward(x, w0, b0, w1, b1, w2, b2))
            }
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn mlp_backward(
        x: FloatTensor<Self>,
        w0: FloatTensor<Self>,
        b0: FloatTensor<Self>,
        w1: FloatTensor<Self>,
        b1: FloatTensor<Self>,
        w2: FloatTensor<Self>,
        b2: FloatTensor<Self>,
        grad: FloatTensor<Self>,
    ) -> (
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
        FloatTensor<Self>,
    ) {
        let p = |t: FloatTensor<Self>| t.into_primitive();
        let (a, b, c, d, e, f, g) = B::mlp_backward(p(x), p(w0), p(b0), p(w1), p(b1), p(w2), p(b2), p(grad));
        let n = FloatTensor::<Self>::new;
        (n(a), n(b), n(c), n(d), n(e), n(f), n(g))
    }
}
