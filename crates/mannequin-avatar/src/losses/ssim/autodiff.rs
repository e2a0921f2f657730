//! The fused SSIM under autodiff: the forward runs on the inner backend and registers a step
//! that calls its `ssim_backward` with the saved moments, asking only for the gradients of the
//! inputs that are tracked.

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::SsimBackend;

#[derive(Debug)]
struct SsimStep;

impl<B: SsimBackend> Backward<B, 2> for SsimStep {
    /// The two input nodes and the moments.
    type State = ([NodeId; 2], FloatTensor<B>);

    fn backward(self, ops: Ops<Self::State, 2>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let ([x_id, y_id], moments) = ops.state;
        let x = checkpointer.retrieve_node_output::<FloatTensor<B>>(x_id);
        let y = checkpointer.retrieve_node_output::<FloatTensor<B>>(y_id);
        let [px, py] = ops.parents;
        let (dx, dy) = B::ssim_backward(x, y, moments, grad, px.is_some(), py.is_some());
        for (parent, g) in [(px, dx), (py, dy)] {
            if let Some(node) = parent {
                grads.register::<B>(node.id, g);
            }
        }
    }
}

impl<B: SsimBackend, C: CheckpointStrategy> SsimBackend for Autodiff<B, C> {
    fn ssim_forward(x: FloatTensor<Self>, y: FloatTensor<Self>) -> (FloatTensor<Self>, FloatTensor<Self>) {
        match SsimStep.prepare::<C>([x.node(), y.node()]).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let ids = [prep.checkpoint(&x), prep.checkpoint(&y)];
                let (map, moments) = B::ssim_forward(x.into_primitive(), y.into_primitive());
                (prep.finish((ids, moments.clone()), map), FloatTensor::<Self>::new(moments))
            }
            OpsKind::UnTracked(prep) => {
                let (map, moments) = B::ssim_forward(x.into_primitive(), y.into_primitive());
                (prep.finish(map), FloatTensor::<Self>::new(moments))
            }
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn ssim_backward(
        x: FloatTensor<Self>,
        y: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        want_x: bool,
        want_y: bool,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let p = |t: FloatTensor<Self>| t.into_primitive();
        let (dx, dy) = B::ssim_backward(p(x), p(y), p(moments), p(grad), want_x, want_y);
        (FloatTensor::<Self>::new(dx), FloatTensor::<Self>::new(dy))
    }
}
