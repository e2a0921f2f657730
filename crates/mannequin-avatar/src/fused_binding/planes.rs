//! The binding output's planes on the CubeCL backends, as views whose gradients go straight into
//! one buffer. Through `narrow`, autodiff gives each plane's gradient as a zero-filled copy of the
//! whole output with the plane assigned in (two launches each), then adds the four (three more):
//! eleven launches a step. Here the first plane to get its gradient writes it into a fresh buffer
//! with zeros around it and registers that buffer as the output's gradient; each later plane writes
//! its own part of the same buffer in place. Autodiff runs the binding's backward, which reads the
//! buffer, only after every plane's: four launches. Planes whose gradient never comes stay zero.

use std::any::Any;
use std::sync::{Arc, Mutex};

use burn::backend::Autodiff;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;
use burn_cubecl::cubecl;
use cubecl::prelude::*;

use crate::cube_launch::{empty_f32, per_element, u32_of};
use crate::losses::blur::as_f32;

/// The output's gradient buffer, once the first plane has made it (type-erased: it is an inner
/// backend's tensor, and the configuration is not generic).
type Gathered = Arc<Mutex<Option<Box<dyn Any + Send>>>>;

/// One plane `[start, start + len)` of an output of `total` values, and the buffer its
/// gradient goes into, shared by the output's planes.
#[derive(Clone)]
pub struct PlaneConfig {
    pub start: usize,
    pub len: usize,
    pub total: usize,
    gathered: Gathered,
}

impl std::fmt::Debug for PlaneConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PlaneConfig {{ start: {}, len: {}, total: {} }}", self.start, self.len, self.total)
    }
}

/// Backends that hand out planes whose gradients gather in one buffer.
#[backend_extension(Cube, Autodiff)]
pub trait PlanesBackend: Backend {
    /// The plane, `[len]` (a view where the device's alignment allows).
    fn plane_forward(output: FloatTensor<Self>, plane: PlaneConfig) -> FloatTensor<Self>;

    /// A fresh `[total]` buffer with `grad` in the plane and zeros around it.
    fn plane_gradient(grad: FloatTensor<Self>, plane: PlaneConfig) -> FloatTensor<Self>;

    /// Writes `grad` into `into[start..start + len]`, in place. Returns `into`.
    fn plane_write(into: FloatTensor<Self>, grad: FloatTensor<Self>, plane: PlaneConfig)
    -> FloatTensor<Self>;
}

/// The planes `(start, len)` of `output` (`[total]`, `f32`, on a CubeCL device) as tensors.
pub fn planes<const N: usize>(output: Tensor<1>, spans: [(usize, usize); N]) -> [Tensor<1>; N] {
    let total = output.dims()[0];
    let gathered: Gathered = Arc::default();
    spans.map(|(start, len)| {
        let plane = PlaneConfig { start, len, total, gathered: gathered.clone() };
        Tensor::from_dispatch(<Dispatch as PlanesBackend>::plane_forward(
            output.clone().into_dispatch(),
            plane,
        ))
    })
}

/// `into[start + i] = grad[i]`, and zeros elsewhere in `into` when `zero_rest`; one unit per
/// word of `into` (or of the plane).
#[cube(launch)]
fn write_plane(
    grad: &[f32],
    into: &mut [f32],
    start: u32,
    len: u32,
    total: u32,
    #[comptime] zero_rest: bool,
) {
    let i = ABSOLUTE_POS as u32;
    if zero_rest {
        if i < total {
            let inside = i >= start && i < start + len;
            into[i as usize] = select(inside, grad[(i - select(inside, start, i)) as usize], 0.0f32);
        }
    } else if i < len {
        into[(start + i) as usize] = grad[i as usize];
    }
}

impl PlanesBackend for CubeBackend {
    fn plane_forward(output: FloatTensor<Self>, plane: PlaneConfig) -> FloatTensor<Self> {
        Self::float_slice(output, &[(plane.start..plane.start + plane.len).into()])
    }

    fn plane_gradient(grad: FloatTensor<Self>, plane: PlaneConfig) -> FloatTensor<Self> {
        let (grad, back) = as_f32(grad);
        let into = empty_f32(vec![plane.total], &grad);
        back(write(into, grad, &plane, true))
    }

    fn plane_write(
        into: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        plane: PlaneConfig,
    ) -> FloatTensor<Self> {
        write(into, as_f32(grad).0, &plane, false)
    }
}

fn write(into: CubeTensor, grad: CubeTensor, plane: &PlaneConfig, zero_rest: bool) -> CubeTensor {
    let (count, dim) = per_element(&into, if zero_rest { plane.total } else { plane.len });
    write_plane::launch(
        &into.client,
        count,
        dim,
        grad.into_buffer_arg(),
        into.clone().into_buffer_arg(),
        u32_of(plane.start),
        u32_of(plane.len),
        u32_of(plane.total),
        zero_rest,
    );
    into
}

#[derive(Debug)]
struct PlaneStep;

impl<B: PlanesBackend> Backward<B, 1> for PlaneStep {
    type State = PlaneConfig;

    fn backward(self, ops: Ops<Self::State, 1>, grads: &mut Gradients, _: &mut Checkpointer) {
        let grad = grads.consume::<B>(&ops.node);
        let [Some(parent)] = ops.parents else { return };
        let plane = ops.state;
        let mut gathered = plane.gathered.lock().expect("a plane's backward panicked");
        match gathered.as_ref().and_then(|b| b.downcast_ref::<FloatTensor<B>>()) {
            Some(into) => {
                B::plane_write(into.clone(), grad, plane.clone());
            }
            None => {
                let into = B::plane_gradient(grad, plane.clone());
                grads.register::<B>(parent.id, into.clone());
                *gathered = Some(Box::new(into));
            }
        }
    }
}

impl<B: PlanesBackend, C: CheckpointStrategy> PlanesBackend for Autodiff<B, C> {
    fn plane_forward(output: FloatTensor<Self>, plane: PlaneConfig) -> FloatTensor<Self> {
        match PlaneStep.prepare::<C>([output.node()]).compute_bound().stateful() {
            OpsKind::Tracked(prep) => {
                let out = B::plane_forward(output.into_primitive(), plane.clone());
                prep.finish(plane, out)
            }
            OpsKind::UnTracked(prep) => prep.finish(B::plane_forward(output.into_primitive(), plane)),
        }
    }

    /// Gradients of gradients are not supported: these run on the inner backend.
    fn plane_gradient(grad: FloatTensor<Self>, plane: PlaneConfig) -> FloatTensor<Self> {
        FloatTensor::<Self>::new(B::plane_gradient(grad.into_primitive(), plane))
    }

    fn plane_write(
        into: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        plane: PlaneConfig,
    ) -> FloatTensor<Self> {
        FloatTensor::<Self>::new(B::plane_write(into.into_primitive(), grad.into_primitive(), plane))
    }
}
