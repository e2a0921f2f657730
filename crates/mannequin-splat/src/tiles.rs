//! Tile binning: each 16×16 tile gets the list of Gaussians that can reach one of its pixels,
//! front to back. Gaussians are sorted by depth once, then scattered into tiles by a stable,
//! parallel counting sort, so every tile list comes out depth-ordered (ties by index).
//!
//! A Gaussian is listed in a tile only if some pixel centre of the tile can reach the alpha
//! threshold: inside gsplat's 3.33σ box, the tile must also meet the ellipse
//! `σ(d) ≤ ln(opacity / threshold)`. Pixels outside that ellipse are skipped by the compositor
//! anyway, so the test changes no pixel; it only saves work on elongated or faint splats.

use rayon::prelude::*;

use crate::TILE;
use crate::project::Projection;
use crate::real::Real;

/// Slack on the `σ ≤ ln(o/t)` test so that rounding in the compositor never meets a pixel the
/// culling dropped (1% in alpha).
pub(crate) const CULL_SLACK: f64 = 0.01;

/// Per-tile lists, concatenated. Lists hold ranks in the global depth order, so that a tile walks
/// the depth-ordered packed rows forwards (kind to caches), and `order` maps ranks to Gaussians.
#[derive(Clone, Debug)]
pub(crate) struct Tiles {
    pub tiles_x: usize,
    pub tiles_y: usize,
    /// Indices of the visible Gaussians, front to back.
    pub order: Vec<u32>,
    /// `offsets[t]..offsets[t + 1]` indexes `ids` for tile `t` (row-major over tiles).
    pub offsets: Vec<usize>,
    /// Depth ranks (indices into `order`).
    pub ids: Vec<u32>,
}

impl Tiles {
    pub fn list(&self, tile: usize) -> &[u32] {
        &self.ids[self.offsets[tile]..self.offsets[tile + 1]]
    }
}

/// The minimum of `σ(d) = ½(a dx² + c dy²) + b dx dy` over the rectangle
/// `[x0, x1] × [y0, y1]` of offsets from the mean (σ is convex, so the minimum is 0 inside or on
/// an edge).
fn min_sigma_on_rect(con: [f64; 3], x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    let [a, b, c] = con;
    if x0 <= 0.0 && 0.0 <= x1 && y0 <= 0.0 && 0.0 <= y1 {
        return 0.0;
    }
    let sigma = |dx: f64, dy: f64| 0.5 * (a * dx * dx + c * dy * dy) + b * dx * dy;
    let on_row = |dy: f64| sigma((-b * dy / a).clamp(x0, x1), dy);
    let on_col = |dx: f64| sigma(dx, (-b * dx / c).clamp(y0, y1));
    on_row(y0).min(on_row(y1)).min(on_col(x0)).min(on_col(x1))
}

/// Screen data of one Gaussian needed for binning, kept small (binning reads it twice).
struct Footprint {
    mean: [f32; 2],
    conic: [f32; 3],
    /// `ln(opacity / threshold)` plus slack; infinite without a threshold.
    level: f32,
    /// Tile rectangle `[tx0, tx1) × [ty0, ty1)`.
    rect: [u32; 4],
}

impl Footprint {
    fn new<T: Real>(
        p: &Projection<T>,
        opacity: T,
        i: usize,
        threshold: f64,
        width: usize,
        height: usize,
    ) -> Self {
        let (tx, ty) = (width.div_ceil(TILE), height.div_ceil(TILE));
        let mean = [p.means2d[2 * i].to_f64(), p.means2d[2 * i + 1].to_f64()];
        let (rx, ry) = (p.radii[2 * i] as f64, p.radii[2 * i + 1] as f64);
        let t = TILE as f64;
        // gsplat's rule: floor((m − r)/16) to ceil((m + r)/16), clamped to the image.
        let clamp = |v: f64, hi: usize| v.clamp(0.0, hi as f64) as u32;
        let rect = [
            clamp(((mean[0] - rx) / t).floor(), tx),
            clamp(((mean[0] + rx) / t).ceil(), tx),
            clamp(((mean[1] - ry) / t).floor(), ty),
            clamp(((mean[1] + ry) / t).ceil(), ty),
        ];
        let level =
            if threshold > 0.0 { (opacity.to_f64() / threshold).ln() + CULL_SLACK } else { f64::INFINITY };
        Footprint {
            mean: mean.map(|v| v as f32),
            conic: [0, 1, 2].map(|k| p.conics[3 * i + k].to_f64() as f32),
            level: level as f32,
            rect,
        }
    }

