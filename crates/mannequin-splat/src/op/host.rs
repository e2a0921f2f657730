//! The splatting op on host memory: what the Flex backend runs directly (on its tensors' own
//! buffers), in terms of the CPU renderer.

use super::config::{Inputs, SplatConfig};
use super::saved;
use crate::render::{OutputGrads, backward_checked, render_checked};

/// Renders; returns `[C + 2, H, W]` (colour, alpha, expected depth) and the saved state.
pub(crate) fn forward(x: &Inputs, cfg: &SplatConfig) -> (Vec<f32>, Vec<f32>) {
    let g = cfg.gaussians(x);
    // splat_render checked shapes, camera and options before dispatching.
    let out = render_checked(&g, &cfg.camera, &cfg.options, false).expect("inputs checked by splat_render");
    let mut rendered = Vec::with_capacity(out.image.len() + 2 * out.alpha.len());
    rendered.extend_from_slice(&out.image);
    rendered.extend_from_slice(&out.alpha);
    rendered.extend_from_slice(&out.depth);
    (rendered, saved::encode(&out))
}

/// Gradients of the five inputs, from the forward's outputs and the gradient of `[C + 2, H, W]`.
pub(crate) fn backward(
    x: &Inputs,
    cfg: &SplatConfig,
    rendered: &[f32],
    words: &[f32],
    grad: &[f32],
) -> [Vec<f32>; 5] {
    let g = cfg.gaussians(x);
    let (w, h) = (cfg.camera.width, cfg.camera.height);
    let out = saved::decode(rendered, words, w, h).expect("the state splat_forward saved");
    let npx = w * h;
    let ch = out.channels;
    let grads = OutputGrads {
        image: Some(&grad[..ch * npx]),
        alpha: Some(&grad[ch * npx..(ch + 1) * npx]),
        depth: Some(&grad[(ch + 1) * npx..]),
    };
    let d = backward_checked(&g, &cfg.camera, &cfg.options, &out, &grads, false)
        .expect("inputs checked by splat_render");
    [d.means, d.rotations, d.scales, d.opacities, d.colors]
}
