//! Hash-grid encoding of the default body's 13,380 template vertices with the default config
//! (16 levels, T = 2^17, F = 2): forward, and forward + backward through autodiff, on Flex,
//! against a naive baseline timed in the same run: a single-threaded loop that recomputes every
//! level's cell, weights and hash on each call and scatters the gradient directly.
//!
//! `cargo bench -p mannequin-avatar --bench hash_grid` (add `-- --quick` for fewer repetitions,
//! `-- --ours-only` to skip the baseline when profiling).

use std::time::Instant;

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::hash_grid::{Aabb, HashGridConfig, HashGridLookup, encode, init_table};
use mannequin_body::BodyModel;

mod timing;

/// Median wall time of `f` in milliseconds, after one warm-up call.
fn median_ms(reps: usize, f: impl FnMut()) -> f64 {
    timing::median_and_min_ms(reps, f).0
}

/// The encoding recomputed from the positions, as a direct reading of the paper would do it.
struct Naive<'a> {
    config: HashGridConfig,
    aabb: Aabb,
    points: &'a [[f32; 3]],
}

impl Naive<'_> {
    /// Calls `visit(point, level, row, weight)` for every corner of every level of every point.
    fn corners(&self, mut visit: impl FnMut(usize, usize, usize, f32)) {
        let c = &self.config;
        let t = c.table_size() as u32;
        for (i, p) in self.points.iter().enumerate() {
            for l in 0..c.levels {
                let n = (c.base_resolution as f64 * c.growth.powi(l as i32)).floor() as u32;
                let mut cell = [0u32; 3];
                let mut frac = [0f32; 3];
                for k in 0..3 {
                    let u = (p[k] - self.aabb.min[k]) / (self.aabb.max[k] - self.aabb.min[k]);
                    let x = u * n as f32;
                    let f = x.floor().min(n as f32 - 1.0);
                    cell[k] = f as u32;
                    frac[k] = x - f;
                }
                let dense = (n as u64 + 1).pow(3) <= t as u64;
                for corner in 0..8 {
                    let mut w = 1.0;
                    let mut q = cell;
                    for k in 0..3 {
                        if corner >> k & 1 == 1 {
                            q[k] += 1;
                            w *= frac[k];
                        } else {
                            w *= 1.0 - frac[k];
                        }
                    }
                    let index = if dense {
                        q[0] + (n + 1) * (q[1] + (n + 1) * q[2])
                    } else {
                        (q[0] ^ q[1].wrapping_mul(2_654_435_761) ^ q[2].wrapping_mul(805_459_861)) & (t - 1)
                    };
                    visit(i, l, (l as u32 * t + index) as usize, w);
                }
            }
        }
    }

    fn forward(&self, table: &[f32]) -> Vec<f32> {
        let f = self.config.features_per_level;
        let width = self.config.output_dim();
        let mut out = vec![0.0; self.points.len() * width];
        self.corners(|i, l, row, w| {
            for k in 0..f {
                out[i * width + l * f + k] += w * table[row * f + k];
            }
        });
        out
    }

    fn backward(&self, grad: &[f32]) -> Vec<f32> {
        let f = self.config.features_per_level;
        let width = self.config.output_dim();
        let mut d = vec![0.0; self.config.table_rows() * f];
        self.corners(|i, l, row, w| {
            for k in 0..f {
                d[row * f + k] += w * grad[i * width + l * f + k];
            }
        });
        d
    }
}

fn main() {
    let reps = if std::env::args().any(|a| a == "--quick") { 5 } else { 21 };
    let points = BodyModel::default_body().v_template;
    let config = HashGridConfig::default();
    let aabb = Aabb::enclosing(&points, 0.05).expect("the template spans a box");
    println!(
        "{} points, {} levels, T = 2^{}, F = {}, {} threads",
        points.len(),
        config.levels,
        config.log2_table_size,
        config.features_per_level,
        rayon::current_num_threads()
    );

    let start = Instant::now();
    let host = HashGridLookup::new(&config, &aabb, &points).expect("template inside its box");
    println!("lookup (once per point set): {:.1} ms", start.elapsed().as_secs_f64() * 1e3);

    let flex = Device::flex();
    let lookup = host.to_device(&flex, DType::F32).expect("f32 lookup");
    let table = init_table(&config, 1, &flex);
    let forward = median_ms(reps, || {
        let _ = encode(&lookup, table.clone()).expect("encode").into_data();
    });

    let autodiff = flex.clone().autodiff();
    let ad_lookup = host.to_device(&autodiff, DType::F32).expect("f32 lookup");
    let leaf = init_table(&config, 1, &autodiff).require_grad();
    let shape = [points.len(), config.output_dim()];
    let upstream: Vec<f32> = (0..shape[0] * shape[1]).map(|i| ((i % 7) as f32 - 3.0) * 0.1).collect();
    let weights = Tensor::<2>::from_data(TensorData::new(upstream.clone(), shape), (&autodiff, DType::F32));
    let both = median_ms(reps, || {
        let grads = (encode(&ad_lookup, leaf.clone()).expect("encode") * weights.clone()).sum().backward();
        assert!(leaf.grad(&grads).is_some());
    });

    if std::env::args().any(|a| a == "--ours-only") {
        println!("forward: {forward:.2} ms, forward + backward: {both:.2} ms");
        return;
    }
    let naive = Naive { config, aabb, points: &points };
    let host_table: Vec<f32> = table.clone().into_data().iter::<f32>().collect();
    let naive_forward = median_ms(reps, || {
        std::hint::black_box(naive.forward(&host_table));
    });
    let naive_both = median_ms(reps, || {
        std::hint::black_box(naive.forward(&host_table));
        std::hint::black_box(naive.backward(&upstream));
    });

    println!(
        "forward:            ours {forward:7.2} ms   naive {naive_forward:7.2} ms   ×{:.1}",
        naive_forward / forward
    );
    println!(
        "forward + backward: ours {both:7.2} ms   naive {naive_both:7.2} ms   ×{:.1}",
        naive_both / both
    );
}