    /// Calls `f` for each tile (row-major index) the Gaussian can reach.
    fn for_each_tile(&self, tiles_x: usize, width: usize, height: usize, mut f: impl FnMut(usize)) {
        let [tx0, tx1, ty0, ty1] = self.rect.map(|v| v as usize);
        let (mx, my) = (self.mean[0] as f64, self.mean[1] as f64);
        let conic = self.conic.map(f64::from);
        let level = self.level as f64;
        // A single tile needs no test: the 3.33σ box already put the Gaussian there.
        let test = level.is_finite() && (tx1 - tx0) * (ty1 - ty0) > 1;
        for ty in ty0..ty1 {
            for tx in tx0..tx1 {
                if test {
                    // Pixel centres of the tile, clipped to the image.
                    let x0 = (tx * TILE) as f64 + 0.5 - mx;
                    let x1 = (((tx + 1) * TILE).min(width)) as f64 - 0.5 - mx;
                    let y0 = (ty * TILE) as f64 + 0.5 - my;
                    let y1 = (((ty + 1) * TILE).min(height)) as f64 - 0.5 - my;
                    if min_sigma_on_rect(conic, x0, x1, y0, y1) > level {
                        continue;
                    }
                }
                f(ty * tiles_x + tx);
            }
        }
    }
}

/// Sorts `(key, value)` pairs by key, stably: a least-significant-digit radix sort, 16 bits a
/// pass, skipping the digits that every key shares.
fn radix_sort(items: &mut Vec<(u64, u32)>) {
    const BITS: u32 = 16;
    let mut spare = vec![(0u64, 0u32); items.len()];
    let mut count = vec![0usize; 1 << BITS];
    for shift in (0..64).step_by(BITS as usize) {
        let digit = |k: u64| ((k >> shift) & ((1 << BITS) - 1)) as usize;
        count.fill(0);
        for &(k, _) in items.iter() {
            count[digit(k)] += 1;
        }
        if count.contains(&items.len()) {
            continue;
        }
        let mut running = 0;
        for c in count.iter_mut() {
            (*c, running) = (running, running + *c);
        }
        for &item in items.iter() {
            let d = digit(item.0);
            spare[count[d]] = item;
            count[d] += 1;
        }
        std::mem::swap(items, &mut spare);
    }
}

