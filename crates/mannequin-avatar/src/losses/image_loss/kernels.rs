//! CubeCL kernels of the image loss, one unit per pixel: the forward writes each pixel's share
//! of the loss and of the colour MSE, summed after by one cube (`crate::row_totals`); the backward adds the L1 and mask
//! terms' signs to the SSIM's gradient and writes every rendered plane's gradient. `sign(0) = 0`,
//! as Burn's |x| differentiates.

// Kernels index their buffers: iterator forms do not exist in CubeCL.
#![allow(clippy::needless_range_loop)]

use burn_cubecl::cubecl;
use cubecl::prelude::*;

#[cube]
fn sign(x: f32) -> f32 {
    let mut s = 0.0f32;
    if x > 0.0 {
        s = 1.0f32;
    }
    if x < 0.0 {
        s = -1.0f32;
    }
    s
}

/// `share[i] = Σ_c w_c·[(1 − λ)|p − t|/(HW) + λ(1 − S_c)/(H'W')] + λ_m|a − m|/(HW)`, the SSIM
/// part only where pixel `i` anchors a map entry (`map` is `[C, H − 10, W − 10]`), and
/// `share[HW + i] = Σ_{c<3} (p − t)²/(3HW)`. `p` is plane c of `rendered`, `a` its plane
/// `alpha_plane`.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn loss_shares(
    rendered: &[f32],
    target: &[f32],
    mask: &[f32],
    map: &[f32],
    weights: &[f32],
    share: &mut [f32],
    channels: u32,
    height: u32,
    width: u32,
    alpha_plane: u32,
    lambda: f32,
    lambda_mask: f32,
) {
    let i = ABSOLUTE_POS;
    let (h, w) = (height as usize, width as usize);
    let plane = h * w;
    if i >= plane {
        terminate!();
    }
    let (y, x) = (i / w, i % w);
    let (mh, mw) = (h - 10, w - 10);
    let valid = y < mh && x < mw;
    let inv = 1.0 / f32::cast_from(plane);
    let inv_map = 1.0 / f32::cast_from(mh * mw);
    let mut acc = lambda_mask * f32::abs(rendered[alpha_plane as usize * plane + i] - mask[i]) * inv;
    let mut squares = 0.0f32;
    for c in 0..channels as usize {
        let k = c * plane + i;
        let d = rendered[k] - target[k];
        let mut term = (1.0 - lambda) * f32::abs(d) * inv;
        if valid {
            term += lambda * (1.0 - map[c * mh * mw + y * mw + x]) * inv_map;
        }
        acc += weights[c] * term;
        if c < 3 {
            squares += d * d;
        }
    }
    share[i] = acc;
    share[plane + i] = squares * inv / 3.0;
}

/// The SSIM map's gradient: `−g·λ·w_c/(H'W')` everywhere in channel c.
#[cube(launch)]
pub(crate) fn map_gradient(
    grad: &[f32],
    weights: &[f32],
    d_map: &mut [f32],
    channels: u32,
    height: u32,
    width: u32,
    lambda: f32,
) {
    let i = ABSOLUTE_POS;
    let (mh, mw) = (height as usize - 10, width as usize - 10);
    let entries = mh * mw;
    if i >= entries * channels as usize {
        terminate!();
    }
    d_map[i] = -grad[0] * lambda * weights[i / entries] / f32::cast_from(entries);
}

/// The rendered planes' gradient `[K, H, W]`: `d_ssim + g·(1 − λ)·w_c·sign(p − t)/(HW)` on the
/// C compared planes, `g·λ_m·sign(a − m)/(HW)` on the alpha plane, zero on the others.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn pixel_gradients(
    rendered: &[f32],
    target: &[f32],
    mask: &[f32],
    d_ssim: &[f32],
    grad: &[f32],
    weights: &[f32],
    d_rendered: &mut [f32],
    channels: u32,
    planes: u32,
    height: u32,
    width: u32,
    alpha_plane: u32,
    lambda: f32,
    lambda_mask: f32,
) {
    let i = ABSOLUTE_POS;
    let plane = (height * width) as usize;
    if i >= plane {
        terminate!();
    }
    let g = grad[0] / f32::cast_from(plane);
    for c in 0..planes as usize {
        let k = c * plane + i;
        let mut d = 0.0f32;
        if c < channels as usize {
            d = d_ssim[k] + g * (1.0 - lambda) * weights[c] * sign(rendered[k] - target[k]);
        } else if c == alpha_plane as usize {
            d = g * lambda_mask * sign(rendered[k] - mask[i]);
        }
        d_rendered[k] = d;
    }
}
