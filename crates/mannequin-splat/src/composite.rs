//! Front-to-back alpha compositing of one tile (3DGS eq. 3): `C = Σ cᵢ αᵢ Tᵢ + T_N · background`
//! with `Tᵢ = Π_{j<i} (1 − αⱼ)` and `αᵢ = min(0.99, oᵢ exp(−σᵢ))`. A Gaussian is skipped at a
//! pixel where `σ < 0` or `α < 1/255`, and a pixel stops before the Gaussian that would bring
//! its transmittance to 1e-4 or below (the CUDA rasterizers' rule).
//!
//! The tile is processed one 16-pixel row at a time, so each per-pixel loop is one 512-bit
//! vector of `f32`. Rows that a Gaussian cannot reach (its ellipse at the alpha threshold misses
//! them) are skipped; this never changes a pixel.

// Lane loops index several per-pixel arrays by lane; they are written that way to vectorise.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use crate::TILE;
use crate::project::Projection;
use crate::real::Real;
use crate::tiles::{CULL_SLACK, Tiles};

/// How many list entries ahead to prefetch.
pub(crate) const PREFETCH_AHEAD: usize = 2;

/// Pixels in one tile.
pub(crate) const TILE_PIXELS: usize = TILE * TILE;

/// Offsets into a packed Gaussian row.
pub(crate) mod field {
    pub const MX: usize = 0;
    pub const MY: usize = 1;
    pub const A: usize = 2;
    pub const B: usize = 3;
    pub const C: usize = 4;
    pub const OPACITY: usize = 5;
    pub const DEPTH: usize = 6;
    /// `ln(o / threshold)` + slack: the σ level beyond which alpha is under the threshold.
    pub const LEVEL: usize = 7;
    /// `1/Σ'_yy`: the row-wise minimum of σ is `½ dy² / Σ'_yy`.
    pub const INV_SYY: usize = 8;
    pub const B_OVER_A: usize = 9;
    pub const TWO_OVER_A: usize = 10;
    /// Half-height in pixels of the ellipse `σ ≤ level`.
    pub const Y_EXTENT: usize = 11;
    /// First colour channel.
    pub const COLOR: usize = 12;
}

/// Projected Gaussians packed one row each (`field::*`, then C colours), so a tile reads one
/// or two cache lines per Gaussian.
#[derive(Clone, Debug)]
pub(crate) struct Packed<T> {
    pub stride: usize,
    pub rows: Vec<T>,
}

impl<T: Real> Packed<T> {
    /// Packs the Gaussians `order` (the visible ones, front to back) in that order.
    pub fn new(p: &Projection<T>, opacities: &[T], channels: usize, threshold: f64, order: &[u32]) -> Self {
        let stride = field::COLOR + channels;
        let mut rows = vec![T::ZERO; stride * order.len()];
        rows.par_chunks_mut(stride).zip(order.par_iter()).for_each(|(row, &i)| {
            let i = i as usize;
            let [a, b, c] = [0, 1, 2].map(|k| p.conics[3 * i + k].to_f64());
            let o = opacities[i].to_f64();
            let level = if threshold > 0.0 { (o / threshold).ln() + CULL_SLACK } else { f64::INFINITY };
            let inv_syy = (a * c - b * b) / a;
            let head = [
                p.means2d[2 * i].to_f64(),
                p.means2d[2 * i + 1].to_f64(),
                a,
                b,
                c,
                o,
                p.depths[i].to_f64(),
                level,
                inv_syy,
                b / a,
                2.0 / a,
                (2.0 * level.max(0.0) / inv_syy).sqrt(),
            ];
            for (dst, v) in row.iter_mut().zip(head) {
                *dst = T::from_f64(v);
            }
            row[field::COLOR..].copy_from_slice(&p.colors[channels * i..channels * (i + 1)]);
        });
        Packed { stride, rows }
    }

