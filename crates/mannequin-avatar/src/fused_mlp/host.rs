//! The passes over host slices for fixed widths `I → H → H → O` (compile-time, so every product
//! is a small matrix product the compiler unrolls and vectorises). Rows go through in tiles of
//! [`TILE`]: each layer is one tile × weights product, and each weight gradient one transposed
//! tile × gradient tile product, all in L1. Rows are split into [`CHUNKS`] fixed chunks run in
//! parallel; each chunk sums its own weight gradients, and the chunks are added in order, so the
//! result does not depend on the thread count.

use rayon::prelude::*;

/// Fixed number of row chunks (see the module doc).
const CHUNKS: usize = 16;

/// Rows per tile: its activations (`TILE × H` floats per layer) stay in L1.
const TILE: usize = 32;

/// Output rows per register block: each loaded row of the right factor feeds `MR` independent
/// accumulator rows, so the fused multiply-adds are not serialised on one row's latency.
const MR: usize = 4;

/// The network's parameters, row-major: `w0 [I, H]`, `b0 [H]`, `w1 [H, H]`, `b1 [H]`,
/// `w2 [H, O]`, `b2 [O]`.
pub struct Weights<'a> {
    pub w: [&'a [f32]; 3],
    pub b: [&'a [f32]; 3],
}

/// A row-major `[R, C]` slice as rows.
fn rows<const R: usize, const C: usize>(values: &[f32]) -> &[[f32; C]; R] {
    values.as_chunks::<C>().0.try_into().expect("matrix shape")
}

fn rows_mut<const R: usize, const C: usize>(values: &mut [f32]) -> &mut [[f32; C]; R] {
    values.as_chunks_mut::<C>().0.try_into().expect("matrix shape")
}

/// `c += a·b` (`a [M, K]` given by `a(row, k)`, `b [K, N]`, `c [M, N]`), `B` rows of `c` at a
/// time (`M` is a multiple of `B`); `a` is an accessor so a transposed tile needs no copy.
#[inline(always)]
fn mul_add<const B: usize, const M: usize, const K: usize, const N: usize>(
    c: &mut [[f32; N]; M],
    a: impl Fn(usize, usize) -> f32,
    b: &[[f32; N]; K],
) {
    for (block, c) in c.as_chunks_mut::<B>().0.iter_mut().enumerate() {
        let mut acc = *c;
        for (k, b) in b.iter().enumerate() {
            for (r, acc) in acc.iter_mut().enumerate() {
                let s = a(block * B + r, k);
                acc.iter_mut().zip(b).for_each(|(x, b)| *x = s.mul_add(*b, *x));
            }
        }
        *c = acc;
    }
}

/// `h = max(0, bias + a·w)` for a tile.
#[inline(always)]
fn relu_layer<const K: usize, const N: usize>(
    h: &mut [[f32; N]; TILE],
    a: &[[f32; K]; TILE],
    w: &[[f32; N]; K],
    bias: &[f32],
) {
    h.fill(bias.try_into().expect("bias width"));
    mul_add::<MR, TILE, K, N>(h, |r, k| a[r][k], w);
    h.as_flattened_mut().iter_mut().for_each(|x| *x = x.max(0.0));
}

/// `bias + h·W` for a layer of few outputs, from `wt = Wᵀ`: one dot product per output, summed
/// in 16 lanes so that it vectorises.
fn narrow_layer<const K: usize, const N: usize>(h: &[f32; K], wt: &[[f32; K]; N], bias: &[f32]) -> [f32; N] {
    std::array::from_fn(|o| {
        let mut lanes = [0.0f32; 16];
        for (h, w) in h.as_chunks::<16>().0.iter().zip(wt[o].as_chunks::<16>().0) {
            lanes.iter_mut().zip(h.iter().zip(w)).for_each(|(l, (h, w))| *l = h.mul_add(*w, *l));
        }
        bias[o] + lanes.iter().sum::<f32>()
    })
}

/// `g = upstream·Wᵀ` for a tile (from `wt = Wᵀ`), zeroed where the layer's input `h` was
/// clipped by its ReLU (none for the network's input).
#[inline(always)]
fn back_layer<const K: usize, const N: usize>(
    g: &mut [[f32; N]; TILE],
    upstream: &[[f32; K]; TILE],
    wt: &[[f32; N]; K],
    h: Option<&[[f32; N]; TILE]>,
) {
    g.fill([0.0; N]);
    mul_add::<MR, TILE, K, N>(g, |r, k| upstream[r][k], wt);
    if let Some(h) = h {
        let h = h.as_flattened();
        g.as_flattened_mut().iter_mut().zip(h).for_each(|(g, h)| *g = if *h > 0.0 { *g } else { 0.0 });
    }
}

fn transpose<const M: usize, const N: usize>(a: &[[f32; N]; M]) -> [[f32; M]; N] {
    std::array::from_fn(|j| std::array::from_fn(|i| a[i][j]))
}

/// Loads rows `start..start + TILE` of a `[n, C]` slice, zero past its end; returns how many
/// rows were present.
fn load<const C: usize>(t: &mut [[f32; C]; TILE], values: &[f32], start: usize) -> usize {
    let present = &values.as_chunks::<C>().0[start..];
    let m = present.len().min(TILE);
    t[..m].copy_from_slice(&present[..m]);
    t[m..].fill([0.0; C]);
    m
}

/// One tile's activations and gradients, reused across a chunk's tiles.
struct Tile<const I: usize, const H: usize, const O: usize> {
    x: [[f32; I]; TILE],
    h1: [[f32; H]; TILE],
    h2: [[f32; H]; TILE],
    g0: [[f32; H]; TILE],
    g1: [[f32; H]; TILE],
    g2: [[f32; O]; TILE],
    dx: [[f32; I]; TILE],
}

impl<const I: usize, const H: usize, const O: usize> Tile<I, H, O> {
    fn new() -> Box<Self> {
        Box::new(Tile {
            x: [[0.0; I]; TILE],
            h1: [[0.0; H]; TILE],
            h2: [[0.0; H]; TILE],
            g0: [[0.0; H]; TILE],
            g1: [[0.0; H]; TILE],
            g2: [[0.0; O]; TILE],
            dx: [[0.0; I]; TILE],
        })
    }

    /// Loads the inputs from row `start` and computes the hidden activations (after the ReLUs);
    /// returns how many rows were present.
    fn hidden(&mut self, x: &[f32], start: usize, p: &Weights) -> usize {
        let m = load(&mut self.x, x, start);
        relu_layer(&mut self.h1, &self.x, rows::<I, H>(p.w[0]), p.b[0]);
        relu_layer(&mut self.h2, &self.h1, rows::<H, H>(p.w[1]), p.b[1]);
        m
    }
}

/// The rows of `n` that chunk `c` covers.
fn chunk_rows(n: usize, c: usize) -> std::ops::Range<usize> {
    let per_chunk = n.div_ceil(CHUNKS).max(1);
    (c * per_chunk).min(n)..((c + 1) * per_chunk).min(n)
}

pub fn forward<const I: usize, const H: usize, const O: usize>(x: &[f32], p: &Weights) -> Vec<f32> {
    let n = x.len() / I;
    let wt2: [[f32; H]; O] = transpose(rows::<H, O>(p.w[2]));
    let chunks: Vec<Vec<f32>> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let rows_c = chunk_rows(n, c);
            let mut out = Vec::with_capacity(rows_c.len() * O);
            let mut t = Tile::<I, H, O>::new();
            for start in rows_c.clone().step_by(TILE) {
                let m = t.hidden(&x[..rows_c.end * I], start, p);
                t.h2[..m].iter().for_each(|h| out.extend(narrow_layer(h, &wt2, p.b[2])));
            }
            out
        })
        .collect();
    chunks.concat()
}

