//! The op under autodiff: the forward runs on the inner backend and registers a backward step
//! that calls the inner backend's `splat_backward` (the hand-written pass).

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::{SplatBackend, SplatConfig};

#[derive(Debug)]
struct SplatStep;

impl<B: SplatBackend> Backward<B, 5> for SplatStep {
    /// Input nodes, the rendered images, the saved state and the configuration.
    type State = ([NodeId; 5], FloatTensor<B>, FloatTensor<B>, SplatConfig);

    fn backward(self, ops: Ops<Self::State, 5>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (ids, rendered, saved, config) = ops.state;
        let [m, r, s, o, c] = ids.map(|id| checkpointer.retrieve_node_output::<FloatTensor<B>>(id));
        let (dm, dr, ds, d_o, dc) = B::splat_backward(m, r, s, o, c, rendered, saved, grad, config);
        for (parent, g) in ops.parents.into_iter().zip([dm, dr, ds, d_o, dc]) {
            if let Some(node) = parent {
                grads.register::<B>(node.id, g);
            }
        }
    }
}

impl<B: SplatBackend, C: CheckpointStrategy> SplatBackend for Autodiff<B, C> {
    fn splat_forward(
        means: FloatTensor<Self>,
        rotations: FloatTensor<Self>,
        scales: FloatTensor<Self>,
        opacities: FloatTensor<Self>,
        colors: FloatTensor<Self>,
        config: SplatConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let inputs = [means, rotations, scales, opacities, colors];
        let nodes = inputs.each_ref().map(|t| t.node());
        match SplatStep.prepare::<C>(nodes).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let ids = inputs.each_ref().map(|t| prep.checkpoint(t));
                let [m, r, s, o, c] = inputs.map(|t| t.into_primitive());
                let (rendered, saved) = B::splat_forward(m, r, s, o, c, config.clone());
                let state = (ids, rendered.clone(), saved.clone(), config);
                (prep.finish(state, rendered), FloatTensor::<Self>::new(saved))
            }
            OpsKind::UnTracked(prep) => {
                let [m, r, s, o, c] = inputs.map(|t| t.into_primitive());
                let (rendered, saved) = B::splat_forward(m, r, s, o, c, config);
                (prep.finish(rendered), FloatTensor::<Self>::new(saved))
            }
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn splat_backward(
        means: FloatTensor<Self>,
        rotations: FloatTensor<Self>,
        scales: FloatTensor<Self>,
        opacities: FloatTensor<Self>,
        colors: FloatTensor<Self>,
        rendered: FloatTensor<Self>,
        saved: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: SplatConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let p = |t: FloatTensor<Self>| t.into_primitive();
        let (a, b, c, d, e) = B::splat_backward(
            p(means),
            p(rotations),
            p(scales),
            p(opacities),
            p(colors),
            p(rendered),
            p(saved),
            p(grad),
            config,
        );
        let w = FloatTensor::<Self>::new;
        (w(a), w(b), w(c), w(d), w(e))
    }
}