    /// The row of the Gaussian with depth rank `i`.
    pub fn row(&self, i: u32) -> &[T] {
        let i = i as usize;
        &self.rows[self.stride * i..self.stride * (i + 1)]
    }
}

/// Asks the CPU to start loading `data[at..]` into cache: tile lists jump around the packed rows
/// and gradient buffers, and the loads would otherwise stall the lane loops.
#[inline(always)]
pub(crate) fn prefetch<T>(data: &[T], at: usize) {
    #[cfg(target_arch = "x86_64")]
    if at < data.len() {
        // SAFETY: a prefetch is only a hint: it cannot fault or change memory, and SSE (which
        // provides it) is part of the x86_64 baseline. The address is inside `data`.
        unsafe {
            std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                data.as_ptr().add(at).cast(),
            );
        }
    }
}

/// The compositing rule's constants, in the renderer's scalar type.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rule<T> {
    pub threshold: T,
    pub max_alpha: T,
    pub min_transmittance: T,
}

/// Where a tile lies in the image.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TileRect {
    pub x0: usize,
    pub y0: usize,
    /// Pixels of the tile inside the image.
    pub w: usize,
    pub h: usize,
}

impl TileRect {
    pub fn new(tiles: &Tiles, tile: usize, width: usize, height: usize) -> Self {
        let (x0, y0) = ((tile % tiles.tiles_x) * TILE, (tile / tiles.tiles_x) * TILE);
        TileRect { x0, y0, w: (width - x0).min(TILE), h: (height - y0).min(TILE) }
    }

    /// The rows `[r0, r1)` of this tile that a Gaussian with row `g` can reach, skipping those
    /// where its peak alpha is under the threshold.
    pub fn rows<T: Real>(&self, g: &[T]) -> std::ops::Range<usize> {
        let (my, ext) = (g[field::MY].to_f64(), g[field::Y_EXTENT].to_f64());
        let base = self.y0 as f64 + 0.5;
        let r0 = (my - ext - base).ceil().clamp(0.0, self.h as f64) as usize;
        let r1 = ((my + ext - base).floor() + 1.0).clamp(0.0, self.h as f64) as usize;
        r0..r1
    }

    /// Whether the Gaussian's ellipse at the threshold meets pixel row `r` of this tile.
    #[inline(always)]
    pub fn row_reached<T: Real>(&self, g: &[T], r: usize) -> bool {
        let dy = T::from_f64((self.y0 + r) as f64 + 0.5) - g[field::MY];
        let q = T::from_f64(0.5) * dy * dy * g[field::INV_SYY];
        let room = g[field::LEVEL] - q;
        if matches!(room.partial_cmp(&T::ZERO), Some(std::cmp::Ordering::Less) | None) {
            return false;
        }
        let half = (room * g[field::TWO_OVER_A]).sqrt();
        let xc = g[field::MX] - g[field::B_OVER_A] * dy;
        let (lo, hi) = (T::from_f64(self.x0 as f64 + 0.5), T::from_f64((self.x0 + self.w) as f64 - 0.5));
        xc + half >= lo && xc - half <= hi
    }
}

/// `σ` and the exponential at one row of 16 pixels: the shared first step of the forward and
/// backward passes (they must agree bit for bit on which Gaussians a pixel used).
#[inline(always)]
pub(crate) fn row_sigma<T: Real>(g: &[T], x0: usize, dy: T, sigma: &mut [T; TILE], expo: &mut [T; TILE]) {
    let (mx, a, b, c) = (g[field::MX], g[field::A], g[field::B], g[field::C]);
    let half = T::from_f64(0.5);
    let cdy = half * c * dy * dy;
    let bdy = b * dy;
    let base = T::from_f64(x0 as f64 + 0.5) - mx;
    for l in 0..TILE {
        let dx = base + T::from_f64(l as f64);
        let s = half * a * dx * dx + bdy * dx + cdy;
        sigma[l] = s;
        expo[l] = (-s).exp_clamped();
    }
}

