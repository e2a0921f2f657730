//! The op under autodiff: the backward step re-reads the saved vertices.

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::FloatTensor;

use super::{MeshLoss, MeshLossBackend};

#[derive(Debug)]
struct MeshLossStep;

impl<B: MeshLossBackend> Backward<B, 1> for MeshLossStep {
    type State = (NodeId, MeshLoss);

    fn backward(self, ops: Ops<Self::State, 1>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (id, loss) = ops.state;
        let [parent] = ops.parents;
        if let Some(node) = parent {
            let vertices = checkpointer.retrieve_node_output::<FloatTensor<B>>(id);
            grads.register::<B>(node.id, B::mesh_loss_backward(vertices, grad, loss));
        }
    }
}

impl<B: MeshLossBackend, C: CheckpointStrategy> MeshLossBackend for Autodiff<B, C> {
    fn mesh_loss_forward(vertices: FloatTensor<Self>, loss: MeshLoss) -> FloatTensor<Self> {
        match MeshLossStep.prepare::<C>([vertices.node()]).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let id = prep.checkpoint(&vertices);
                let out = B::mesh_loss_forward(vertices.into_primitive(), loss.clone());
                prep.finish((id, loss), out)
            }
            OpsKind::UnTracked(prep) => prep.finish(B::mesh_loss_forward(vertices.into_primitive(), loss)),
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn mesh_loss_backward(
        vertices: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        loss: MeshLoss,
    ) -> FloatTensor<Self> {
        FloatTensor::<Self>::new(B::mesh_loss_backward(
            vertices.into_primitive(),
            grad.into_primitive(),
            loss,
        ))
    }
}
