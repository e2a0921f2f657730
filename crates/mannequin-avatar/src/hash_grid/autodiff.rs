//! The op under autodiff. The encoding is linear in the table, so the backward step needs none
//! of the table's values: its state is the lookup's grouping (constant tensors) and the table's
//! row count.

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
    /// Touched rows, offsets, grouped pairs and weights, and the table's row count.
    type State = (IntTensor<B>, IntTensor<B>, IntTensor<B>, FloatTensor<B>, usize);

    fn backward(self, ops: Ops<Self::State, 1>, grads: &mut Gradients, _checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (touched, offsets, pairs, weights, table_rows) = ops.state;
        let [table] = ops.parents;
        if let Some(node) = table {
            let d_table = B::hash_grid_backward(grad, touched, offsets, pairs, weights, table_rows);
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
        grouped_pairs: IntTensor<Self>,
        grouped_weights: FloatTensor<Self>,
    ) -> FloatTensor<Self> {
        let table_rows = table.shape()[0];
        let (weights, grouped_weights) = (weights.into_primitive(), grouped_weights.into_primitive());
        match EncodeStep.prepare::<C>([table.node()]).compute_bound().stateful() {
            OpsKind::Tracked(prep) => {
                let out = B::hash_grid_forward(
                    table.into_primitive(),
                    rows,
                    weights,
                    touched.clone(),
                    offsets.clone(),
                    grouped_pairs.clone(),
                    grouped_weights.clone(),
                );
                prep.finish((touched, offsets, grouped_pairs, grouped_weights, table_rows), out)
            }
            OpsKind::UnTracked(prep) => prep.finish(B::hash_grid_forward(
                table.into_primitive(),
                rows,
                weights,
                touched,
                offsets,
                grouped_pairs,
                grouped_weights,
            )),
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn hash_grid_backward(
        grad: FloatTensor<Self>,
        touched: IntTensor<Self>,
        offsets: IntTensor<Self>,
        grouped_pairs: IntTensor<Self>,
        grouped_weights: FloatTensor<Self>,
        table_rows: usize,
    ) -> FloatTensor<Self> {
        FloatTensor::<Self>::new(B::hash_grid_backward(
            grad.into_primitive(),
            touched,
            offsets,
            grouped_pairs,
            grouped_weights.into_primitive(),
            table_rows,
        ))
    }
}