/// Gradients of one chunk: `(dx rows, [dw0, dw1, dw2ᵀ], [db0, db1, db2])`.
type ChunkGrads = (Vec<f32>, [Vec<f32>; 3], [Vec<f32>; 3]);

/// `db += Σ_r g_r`.
fn add_rows<const N: usize>(db: &mut [f32], g: &[[f32; N]; TILE]) {
    g.iter().for_each(|g| db.iter_mut().zip(g).for_each(|(d, x)| *d += x));
}

/// `(dx [N, I], [dw0, dw1, dw2], [db0, db1, db2])` given `grad` `[N, O]` of the outputs; the
/// activations are recomputed (cheaper than storing them).
pub fn backward<const I: usize, const H: usize, const O: usize>(
    x: &[f32],
    grad: &[f32],
    p: &Weights,
) -> (Vec<f32>, [Vec<f32>; 3], [Vec<f32>; 3]) {
    let n = x.len() / I;
    let wt0: [[f32; I]; H] = transpose(rows::<I, H>(p.w[0]));
    let wt1: [[f32; H]; H] = transpose(rows::<H, H>(p.w[1]));
    let wt2: [[f32; H]; O] = transpose(rows::<H, O>(p.w[2]));
    let chunks: Vec<ChunkGrads> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let rows_c = chunk_rows(n, c);
            let mut dx = Vec::with_capacity(rows_c.len() * I);
            let mut dw = [vec![0.0f32; I * H], vec![0.0f32; H * H], vec![0.0f32; O * H]];
            let mut db = [vec![0.0f32; H], vec![0.0f32; H], vec![0.0f32; O]];
            let mut t = Tile::<I, H, O>::new();
            for start in rows_c.clone().step_by(TILE) {
                // Rows past the chunk's end have zero output gradient, so they add nothing.
                let m = t.hidden(&x[..rows_c.end * I], start, p);
                load(&mut t.g2, &grad[..rows_c.end * O], start);
                let Tile { x, h1, h2, g0, g1, g2, dx: dx_t } = &mut *t;
                back_layer(g1, g2, &wt2, Some(h2));
                back_layer(g0, g1, &wt1, Some(h1));
                back_layer(dx_t, g0, &wt0, None);
                dx.extend_from_slice(dx_t[..m].as_flattened());
                mul_add::<MR, I, TILE, H>(rows_mut(&mut dw[0]), |i, r| x[r][i], g0);
                mul_add::<MR, H, TILE, H>(rows_mut(&mut dw[1]), |i, r| h1[r][i], g1);
                mul_add::<O, O, TILE, H>(rows_mut(&mut dw[2]), |o, r| g2[r][o], h2);
                add_rows(&mut db[0], g0);
                add_rows(&mut db[1], g1);
                add_rows(&mut db[2], g2);
            }
            (dx, dw, db)
        })
        .collect();
    let mut dx = Vec::with_capacity(n * I);
    let mut dw = [vec![0.0f32; I * H], vec![0.0f32; H * H], vec![0.0f32; O * H]];
    let mut db = [vec![0.0f32; H], vec![0.0f32; H], vec![0.0f32; O]];
    for (cdx, cdw, cdb) in chunks {
        dx.extend(cdx);
        for (total, part) in dw.iter_mut().chain(db.iter_mut()).zip(cdw.iter().chain(cdb.iter())) {
            total.iter_mut().zip(part).for_each(|(t, p)| *t += p);
        }
    }
    let dw2 = transpose(rows::<O, H>(&dw[2])).as_flattened().to_vec();
    let [dw0, dw1, _] = dw;
    (dx, [dw0, dw1, dw2], db)
}
