//! The op under autodiff. The encoding is linear in the table, so the backward step needs none
//! of the table's values: its state is the lookup (constant tensors) and the table's row count.

use burn::backend::Autodiff;
use burn::backend::TensorMetadata;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::{FloatTensor, IntTensor};

use super::HashGridBackend;

#[derive(Debug)]
struct EncodeStep;

impl<B: HashGridBackend> Backward<B, 1> for EncodeStep {
    /// Weights, touched rows, offsets, sources, and the table's row count.
    type State = (FloatTensor<B>, IntTensor<B>, IntTensor<B>, IntTensor<B>, usize);

    fn backward(self, ops: Ops<Self::State, 1>, grads: &mut Gradients, _checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (weights, touched, offsets, sources, table_rows) = ops.state;
        let [table] = ops.parents;
        if let Some(node) = table {
            let d_table = B::hash_grid_backward(grad, weights, touched, offsets, sources, table_rows);
            grads.register::<B>(node.id, d_table);
        }
    }
}

impl<B: HashGridBackend, C: CheckpointStrategy> HashGridBackend for Autodiff<B, C> {
    fn hash_grid_forward(
        table: FloatTensor<Self>,
        rows: IntTensor<Self>,
        weights: FloatTensor<Self>,
        touched: IntTensor<Self>,
        offsets: IntTensor<Self>,
        sources: IntTensor<Self>,
    ) -> FloatTensor<Self> {
        let table_rows = table.shape()[0];
        let weights = weights.into_primitive();
        match EncodeStep.prepare::<C>([table.node()]).compute_bound().stateful() {
            OpsKind::Tracked(prep) => {
                let out = B::hash_grid_forward(
                    table.into_primitive(),
                    rows,
                    weights.clone(),
                    touched.clone(),
                    offsets.clone(),
                    sources.clone(),
                );
                prep.finish((weights, touched, offsets, sources, table_rows), out)
            }
            OpsKind::UnTracked(prep) => prep.finish(B::hash_grid_forward(
                table.into_primitive(),
                rows,
                weights,
                touched,
                offsets,
                sources,
            )),
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn hash_grid_backward(
        grad: FloatTensor<Self>,
        weights: FloatTensor<Self>,
        touched: IntTensor<Self>,
        offsets: IntTensor<Self>,
        sources: IntTensor<Self>,
        table_rows: usize,
    ) -> FloatTensor<Self> {
        FloatTensor::<Self>::new(B::hash_grid_backward(
            grad.into_primitive(),
            weights.into_primitive(),
            touched,
            offsets,
            sources,
            table_rows,
        ))
    }
}
