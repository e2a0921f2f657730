//! The op under autodiff: the backward step recomputes the basis from the saved means and
//! coefficients (cheaper than storing it); the normals' gradient needs only the rotation.

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::{FeaturesBackend, FeaturesConfig};

#[derive(Debug)]
struct FeaturesStep;

impl<B: FeaturesBackend> Backward<B, 3> for FeaturesStep {
    type State = ([NodeId; 2], FeaturesConfig);

    fn backward(self, ops: Ops<Self::State, 3>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (ids, config) = ops.state;
        let [m, c] = ids.map(|id| checkpointer.retrieve_node_output::<FloatTensor<B>>(id));
        let (dm, dc, dn) = B::features_backward(m, c, grad, config);
        for (parent, g) in ops.parents.into_iter().zip([dm, dc, dn]) {
            if let Some(node) = parent {
                grads.register::<B>(node.id, g);
            }
        }
    }
}

impl<B: FeaturesBackend, C: CheckpointStrategy> FeaturesBackend for Autodiff<B, C> {
    fn features_forward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        normals: FloatTensor<Self>,
        config: FeaturesConfig,
    ) -> FloatTensor<Self> {
        let nodes = [means.node(), coeffs.node(), normals.node()];
        match FeaturesStep.prepare::<C>(nodes).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let ids = [prep.checkpoint(&means), prep.checkpoint(&coeffs)];
                let out = B::features_forward(
                    means.into_primitive(),
                    coeffs.into_primitive(),
                    normals.into_primitive(),
                    config.clone(),
                );
                prep.finish((ids, config), out)
            }
            OpsKind::UnTracked(prep) => prep.finish(B::features_forward(
                means.into_primitive(),
                coeffs.into_primitive(),
                normals.into_primitive(),
                config,
            )),
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn features_backward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: FeaturesConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let (dm, dc, dn) = B::features_backward(
            means.into_primitive(),
            coeffs.into_primitive(),
            grad.into_primitive(),
            config,
        );
        let w = FloatTensor::<Self>::new;
        (w(dm), w(dc), w(dn))
    }
}