/// Per-pixel results of compositing one tile, row-major within the tile.
pub(crate) struct TileOut<T> {
    pub transmittance: [T; TILE_PIXELS],
    /// Σ wᵢ zᵢ (not yet divided by alpha).
    pub depth: [T; TILE_PIXELS],
    /// `C × 256`, channel-major, without background.
    pub color: Vec<T>,
    /// Number of list entries each pixel consumed (backward replays up to here).
    pub last: [u32; TILE_PIXELS],
    pub count: [u32; TILE_PIXELS],
}

impl<T: Real> TileOut<T> {
    pub fn new(channels: usize) -> Self {
        TileOut {
            transmittance: [T::ONE; TILE_PIXELS],
            depth: [T::ZERO; TILE_PIXELS],
            color: vec![T::ZERO; channels * TILE_PIXELS],
            last: [0; TILE_PIXELS],
            count: [0; TILE_PIXELS],
        }
    }
}

/// Composites tile `rect` from its depth-sorted list into `out` (which is reset first).
pub(crate) fn composite_tile<T: Real>(
    rect: TileRect,
    list: &[u32],
    packed: &Packed<T>,
    rule: &Rule<T>,
    out: &mut TileOut<T>,
) {
    let channels = packed.stride - field::COLOR;
    out.transmittance.fill(T::ONE);
    out.depth.fill(T::ZERO);
    out.color.fill(T::ZERO);
    out.last.fill(0);
    out.count.fill(0);
    // A pixel is done once it has stopped (or lies outside the image).
    let mut done = [true; TILE_PIXELS];
    for r in 0..rect.h {
        done[r * TILE..r * TILE + rect.w].fill(false);
    }
    let mut row_live = [false; TILE];
    row_live[..rect.h].fill(true);
    let mut live_rows = rect.h;
    let (mut sigma, mut expo, mut w) = ([T::ZERO; TILE], [T::ZERO; TILE], [T::ZERO; TILE]);
    for (k, &gid) in list.iter().enumerate() {
        if let Some(&ahead) = list.get(k + PREFETCH_AHEAD) {
            prefetch(&packed.rows, ahead as usize * packed.stride);
        }
        let g = packed.row(gid);
        let (o, z) = (g[field::OPACITY], g[field::DEPTH]);
        let entry = k as u32 + 1;
        for r in rect.rows(g) {
            if !row_live[r] || !rect.row_reached(g, r) {
                continue;
            }
            let dy = T::from_f64((rect.y0 + r) as f64 + 0.5) - g[field::MY];
            row_sigma(g, rect.x0, dy, &mut sigma, &mut expo);
            let base = r * TILE;
            let mut stopped = false;
            for l in 0..TILE {
                let p = base + l;
                let alpha = (o * expo[l]).min(rule.max_alpha);
                let ok = sigma[l] >= T::ZERO && alpha >= rule.threshold && !done[p];
                let t = out.transmittance[p];
                let next = t * (T::ONE - alpha);
                let stop = ok && next <= rule.min_transmittance;
                let take = ok && !stop;
                done[p] |= stop;
                stopped |= stop;
                w[l] = if take { alpha * t } else { T::ZERO };
                out.transmittance[p] = if take { next } else { t };
                out.last[p] = if take { entry } else { out.last[p] };
                out.count[p] += take as u32;
            }
            for l in 0..TILE {
                out.depth[base + l] += w[l] * z;
            }
            for ch in 0..channels {
                let col = g[field::COLOR + ch];
                let plane = &mut out.color[ch * TILE_PIXELS + base..ch * TILE_PIXELS + base + TILE];
                for l in 0..TILE {
                    plane[l] += w[l] * col;
                }
            }
            if stopped && done[base..base + TILE].iter().all(|&d| d) {
                row_live[r] = false;
                live_rows -= 1;
            }
        }
        if live_rows == 0 {
            break;
        }
    }
}
