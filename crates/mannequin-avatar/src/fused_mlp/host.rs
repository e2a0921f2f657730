//! The passes over host slices for fixed widths `I → H → H → O` (compile-time, so each row's
//! activations stay in vector registers). Rows are split into [`CHUNKS`] fixed chunks run in
//! parallel; each chunk sums its own weight gradients, and the chunks are added in order, so
//! the result does not depend on the thread count.

use rayon::prelude::*;

/// Fixed number of row chunks (see the module doc).
const CHUNKS: usize = 16;

/// Rows whose weight-gradient outer products are summed in registers before touching memory.
const BLOCK: usize = 8;

/// The network's parameters, row-major: `w0 [I, H]`, `b0 [H]`, `w1 [H, H]`, `b1 [H]`,
/// `w2 [H, O]`, `b2 [O]`.
pub struct Weights<'a> {
    pub w: [&'a [f32]; 3],
    pub b: [&'a [f32]; 3],
}

/// `out = b + x·W` for one row (`W` row-major `[N_IN, N_OUT]`).
#[inline(always)]
fn affine<const N_IN: usize, const N_OUT: usize>(x: &[f32; N_IN], w: &[f32], b: &[f32]) -> [f32; N_OUT] {
    let mut out: [f32; N_OUT] = b.try_into().expect("bias width");
    for (xi, row) in x.iter().zip(w.chunks_exact(N_OUT)) {
        for (o, wij) in out.iter_mut().zip(row) {
            *o += xi * wij;
        }
    }
    out
}

fn relu<const N: usize>(mut h: [f32; N]) -> [f32; N] {
    h.iter_mut().for_each(|x| *x = x.max(0.0));
    h
}

/// The hidden activations of one row (after the ReLUs).
#[inline(always)]
fn hidden<const I: usize, const H: usize>(x: &[f32; I], p: &Weights) -> ([f32; H], [f32; H]) {
    let h1 = relu(affine::<I, H>(x, p.w[0], p.b[0]));
    let h2 = relu(affine::<H, H>(&h1, p.w[1], p.b[1]));
    (h1, h2)
}

fn row<const N: usize>(values: &[f32], r: usize) -> &[f32; N] {
    values[r * N..][..N].try_into().expect("row width")
}

pub fn forward<const I: usize, const H: usize, const O: usize>(x: &[f32], p: &Weights) -> Vec<f32> {
    let n = x.len() / I;
    let mut out = vec![0.0f32; n * O];
    out.par_chunks_mut(O * n.div_ceil(CHUNKS).max(1)).enumerate().for_each(|(c, out)| {
        let start = c * n.div_ceil(CHUNKS).max(1);
        for (k, o) in out.chunks_exact_mut(O).enumerate() {
            let (_, h2) = hidden::<I, H>(row::<I>(x, start + k), p);
            o.copy_from_slice(&affine::<H, O>(&h2, p.w[2], p.b[2]));
        }
    });
    out
}

/// `dW += Σ_r a_r ⊗ g_r` over a block of rows (`a` `[B, N_A]`, `g` `[B, N_G]`), one weight row
/// at a time so its partial sum stays in registers.
#[inline(always)]
fn outer_add<const N_A: usize, const N_G: usize>(dw: &mut [f32], a: &[[f32; N_A]], g: &[[f32; N_G]]) {
    for (i, dw_row) in dw.chunks_exact_mut(N_G).enumerate() {
        let mut acc = [0.0f32; N_G];
        for (ar, gr) in a.iter().zip(g) {
            let s = ar[i];
            for (x, gj) in acc.iter_mut().zip(gr) {
                *x += s * gj;
            }
        }
        for (d, x) in dw_row.iter_mut().zip(acc) {
            *d += x;
        }
    }
}

/// `db += Σ_r g_r`.
fn add_rows<const N: usize>(db: &mut [f32], g: &[[f32; N]]) {
    g.iter().for_each(|g| db.iter_mut().zip(g).for_each(|(d, x)| *d += x));
}

/// `g·Wᵀ` for one row, from `wt = Wᵀ` (`[N_OUT, N_IN]`, so the sum runs over contiguous rows
/// and vectorises), zeroed where the layer's input was clipped by its ReLU (`h = 0`).
#[inline(always)]
fn back<const N_IN: usize, const N_OUT: usize>(
    g: &[f32; N_OUT],
    wt: &[f32],
    h: Option<&[f32; N_IN]>,
) -> [f32; N_IN] {
    let mut out = affine::<N_OUT, N_IN>(g, wt, &[0.0; N_IN]);
    if let Some(h) = h {
        out.iter_mut().zip(h).for_each(|(o, h)| *o = if *h > 0.0 { *o } else { 0.0 });
    }
    out
}

/// `Wᵀ` of a row-major `[rows, cols]` matrix.
fn transpose(w: &[f32], cols: usize) -> Vec<f32> {
    let rows = w.len() / cols;
    (0..cols).flat_map(|j| (0..rows).map(move |i| w[i * cols + j])).collect()
}

/// Gradients of one chunk: `(dx rows, [dw0, dw1, dw2], [db0, db1, db2])`.
type ChunkGrads = (Vec<f32>, [Vec<f32>; 3], [Vec<f32>; 3]);

/// `(dx [N, I], [dw0, dw1, dw2], [db0, db1, db2])` given `grad` `[N, O]` of the outputs; the
/// activations are recomputed (cheaper than storing them).
pub fn backward<const I: usize, const H: usize, const O: usize>(
    x: &[f32],
    grad: &[f32],
    p: &Weights,
) -> (Vec<f32>, [Vec<f32>; 3], [Vec<f32>; 3]) {
    let n = x.len() / I;
    let per_chunk = n.div_ceil(CHUNKS).max(1);
    let wt = [transpose(p.w[0], H), transpose(p.w[1], H), transpose(p.w[2], O)];
    let chunks: Vec<ChunkGrads> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let rows = (c * per_chunk).min(n)..((c + 1) * per_chunk).min(n);
            let mut dx = Vec::with_capacity(rows.len() * I);
            let mut dw = [vec![0.0f32; I * H], vec![0.0f32; H * H], vec![0.0f32; H * O]];
            let mut db = [vec![0.0f32; H], vec![0.0f32; H], vec![0.0f32; O]];
            let mut start = rows.start;
            while start < rows.end {
                let end = (start + BLOCK).min(rows.end);
                let m = end - start;
                let (mut xs, mut h1s, mut h2s) = ([[0.0; I]; BLOCK], [[0.0; H]; BLOCK], [[0.0; H]; BLOCK]);
                let (mut g0s, mut g1s, mut g2s) = ([[0.0; H]; BLOCK], [[0.0; H]; BLOCK], [[0.0; O]; BLOCK]);
                for (k, r) in (start..end).enumerate() {
                    xs[k] = *row::<I>(x, r);
                    (h1s[k], h2s[k]) = hidden::<I, H>(&xs[k], p);
                    g2s[k] = *row::<O>(grad, r);
                    g1s[k] = back::<H, O>(&g2s[k], &wt[2], Some(&h2s[k]));
                    g0s[k] = back::<H, H>(&g1s[k], &wt[1], Some(&h1s[k]));
                    dx.extend_from_slice(&back::<I, H>(&g0s[k], &wt[0], None));
                }
                outer_add::<I, H>(&mut dw[0], &xs[..m], &g0s[..m]);
                outer_add::<H, H>(&mut dw[1], &h1s[..m], &g1s[..m]);
                outer_add::<H, O>(&mut dw[2], &h2s[..m], &g2s[..m]);
                add_rows(&mut db[0], &g0s[..m]);
                add_rows(&mut db[1], &g1s[..m]);
                add_rows(&mut db[2], &g2s[..m]);
                start = end;
            }
            (dx, dw, db)
        })
        .collect();
    let mut dx = Vec::with_capacity(n * I);
    let mut dw = [vec![0.0f32; I * H], vec![0.0f32; H * H], vec![0.0f32; H * O]];
    let mut db = [vec![0.0f32; H], vec![0.0f32; H], vec![0.0f32; O]];
    for (cdx, cdw, cdb) in chunks {
        dx.extend(cdx);
        for (total, part) in dw.iter_mut().chain(db.iter_mut()).zip(cdw.iter().chain(cdb.iter())) {
            total.iter_mut().zip(part).for_each(|(t, p)| *t += p);
        }
    }
    (dx, dw, db)
}
