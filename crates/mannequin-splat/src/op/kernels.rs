//! CubeCL kernels for the per-pixel work of splatting: front-to-back compositing and its replay
//! for the backward pass. One cube is one 16×16 tile and one unit is one pixel, which walks its
//! tile's depth-ordered list exactly as the CPU compositor does (same rule, same state).
//!
//! The tile lists (from `binning.rs`) and the packed rows live in one `f32` buffer (`words`, see
//! `saved.rs`): integers are stored as bit patterns and read back with `u32::reinterpret`.
//!
//! Each unit loops over its tile's list. Mesa's lavapipe silently stops any shader loop after
//! 65,535 iterations, so on lavapipe a tile must list fewer Gaussians than that (the tests do);
//! real GPUs have no such limit. Gradient sums use `f32` atomics, so their last bits depend on
//! the order the units run in.

use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// Offsets (in words) of the packed rows' fields, as in `composite::field`.
const MX: usize = 0;
const MY: usize = 1;
const CA: usize = 2;
const CB: usize = 3;
const CC: usize = 4;
const OPACITY: usize = 5;
const DEPTH: usize = 6;
const COLOR: usize = 12;

/// Where the parts of `words` start, and the image geometry.
#[derive(CubeLaunch, CubeType, Clone, Copy)]
pub(crate) struct Layout {
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub stride: u32,
    pub offsets: u32,
    pub ids: u32,
    pub rows: u32,
    pub last: u32,
}

/// Gathers the state's parts into `words` up to the replay lengths, one unit a word: the sizes
/// (`SKIPPED` words), the skipped count, the tile offsets, the tile lists and the packed rows.
/// One launch where a concatenation took one a part.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn pack_state(
    sizes: &[f32],
    skipped: &[f32],
    offsets: &[f32],
    ids: &[f32],
    rows: &[f32],
    words: &mut [f32],
    layout: Layout,
    #[comptime] skipped_at: u32,
) {
    let i = ABSOLUTE_POS as u32;
    if i >= layout.last {
        terminate!();
    }
    let w = if i < skipped_at {
        sizes[i as usize]
    } else if i < layout.offsets {
        skipped[0]
    } else if i < layout.ids {
        offsets[(i - layout.offsets) as usize]
    } else if i < layout.rows {
        ids[(i - layout.ids) as usize]
    } else {
        rows[(i - layout.rows) as usize]
    };
    words[i as usize] = w;
}

/// `params`: alpha threshold, alpha cap, transmittance floor, then the background (C values).
/// Each pixel's replay length goes into `words` from `layout.last` on.
#[cube(launch)]
pub(crate) fn composite_forward(
    words: &mut [f32],
    params: &[f32],
    rendered: &mut [f32],
    layout: Layout,
    #[comptime] channels: usize,
) {
    let tile = CUBE_POS_Y * layout.tiles_x + CUBE_POS_X;
    let px = CUBE_POS_X * 16 + UNIT_POS_X;
    let py = CUBE_POS_Y * 16 + UNIT_POS_Y;
    let inside = px < layout.width && py < layout.height;
    let (threshold, max_alpha, min_t) = (params[0], params[1], params[2]);
    let start = u32::reinterpret(words[(layout.offsets + tile) as usize]);
    let end = u32::reinterpret(words[(layout.offsets + tile + 1) as usize]);
    let fx = f32::cast_from(px) + 0.5;
    let fy = f32::cast_from(py) + 0.5;
    let mut acc = Array::<f32>::new(channels);
    #[unroll]
    for ch in 0..channels {
        acc[ch] = 0.0;
    }
    let mut t = 1.0f32;
    let mut depth = 0.0f32;
    let mut last = 0u32;
    let mut done = !inside;
    for k in start..end {
        if done {
            break;
        }
        let rank = u32::reinterpret(words[(layout.ids + k) as usize]);
        let row = (layout.rows + rank * layout.stride) as usize;
        let dx = fx - words[row + MX];
        let dy = fy - words[row + MY];
        let sigma = 0.5 * (words[row + CA] * dx * dx + words[row + CC] * dy * dy) + words[row + CB] * dx * dy;
        let alpha = f32::min(words[row + OPACITY] * f32::exp(-sigma), max_alpha);
        if sigma >= 0.0 && alpha >= threshold {
            let next = t * (1.0 - alpha);
            if next <= min_t {
                done = true;
            } else {
                let w = alpha * t;
                #[unroll]
                for ch in 0..channels {
                    acc[ch] += w * words[row + COLOR + ch];
                }
                depth += w * words[row + DEPTH];
                t = next;
                last = k - start + 1;
            }
        }
    }
    if inside {
        let npx = (layout.width * layout.height) as usize;
        let p = (py * layout.width + px) as usize;
        #[unroll]
        for ch in 0..channels {
            rendered[ch * npx + p] = acc[ch] + t * params[3 + ch];
        }
        let a = 1.0 - t;
        rendered[channels * npx + p] = a;
        rendered[(channels + 1) * npx + p] = depth / f32::max(a, 1e-10);
        words[layout.last as usize + p] = f32::reinterpret(last);
    }
}

