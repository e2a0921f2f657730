//! The op under autodiff: the backward step recomputes the basis from the saved inputs (cheaper
//! than storing it).

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::{ColourBackend, ColourConfig};

#[derive(Debug)]
struct ColourStep;

impl<B: ColourBackend> Backward<B, 2> for ColourStep {
    type State = ([NodeId; 2], ColourConfig);

    fn backward(self, ops: Ops<Self::State, 2>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (ids, config) = ops.state;
        let [m, c] = ids.map(|id| checkpointer.retrieve_node_output::<FloatTensor<B>>(id));
        let (dm, dc) = B::sh_colour_backward(m, c, grad, config);
        for (parent, g) in ops.parents.into_iter().zip([dm, dc]) {
            if let Some(node) = parent {
                grads.register::<B>(node.id, g);
            }
        }
    }
}

impl<B: ColourBackend, C: CheckpointStrategy> ColourBackend for Autodiff<B, C> {
    fn sh_colour_forward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        config: ColourConfig,
    ) -> FloatTensor<Self> {
        match ColourStep.prepare::<C>([means.node(), coeffs.node()]).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let ids = [prep.checkpoint(&means), prep.checkpoint(&coeffs)];
                let out =
                    B::sh_colour_forward(means.into_primitive(), coeffs.into_primitive(), config.clone());
                prep.finish((ids, config), out)
            }
            OpsKind::UnTracked(prep) => {
                prep.finish(B::sh_colour_forward(means.into_primitive(), coeffs.into_primitive(), config))
            }
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn sh_colour_backward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ColourConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let (dm, dc) = B::sh_colour_backward(
            means.into_primitive(),
            coeffs.into_primitive(),
            grad.into_primitive(),
            config,
        );
        (FloatTensor::<Self>::new(dm), FloatTensor::<Self>::new(dc))
    }
}
