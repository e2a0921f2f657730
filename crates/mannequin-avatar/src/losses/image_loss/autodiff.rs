//! The op under autodiff: the SSIM's moments are kept from the forward; target and mask are
//! constants.

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::{ImageLossBackend, ImageLossConfig};

#[derive(Debug)]
struct ImageLossStep;

/// The prediction's and alpha's nodes; target, mask and moments; the weights.
type Saved<B> = ([NodeId; 2], [FloatTensor<B>; 3], ImageLossConfig);

impl<B: ImageLossBackend> Backward<B, 2> for ImageLossStep {
    type State = Saved<B>;

    fn backward(self, ops: Ops<Self::State, 2>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let ([pred, alpha], [target, mask, moments], config) = ops.state;
        let [pred, alpha] = [pred, alpha].map(|id| checkpointer.retrieve_node_output::<FloatTensor<B>>(id));
        let (d_pred, d_alpha) = B::image_loss_backward(pred, alpha, target, mask, moments, grad, config);
        for (parent, g) in ops.parents.into_iter().zip([d_pred, d_alpha]) {
            if let Some(node) = parent {
                grads.register::<B>(node.id, g);
            }
        }
    }
}

impl<B: ImageLossBackend, C: CheckpointStrategy> ImageLossBackend for Autodiff<B, C> {
    fn image_loss_forward(
        pred: FloatTensor<Self>,
        alpha: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let (target, mask) = (target.into_primitive(), mask.into_primitive());
        match ImageLossStep.prepare::<C>([pred.node(), alpha.node()]).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let ids = [prep.checkpoint(&pred), prep.checkpoint(&alpha)];
                let (loss, moments) = B::image_loss_forward(
                    pred.into_primitive(),
                    alpha.into_primitive(),
                    target.clone(),
                    mask.clone(),
                    config.clone(),
                );
                let state = (ids, [target, mask, moments.clone()], config);
                (prep.finish(state, loss), FloatTensor::<Self>::new(moments))
            }
            OpsKind::UnTracked(prep) => {
                let (loss, moments) = B::image_loss_forward(
                    pred.into_primitive(),
                    alpha.into_primitive(),
                    target,
                    mask,
                    config,
                );
                (prep.finish(loss), FloatTensor::<Self>::new(moments))
            }
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn image_loss_backward(
        pred: FloatTensor<Self>,
        alpha: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let p = |t: FloatTensor<Self>| t.into_primitive();
        let (a, b) =
            B::image_loss_backward(p(pred), p(alpha), p(target), p(mask), p(moments), p(grad), config);
        (FloatTensor::<Self>::new(a), FloatTensor::<Self>::new(b))
    }
}
