//! The counter-based random SMPL-format model of `tools/oracles/body_smplx.py`, rebuilt here so
//! the fixtures need not carry 20 MB of random bases. Must match the Python generator exactly.

use std::f64::consts::PI;

use mannequin_io::{NpyArray, NpzWriter};

const SMPL_PARENTS: [i64; 24] =
    [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21];

fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E3779B97F4A7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
    z ^ (z >> 31)
}

fn uniform(stream: u64, n: usize) -> Vec<f64> {
    (0..n as u64).map(|i| (splitmix64((stream << 32) | i) >> 11) as f64 * 2f64.powi(-53)).collect()
}

pub fn grid(rings: usize, segments: usize) -> (Vec<f32>, Vec<i64>) {
    let mut v = Vec::with_capacity(rings * segments * 3);
    for r in 0..rings {
        let phi = (r as f64 + 0.5) / rings as f64 * PI;
        for s in 0..segments {
            let lam = s as f64 / segments as f64 * 2.0 * PI;
            v.extend(
                [0.3 * phi.sin() * lam.cos(), 0.9 * phi.cos(), 0.2 * phi.sin() * lam.sin()].map(|x| x as f32),
            );
        }
    }
    let mut f = Vec::new();
    for r in 0..rings - 1 {
        for s in 0..segments {
            let (a, b) = ((r * segments + s) as i64, (r * segments + (s + 1) % segments) as i64);
            let (c, d) = (a + segments as i64, b + segments as i64);
            f.extend([a, c, b, b, c, d]);
        }
    }
    (v, f)
}

/// The model as `.npz` bytes, in the SMPL layout.
pub fn random_model_npz(joints: usize, components: usize, rings: usize, segments: usize) -> Vec<u8> {
    let (v_template, faces) = grid(rings, segments);
    let nv = v_template.len() / 3;
    let scaled =
        |stream, n| uniform(stream, n).into_iter().map(|u| (0.02 * (u - 0.5)) as f32).collect::<Vec<_>>();
    let shapedirs = scaled(1, nv * 3 * components);
    let posedirs = scaled(2, nv * 3 * 9 * (joints - 1));
    let normalise = |rows: usize, cols: usize, per: usize, pick: u64, value: u64| {
        let mut m = vec![0.0f64; rows * cols];
        let idx = uniform(pick, rows * per);
        let val = uniform(value, rows * per);
        for i in 0..rows * per {
            let c = (idx[i] * cols as f64).floor() as usize;
            m[(i / per) * cols + c] += val[i] + 0.1;
        }
        m.chunks_mut(cols).for_each(|r| {
            let s: f64 = r.iter().sum();
            r.iter_mut().for_each(|x| *x /= s);
        });
        m.into_iter().map(|x| x as f32).collect::<Vec<_>>()
    };
    let reg = normalise(joints, nv, 8, 3, 4);
    let weights = normalise(nv, joints, 4, 5, 6);
    let parents: Vec<i64> = if joints == 24 {
        SMPL_PARENTS.to_vec()
    } else {
        let u = uniform(7, joints);
        std::iter::once(-1).chain((1..joints).map(|k| (u[k] * k as f64).floor() as i64)).collect()
    };
    let mut kintree: Vec<i64> = parents.iter().map(|&p| if p < 0 { 4294967295 } else { p }).collect();
    kintree.extend(0..joints as i64);
    let mut w = NpzWriter::new();
    w.add("v_template", NpyArray::f32(vec![nv, 3], v_template))
        .add("f", NpyArray::i64(vec![faces.len() / 3, 3], faces))
        .add("shapedirs", NpyArray::f32(vec![nv, 3, components], shapedirs))
        .add("posedirs", NpyArray::f32(vec![nv, 3, 9 * (joints - 1)], posedirs))
        .add("J_regressor", NpyArray::f32(vec![joints, nv], reg))
        .add("weights", NpyArray::f32(vec![nv, joints], weights))
        .add("kintree_table", NpyArray::i64(vec![2, joints], kintree));
    w.to_bytes()
}
