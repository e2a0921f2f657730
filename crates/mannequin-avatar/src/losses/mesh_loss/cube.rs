//! The regularisers on the CubeCL backends, in f32 (other float types are converted on the way
//! in and out), nothing read back. Forward: one kernel writes each element's share of the loss,
//! Burn's sum adds them. Backward: the Laplacian recomputes δ and gathers it over the rings; the
//! face and hinge terms write per-corner gradients that one kernel gathers per vertex.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::FloatDType;

use super::kernels::{face_terms, gather_corners, hinge_terms, laplacian_deltas, laplacian_gather};
use super::tables::{Tables, tables};
use super::{HostTerm, MeshLoss, MeshLossBackend};
use crate::cube_launch::{empty_f32, per_element, u32_of};
use crate::losses::blur::as_f32;
use crate::row_totals::row_totals;

type B = CubeBackend;

/// `1/N` over the connected vertices (the Laplacian's mean).
fn laplacian_scale(loss: &MeshLoss) -> f32 {
    1.0 / loss.mesh.num_connected.max(1) as f32
}

/// The Laplacian's δ `[V·3]` and loss shares `[V]`.
fn deltas(v: &CubeTensor, t: &Tables, loss: &MeshLoss) -> (CubeTensor, CubeTensor) {
    let n = loss.mesh.rings.num_vertices;
    let (delta, share) = (empty_f32(vec![3 * n], v), empty_f32(vec![n], v));
    let (count, dim) = per_element(v, n);
    laplacian_deltas::launch(
        &v.client,
        count,
        dim,
        v.clone().into_buffer_arg(),
        t.ring_start.clone().into_buffer_arg(),
        t.rings.clone().into_buffer_arg(),
        delta.clone().into_buffer_arg(),
        share.clone().into_buffer_arg(),
        u32_of(n),
        laplacian_scale(loss),
    );
    (delta, share)
}

/// The face (`corners` 3) or hinge (`corners` 4) term of `elements` elements: loss shares
/// `[E]`, or per-corner gradients `[E·corners·3]` when `backward`.
fn element_terms(v: &CubeTensor, t: &Tables, term: HostTerm, elements: usize, backward: bool) -> CubeTensor {
    let corners = if term == HostTerm::Equilateral { 3 } else { 4 };
    let out = empty_f32(vec![if backward { elements * corners * 3 } else { elements }], v);
    let (count, dim) = per_element(v, elements);
    let (v_arg, out_arg, e) = (v.clone().into_buffer_arg(), out.clone().into_buffer_arg(), u32_of(elements));
    if term == HostTerm::Equilateral {
        face_terms::launch(
            &v.client,
            count,
            dim,
            v_arg,
            t.faces.clone().into_buffer_arg(),
            out_arg,
            e,
            backward,
        );
    } else {
        hinge_terms::launch(
            &v.client,
            count,
            dim,
            v_arg,
            t.hinges.clone().into_buffer_arg(),
            out_arg,
            e,
            backward,
        );
    }
    out
}

/// Faces or hinges the term runs over.
fn elements(loss: &MeshLoss) -> usize {
    match loss.term {
        HostTerm::Equilateral => loss.mesh.rings.faces.len(),
        _ => loss.mesh.hinges.len(),
    }
}

impl MeshLossBackend for CubeBackend {
    fn mesh_loss_forward(vertices: FloatTensor<Self>, loss: MeshLoss) -> FloatTensor<Self> {
        let (v, back) = as_f32(vertices);
        let t = tables(&loss.mesh, &v.device);
        let shares = match loss.term {
            HostTerm::Laplacian => deltas(&v, &t, &loss).1,
            // No hinge: no pair disagrees, the loss is 0.
            _ if elements(&loss) == 0 => return back(B::float_zeros([1].into(), &v.device, FloatDType::F32)),
            term => element_terms(&v, &t, term, elements(&loss), false),
        };
        let n = shares.shape().num_elements();
        let [total] = <[CubeTensor; 1]>::try_from(row_totals(&shares, n, 1))
            .unwrap_or_else(|_| unreachable!("one row gives one total"));
        back(total)
    }

    fn mesh_loss_backward(
        vertices: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        loss: MeshLoss,
    ) -> FloatTensor<Self> {
        let n = vertices.shape()[0];
        let (v, back) = as_f32(vertices);
        let (upstream, _) = as_f32(grad);
        let t = tables(&loss.mesh, &v.device);
        let out = B::float_empty([n, 3].into(), &v.device, FloatDType::F32);
        let (count, dim) = per_element(&v, n);
        match loss.term {
            HostTerm::Laplacian => {
                let (delta, _) = deltas(&v, &t, &loss);
                laplacian_gather::launch(
                    &v.client,
                    count,
                    dim,
                    delta.into_buffer_arg(),
                    t.ring_start.clone().into_buffer_arg(),
                    t.rings.clone().into_buffer_arg(),
                    upstream.into_buffer_arg(),
                    out.clone().into_buffer_arg(),
                    u32_of(n),
                    laplacian_scale(&loss),
                );
            }
            _ if elements(&loss) == 0 => {
                return back(B::float_zeros([n, 3].into(), &v.device, FloatDType::F32));
            }
            term => {
                let grads = element_terms(&v, &t, term, elements(&loss), true);
                let (start, slots) = if term == HostTerm::Equilateral {
                    (&t.face_start, &t.face_slots)
                } else {
                    (&t.hinge_start, &t.hinge_slots)
                };
                gather_corners::launch(
                    &v.client,
                    count,
                    dim,
                    grads.into_buffer_arg(),
                    start.clone().into_buffer_arg(),
                    slots.clone().into_buffer_arg(),
                    upstream.into_buffer_arg(),
                    out.clone().into_buffer_arg(),
                    u32_of(n),
                );
            }
        }
        back(out)
    }
}
