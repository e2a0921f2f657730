//! The op under autodiff: the SSIM's moments are kept from the forward; target and mask are
//! constants, and the colour MSE is not differentiated.

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

/// The rendered planes' node; target, mask and moments; the weights.
type Saved<B> = (NodeId, [FloatTensor<B>; 3], ImageLossConfig);

impl<B: ImageLossBackend> Backward<B, 1> for ImageLossStep {
    type State = Saved<B>;

    fn backward(self, ops: Ops<Self::State, 1>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (rendered, [target, mask, moments], config) = ops.state;
        let rendered = checkpointer.retrieve_node_output::<FloatTensor<B>>(rendered);
        let d_rendered = B::image_loss_backward(rendered, target, mask, moments, grad, config);
        if let [Some(node)] = ops.parents {
            grads.register::<B>(node.id, d_rendered);
        }
    }
}

impl<B: ImageLossBackend, C: CheckpointStrategy> ImageLossBackend for Autodiff<B, C> {
    fn image_loss_forward(
        rendered: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let (target, mask) = (target.into_primitive(), mask.into_primitive());
        match ImageLossStep.prepare::<C>([rendered.node()]).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let id = prep.checkpoint(&rendered);
                let (loss, mse, moments) = B::image_loss_forward(
                    rendered.into_primitive(),
                    target.clone(),
                    mask.clone(),
                    config.clone(),
                );
                let state = (id, [target, mask, moments.clone()], config);
                let wrap = FloatTensor::<Self>::new;
                (prep.finish(state, loss), wrap(mse), wrap(moments))
            }
            OpsKind::UnTracked(prep) => {
                let (loss, mse, moments) =
                    B::image_loss_forward(rendered.into_primitive(), target, mask, config);
                let wrap = FloatTensor::<Self>::new;
                (prep.finish(loss), wrap(mse), wrap(moments))
            }
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn image_loss_backward(
        rendered: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> FloatTensor<Self> {
        let p = |t: FloatTensor<Self>| t.into_primitive();
        FloatTensor::<Self>::new(B::image_loss_backward(
            p(rendered),
            p(target),
            p(mask),
            p(moments),
            p(grad),
            config,
        ))
    }
}
