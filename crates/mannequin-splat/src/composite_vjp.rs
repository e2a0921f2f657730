//! Backward pass of [`composite_tile`](crate::composite::composite_tile), replayed front to back.
//! For the colour `C = Σ cᵢ wᵢ + T_N b` with `wᵢ = αᵢ Tᵢ`,
//! `∂C/∂αᵢ = Tᵢ cᵢ − Rᵢ / (1 − αᵢ)` where `Rᵢ = Σ_{j>i} cⱼ wⱼ + T_N b` is what lies behind
//! Gaussian i; `Rᵢ` is the final colour minus the running sum, so no division by `1 − α` is
//! needed to recover `Tᵢ`. Alpha (`A = 1 − T_N`, `∂A/∂αᵢ = T_N / (1 − αᵢ)`) and accumulated
//! depth (`D = Σ zᵢ wᵢ`) follow the same pattern.

// Lane loops index several per-pixel arrays by lane; they are written that way to vectorise.
#![allow(clippy::needless_range_loop)]

use crate::TILE;
use crate::composite::{PREFETCH_AHEAD, Packed, Rule, TILE_PIXELS, TileRect, field, prefetch, row_sigma};
use crate::real::Real;

/// Gradient slots per Gaussian emitted by a tile: mean x, mean y, conic a, b, c, opacity,
/// depth, then the C colours.
pub(crate) const SCREEN_GRADS: usize = 7;

/// Per-pixel inputs of the backward pass for one tile, gathered from the full images.
pub(crate) struct TileGrads<T> {
    /// `C × 256` gradient of the loss w.r.t. the image.
    pub d_color: Vec<T>,
    /// Gradient w.r.t. alpha (including what the expected depth passes on).
    pub d_alpha: [T; TILE_PIXELS],
    /// Gradient w.r.t. the accumulated depth Σ wᵢ zᵢ.
    pub d_depth: [T; TILE_PIXELS],
    /// `C × 256` final colour with background.
    pub color: Vec<T>,
    pub transmittance: [T; TILE_PIXELS],
    /// Final accumulated depth Σ wᵢ zᵢ.
    pub depth: [T; TILE_PIXELS],
    pub last: [u32; TILE_PIXELS],
}

impl<T: Real> TileGrads<T> {
    pub fn new(channels: usize) -> Self {
        TileGrads {
            d_color: vec![T::ZERO; channels * TILE_PIXELS],
            d_alpha: [T::ZERO; TILE_PIXELS],
            d_depth: [T::ZERO; TILE_PIXELS],
            color: vec![T::ZERO; channels * TILE_PIXELS],
            transmittance: [T::ONE; TILE_PIXELS],
            depth: [T::ZERO; TILE_PIXELS],
            last: [0; TILE_PIXELS],
        }
    }
}

/// Running state of the replay, reused between tiles.
pub(crate) struct Replay<T> {
    t: [T; TILE_PIXELS],
    acc_color: Vec<T>,
    acc_depth: [T; TILE_PIXELS],
    /// Per-lane gradient sums for the current Gaussian: `SCREEN_GRADS + C` vectors of 16.
    lanes: Vec<[T; TILE]>,
}

impl<T: Real> Replay<T> {
    pub fn new(channels: usize) -> Self {
        Replay {
            t: [T::ONE; TILE_PIXELS],
            acc_color: vec![T::ZERO; channels * TILE_PIXELS],
            acc_depth: [T::ZERO; TILE_PIXELS],
            lanes: vec![[T::ZERO; TILE]; SCREEN_GRADS + channels],
        }
    }
}

