//! The op under autodiff: the backward step recomputes the per-face and per-vertex terms from the
//! saved vertices (cheaper than storing them).

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::{BindConfig, BindingBackend};

#[derive(Debug)]
struct BindStep;

impl<B: BindingBackend> Backward<B, 1> for BindStep {
    type State = (NodeId, BindConfig);

    fn backward(self, ops: Ops<Self::State, 1>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (id, config) = ops.state;
        let [parent] = ops.parents;
        if let Some(node) = parent {
            let vertices = checkpointer.retrieve_node_output::<FloatTensor<B>>(id);
            grads.register::<B>(node.id, B::tavatar_bind_backward(vertices, grad, config));
        }
    }
}

impl<B: BindingBackend, C: CheckpointStrategy> BindingBackend for Autodiff<B, C> {
    fn tavatar_bind_forward(vertices: FloatTensor<Self>, config: BindConfig) -> FloatTensor<Self> {
        match BindStep.prepare::<C>([vertices.node()]).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let id = prep.checkpoint(&vertices);
                let out = B::tavatar_bind_forward(vertices.into_primitive(), config.clone());
                prep.finish((id, config), out)
            }
            OpsKind::UnTracked(prep) => {
                prep.finish(B::tavatar_bind_forward(vertices.into_primitive(), config))
            }
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn tavatar_bind_backward(
        vertices: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: BindConfig,
    ) -> FloatTensor<Self> {
        FloatTensor::<Self>::new(B::tavatar_bind_backward(
            vertices.into_primitive(),
            grad.into_primitive(),
            config,
        ))
    }
}