/// Replays each pixel front to back and adds its share of every Gaussian's screen-space
/// gradient (mean x, y; conic a, b, c; opacity; depth; C colours) into `grads` by rank.
#[cube(launch)]
pub(crate) fn composite_backward(
    words: &[f32],
    params: &[f32],
    rendered: &[f32],
    grad: &[f32],
    grads: &[Atomic<f32>],
    layout: Layout,
    #[comptime] channels: usize,
) {
    let tile = CUBE_POS_Y * layout.tiles_x + CUBE_POS_X;
    let px = CUBE_POS_X * 16 + UNIT_POS_X;
    let py = CUBE_POS_Y * 16 + UNIT_POS_Y;
    if px >= layout.width || py >= layout.height {
        terminate!();
    }
    let (threshold, max_alpha) = (params[0], params[1]);
    let npx = (layout.width * layout.height) as usize;
    let p = (py * layout.width + px) as usize;
    let slots = (7 + channels) as u32;
    // Expected depth E = D / max(A, ε): pass its gradient on to D and A.
    let a_total = rendered[channels * npx + p];
    let e = rendered[(channels + 1) * npx + p];
    let am = f32::max(a_total, 1e-10);
    let g_depth = grad[(channels + 1) * npx + p] / am;
    let mut g_alpha = grad[channels * npx + p];
    if a_total > 1e-10 {
        g_alpha -= grad[(channels + 1) * npx + p] * e / am;
    }
    let d_total = e * am;
    let t_final = 1.0 - a_total;
    let start = u32::reinterpret(words[(layout.offsets + tile) as usize]);
    let last = u32::reinterpret(words[layout.last as usize + p]);
    let fx = f32::cast_from(px) + 0.5;
    let fy = f32::cast_from(py) + 0.5;
    let mut acc = Array::<f32>::new(channels);
    #[unroll]
    for ch in 0..channels {
        acc[ch] = 0.0;
    }
    let mut t = 1.0f32;
    let mut acc_depth = 0.0f32;
    for k in 0..last {
        let rank = u32::reinterpret(words[(layout.ids + start + k) as usize]);
        let row = (layout.rows + rank * layout.stride) as usize;
        let dx = fx - words[row + MX];
        let dy = fy - words[row + MY];
        let (a, b, c) = (words[row + CA], words[row + CB], words[row + CC]);
        let sigma = 0.5 * (a * dx * dx + c * dy * dy) + b * dx * dy;
        let expo = f32::exp(-sigma);
        let raw = words[row + OPACITY] * expo;
        let alpha = f32::min(raw, max_alpha);
        if sigma >= 0.0 && alpha >= threshold {
            let w = alpha * t;
            let inv = 1.0 / (1.0 - alpha);
            let z = words[row + DEPTH];
            acc_depth += w * z;
            let mut d_alpha = g_alpha * t_final * inv + g_depth * (t * z - (d_total - acc_depth) * inv);
            let base = (rank * slots) as usize;
            #[unroll]
            for ch in 0..channels {
                let col = words[row + COLOR + ch];
                acc[ch] += w * col;
                let gc = grad[ch * npx + p];
                d_alpha += gc * (t * col - (rendered[ch * npx + p] - acc[ch]) * inv);
                grads[base + 7 + ch].fetch_add(w * gc);
            }
            grads[base + 6].fetch_add(w * g_depth);
            if raw < max_alpha {
                let ds = -d_alpha * alpha;
                grads[base + 5].fetch_add(d_alpha * expo);
                grads[base].fetch_add(-ds * (a * dx + b * dy));
                grads[base + 1].fetch_add(-ds * (b * dx + c * dy));
                grads[base + 2].fetch_add(ds * 0.5 * dx * dx);
                grads[base + 3].fetch_add(ds * dx * dy);
                grads[base + 4].fetch_add(ds * 0.5 * dy * dy);
            }
            t *= 1.0 - alpha;
        }
    }
}