/// The Gaussians that can reach a pixel, front to back (ties by index, so the order is
/// deterministic).
fn depth_order<T: Real>(p: &Projection<T>, opacities: &[T], threshold: f64) -> Vec<u32> {
    let mut keyed: Vec<(u64, u32)> = (0..p.depths.len())
        .filter(|&i| p.radii[2 * i] > 0 && opacities[i].to_f64() >= threshold)
        .map(|i| (p.depths[i].order_key(), i as u32))
        .collect();
    radix_sort(&mut keyed);
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// The tiles of a run of consecutive Gaussians (in depth order), listed once and reused by the
/// scatter.
struct RunTiles {
    /// Tile indices, Gaussian after Gaussian.
    tiles: Vec<u32>,
    /// How many tiles each Gaussian has.
    per_gaussian: Vec<u32>,
    /// How many Gaussians of the run each tile gets.
    per_tile: Vec<usize>,
}

/// Bins the projected Gaussians into 16×16 tiles of a `width × height` image.
pub(crate) fn bin<T: Real>(
    p: &Projection<T>,
    opacities: &[T],
    threshold: f64,
    width: usize,
    height: usize,
) -> Tiles {
    let (tiles_x, tiles_y) = (width.div_ceil(TILE), height.div_ceil(TILE));
    let n_tiles = tiles_x * tiles_y;
    let order = depth_order(p, opacities, threshold);

    // Stable counting sort by tile, in parallel over runs of the depth order.
    let chunk = order.len().div_ceil(4 * rayon::current_num_threads()).max(1);
    let runs: Vec<RunTiles> = order
        .par_chunks(chunk)
        .map(|part| {
            let mut run = RunTiles {
                tiles: Vec::with_capacity(4 * part.len()),
                per_gaussian: Vec::with_capacity(part.len()),
                per_tile: vec![0; n_tiles],
            };
            for &i in part {
                let before = run.tiles.len();
                let foot = Footprint::new(p, opacities[i as usize], i as usize, threshold, width, height);
                foot.for_each_tile(tiles_x, width, height, |t| {
                    run.tiles.push(t as u32);
                    run.per_tile[t] += 1;
                });
                run.per_gaussian.push((run.tiles.len() - before) as u32);
            }
            run
        })
        .collect();
    let mut offsets = vec![0usize; n_tiles + 1];
    let mut running = 0;
    for (t, o) in offsets[1..].iter_mut().enumerate() {
        running += runs.iter().map(|r| r.per_tile[t]).sum::<usize>();
        *o = running;
    }
    // Tile t's slots hold run 0's Gaussians, then run 1's, …: hand each run its pieces.
    let mut ids = vec![0u32; offsets[n_tiles]];
    let mut pieces: Vec<Vec<&mut [u32]>> = runs.iter().map(|_| Vec::with_capacity(n_tiles)).collect();
    let mut rest: &mut [u32] = &mut ids;
    for t in 0..n_tiles {
        for (run, piece) in runs.iter().zip(pieces.iter_mut()) {
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(run.per_tile[t]);
            piece.push(head);
            rest = tail;
        }
    }
    runs.par_iter().enumerate().zip(pieces.into_par_iter()).for_each(|((c, run), mut piece)| {
        let mut filled = vec![0usize; n_tiles];
        let mut at = 0;
        for (k, &n) in run.per_gaussian.iter().enumerate() {
            let rank = (c * chunk + k) as u32;
            for &t in &run.tiles[at..at + n as usize] {
                let t = t as usize;
                piece[t][filled[t]] = rank;
                filled[t] += 1;
            }
            at += n as usize;
        }
    });
    Tiles { tiles_x, tiles_y, order, offsets, ids }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radix_sort_is_a_stable_sort() {
        let mut state = 7u64;
        let mut items: Vec<(u64, u32)> = (0..5000)
            .map(|i| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                // Few distinct keys (many ties), spread over all four 16-bit digits.
                ((state >> 61) * 0x0001_0001_0001_0001 + (state >> 62), i)
            })
            .collect();
        let mut want = items.clone();
        want.sort_by_key(|&(k, _)| k);
        radix_sort(&mut items);
        assert_eq!(items, want);
    }

    #[test]
    fn min_sigma_on_rect_matches_a_dense_search() {
        let con = [0.9, -0.7, 0.6];
        for &(x0, y0) in &[(-3.0, 2.0), (1.0, 1.0), (-10.0, -10.0), (4.0, -12.0), (-2.0, -1.0)] {
            let (x1, y1) = (x0 + 3.0, y0 + 2.0);
            let got = min_sigma_on_rect(con, x0, x1, y0, y1);
            let mut best = f64::INFINITY;
            for i in 0..=300 {
                for j in 0..=200 {
                    let (dx, dy) = (x0 + 3.0 * i as f64 / 300.0, y0 + 2.0 * j as f64 / 200.0);
                    best = best.min(0.5 * (con[0] * dx * dx + con[2] * dy * dy) + con[1] * dx * dy);
                }
            }
            assert!(got <= best + 1e-12 && got >= best - 1e-3, "rect at ({x0},{y0}): {got} vs {best}");
        }
    }
}
