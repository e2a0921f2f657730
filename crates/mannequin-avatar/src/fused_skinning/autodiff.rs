//! The op under autodiff: the backward step recomputes the chain from the saved inputs (one
//! launch, cheaper than keeping it).

use burn::backend::Autodiff;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::tensor::{FloatTensor, IntTensor};

use super::SkinningBackend;

#[derive(Debug)]
struct SkinStep;

/// The inputs' node ids (vertices, joints, pose, translation), then the rig.
type Saved<B> = ([NodeId; 3], FloatTensor<B>, FloatTensor<B>, IntTensor<B>, usize);

impl<B: SkinningBackend> Backward<B, 4> for SkinStep {
    type State = Saved<B>;

    fn backward(self, ops: Ops<Self::State, 4>, grads: &mut Gradients, checkpointer: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let (ids, blend, posedirs, parents, features) = ops.state;
        let [vertices, joints, pose] = ids.map(|id| checkpointer.retrieve_node_output::<FloatTensor<B>>(id));
        let (dv, dj, dp, dt) =
            B::lbs_backward(vertices, joints, pose, blend, posedirs, parents, features, grad);
        for (parent, g) in ops.parents.into_iter().zip([dv, dj, dp, dt]) {
            if let Some(node) = parent {
                grads.register::<B>(node.id, g);
            }
        }
    }
}

impl<B: SkinningBackend, C: CheckpointStrategy> SkinningBackend for Autodiff<B, C> {
    fn lbs_forward(
        vertices: FloatTensor<Self>,
        joints: FloatTensor<Self>,
        pose: FloatTensor<Self>,
        transl: FloatTensor<Self>,
        blend: FloatTensor<Self>,
        posedirs: FloatTensor<Self>,
        parents: IntTensor<Self>,
        features: usize,
    ) -> FloatTensor<Self> {
        let nodes = [vertices.node(), joints.node(), pose.node(), transl.node()];
        let (blend, posedirs) = (blend.into_primitive(), posedirs.into_primitive());
        match SkinStep.prepare::<C>(nodes).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let ids = [&vertices, &joints, &pose].map(|t| prep.checkpoint(t));
                let out = B::lbs_forward(
                    vertices.into_primitive(),
                    joints.into_primitive(),
                    pose.into_primitive(),
                    transl.into_primitive(),
                    blend.clone(),
                    posedirs.clone(),
                    parents.clone(),
                    features,
                );
                prep.finish((ids, blend, posedirs, parents, features), out)
            }
            OpsKind::UnTracked(prep) => prep.finish(B::lbs_forward(
                vertices.into_primitive(),
                joints.into_primitive(),
                pose.into_primitive(),
                transl.into_primitive(),
                blend,
                posedirs,
                parents,
                features,
            )),
        }
    }

    /// Gradients of gradients are not supported: this evaluates the backward pass on the inner
    /// backend without recording it.
    fn lbs_backward(
        vertices: FloatTensor<Self>,
        joints: FloatTensor<Self>,
        pose: FloatTensor<Self>,
        blend: FloatTensor<Self>,
        posedirs: FloatTensor<Self>,
        parents: IntTensor<Self>,
        features: usize,
        grad: FloatTensor<Self>,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let p = |t: FloatTensor<Self>| t.into_primitive();
        let (a, b, c, d) = B::lbs_backward(
            p(vertices),
            p(joints),
            p(pose),
            p(blend),
            p(posedirs),
            parents,
            features,
            p(grad),
        );
        let n = FloatTensor::<Self>::new;
        (n(a), n(b), n(c), n(d))
    }
}