/// Replays tile `rect` and writes the screen-space gradients of each Gaussian that reached a pixel
/// (`SCREEN_GRADS + C` values) into row `k` of `rows` for the list's `k`-th entry (rows of
/// Gaussians that reached none are left as they are).
pub(crate) fn composite_tile_vjp<T: Real>(
    rect: TileRect,
    list: &[u32],
    packed: &Packed<T>,
    rule: &Rule<T>,
    px: &TileGrads<T>,
    st: &mut Replay<T>,
    rows: &mut [T],
) {
    let channels = packed.stride - field::COLOR;
    st.t.fill(T::ONE);
    st.acc_color.fill(T::ZERO);
    st.acc_depth.fill(T::ZERO);
    let mut row_last = [0u32; TILE];
    for (r, rl) in row_last.iter_mut().enumerate() {
        *rl = px.last[r * TILE..(r + 1) * TILE].iter().copied().max().unwrap_or(0);
    }
    let end = row_last.iter().copied().max().unwrap_or(0) as usize;
    let half = T::from_f64(0.5);
    let (mut sigma, mut expo) = ([T::ZERO; TILE], [T::ZERO; TILE]);
    let (mut w, mut inv, mut tt, mut d_al) =
        ([T::ZERO; TILE], [T::ZERO; TILE], [T::ZERO; TILE], [T::ZERO; TILE]);
    let mut alpha = [T::ZERO; TILE];
    let mut take = [false; TILE];
    let stride = SCREEN_GRADS + channels;
    for (k, &gid) in list[..end].iter().enumerate() {
        if let Some(&ahead) = list[..end].get(k + PREFETCH_AHEAD) {
            prefetch(&packed.rows, ahead as usize * packed.stride);
        }
        let g = packed.row(gid);
        let (o, z) = (g[field::OPACITY], g[field::DEPTH]);
        let (mx, a, b, c) = (g[field::MX], g[field::A], g[field::B], g[field::C]);
        let mut touched = false;
        for lane in st.lanes.iter_mut() {
            *lane = [T::ZERO; TILE];
        }
        for r in rect.rows(g) {
            if row_last[r] as usize <= k || !rect.row_reached(g, r) {
                continue;
            }
            touched = true;
            let dy = T::from_f64((rect.y0 + r) as f64 + 0.5) - g[field::MY];
            row_sigma(g, rect.x0, dy, &mut sigma, &mut expo);
            let base = r * TILE;
            let (vz, rest) = st.lanes.split_at_mut(SCREEN_GRADS);
            let vz = &mut vz[6];
            for l in 0..TILE {
                let p = base + l;
                let al = (o * expo[l]).min(rule.max_alpha);
                let tk = (k as u32) < px.last[p] && sigma[l] >= T::ZERO && al >= rule.threshold;
                let t = st.t[p];
                let wl = if tk { al * t } else { T::ZERO };
                let il = T::ONE / (T::ONE - al);
                st.acc_depth[p] += wl * z;
                d_al[l] = px.d_alpha[p] * px.transmittance[p] * il
                    + px.d_depth[p] * (t * z - (px.depth[p] - st.acc_depth[p]) * il);
                vz[l] += wl * px.d_depth[p];
                take[l] = tk;
                alpha[l] = al;
                w[l] = wl;
                inv[l] = il;
                tt[l] = t;
            }
            for ch in 0..channels {
                let col = g[field::COLOR + ch];
                let off = ch * TILE_PIXELS + base;
                let acc = &mut st.acc_color[off..off + TILE];
                let dc = &px.d_color[off..off + TILE];
                let total = &px.color[off..off + TILE];
                let vcol = &mut rest[ch];
                for l in 0..TILE {
                    acc[l] += w[l] * col;
                    d_al[l] += dc[l] * (tt[l] * col - (total[l] - acc[l]) * inv[l]);
                    vcol[l] += w[l] * dc[l];
                }
            }
            let [vmx, vmy, va, vb, vc, vo, _] =
                <&mut [[T; TILE]; SCREEN_GRADS]>::try_from(&mut st.lanes[..SCREEN_GRADS])
                    .expect("SCREEN_GRADS lanes");
            let bdy = b * dy;
            let base_dx = T::from_f64(rect.x0 as f64 + 0.5) - mx;
            for l in 0..TILE {
                // Where alpha was capped it no longer depends on o or σ.
                let free = take[l] && o * expo[l] < rule.max_alpha;
                let da = if free { d_al[l] } else { T::ZERO };
                let ds = -da * alpha[l];
                let dx = base_dx + T::from_f64(l as f64);
                vo[l] += da * expo[l];
                vmx[l] -= ds * (a * dx + bdy);
                vmy[l] -= ds * (b * dx + c * dy);
                va[l] += ds * half * dx * dx;
                vb[l] += ds * dx * dy;
                vc[l] += ds * half * dy * dy;
                let p = base + l;
                st.t[p] = if take[l] { tt[l] * (T::ONE - alpha[l]) } else { tt[l] };
            }
        }
        if touched {
            for (s, lane) in rows[k * stride..(k + 1) * stride].iter_mut().zip(&st.lanes) {
                *s = lane.iter().copied().sum();
            }
        }
    }
}
