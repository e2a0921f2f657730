//! The hash-grid encoder against references computed another way: linear functions that
//! trilinear interpolation must reproduce, grid corners that must return their own row, the
//! hash written out in u64 arithmetic, and central finite differences in f64. Then Flex against
//! wgpu (lavapipe on machines without a GPU), bit-identical gradients, and bad input.

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::hash_grid::{
    Aabb, HashGridConfig, HashGridError, HashGridLookup, INIT_SCALE, encode, init_table, spatial_hash,
};
use mannequin_io::rng::SplitMix64;

/// The kernels' GPU device; without one the test fails with `GpuUnavailable`'s one line.
fn wgpu() -> Device {
    mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}"))
}

fn table_f64(v: &[f64], config: &HashGridConfig, device: &Device) -> Tensor<2> {
    let shape = [config.table_rows(), config.features_per_level];
    Tensor::from_data(TensorData::new(v.to_vec(), shape), (device, DType::F64))
}

fn table_f32(v: &[f64], config: &HashGridConfig, device: &Device) -> Tensor<2> {
    let shape = [config.table_rows(), config.features_per_level];
    let v: Vec<f32> = v.iter().map(|&x| x as f32).collect();
    Tensor::from_data(TensorData::new(v, shape), (device, DType::F32))
}

fn values(t: Tensor<2>) -> Vec<f64> {
    t.into_data().iter::<f64>().collect()
}

fn random_points(n: usize, aabb: &Aabb, seed: u64) -> Vec<[f32; 3]> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| std::array::from_fn(|k| rng.range(aabb.min[k] as f64, aabb.max[k] as f64) as f32))
        .collect()
}

fn random_values(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed);
    (0..n).map(|_| rng.range(-1.0, 1.0)).collect()
}

/// One dense level of resolution 4 (5³ = 125 corners in a table of 1024 rows).
fn dense_level() -> HashGridConfig {
    HashGridConfig { levels: 1, log2_table_size: 10, base_resolution: 4, growth: 1.5, features_per_level: 2 }
}

/// A linear function of unit-cube coordinates, one per feature.
fn linear(u: [f64; 3]) -> [f64; 2] {
    [1.0 + 2.0 * u[0] - 3.0 * u[1] + 0.5 * u[2], -0.25 + u[0] + u[1] + u[2]]
}

/// The dense level's table holding `linear` at every corner (row `x + 5y + 25z`, as the paper
/// lays a dense grid out); rows past the grid hold a large value that must never be read.
fn linear_table() -> Vec<f64> {
    let config = dense_level();
    let mut table = vec![1e3; config.table_rows() * 2];
    for (x, y, z) in (0..5).flat_map(|x| (0..5).flat_map(move |y| (0..5).map(move |z| (x, y, z)))) {
        let row = x + 5 * y + 25 * z;
        let f = linear([x as f64 / 4.0, y as f64 / 4.0, z as f64 / 4.0]);
        table[row * 2..row * 2 + 2].copy_from_slice(&f);
    }
    table
}

#[test]
fn a_dense_level_reproduces_linear_functions() {
    let config = dense_level();
    let aabb = Aabb::new([-1.0, 0.0, 2.0], [1.0, 3.0, 2.5]).unwrap();
    let points = random_points(200, &aabb, 1);
    let lookup = HashGridLookup::new(&config, &aabb, &points).unwrap();
    let table = linear_table();
    let want: Vec<f64> = points
        .iter()
        .flat_map(|p| {
            let u = std::array::from_fn(|k| {
                (p[k] as f64 - aabb.min[k] as f64) / (aabb.max[k] as f64 - aabb.min[k] as f64)
            });
            linear(u)
        })
        .collect();
    let flex = Device::flex();
    let got = values(
        encode(&lookup.to_device(&flex, DType::F64).unwrap(), table_f64(&table, &config, &flex)).unwrap(),
    );
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!((g - w).abs() < 1e-12, "flex f64 [{i}]: {g} vs {w}");
    }
    let gpu = wgpu();
    let got = values(
        encode(&lookup.to_device(&gpu, DType::F32).unwrap(), table_f32(&table, &config, &gpu)).unwrap(),
    );
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!((g - w).abs() < 1e-5, "wgpu f32 [{i}]: {g} vs {w}");
    }
}

#[test]
fn a_point_on_a_corner_returns_that_corners_row() {
    let config = dense_level();
    let aabb = Aabb::new([0.0; 3], [1.0; 3]).unwrap();
    let corners = [[0, 0, 0], [1, 2, 3], [4, 4, 4], [4, 0, 2]];
    let points: Vec<[f32; 3]> = corners.iter().map(|c: &[usize; 3]| c.map(|v| v as f32 / 4.0)).collect();
    let lookup = HashGridLookup::new(&config, &aabb, &points).unwrap();
    let table = random_values(config.table_rows() * 2, 2);
    let flex = Device::flex();
    let got = values(
        encode(&lookup.to_device(&flex, DType::F64).unwrap(), table_f64(&table, &config, &flex)).unwrap(),
    );
    for (i, c) in corners.iter().enumerate() {
        let row = c[0] + 5 * c[1] + 25 * c[2];
        assert_eq!(got[i * 2..i * 2 + 2], table[row * 2..row * 2 + 2], "corner {c:?}");
    }
}

/// instant-ngp's hash written out in u64 arithmetic with an explicit reduction mod 2³².
fn hash_u64(c: [u64; 3]) -> u64 {
    let m = 1u64 << 32;
    (c[0] % m) ^ ((c[1] * 2_654_435_761) % m) ^ ((c[2] * 805_459_861) % m)
}

#[test]
fn the_spatial_hash_follows_instant_ngp() {
    // Worked by hand: single primes, and 2·2654435761 = 5308871522 = 2³² + 1013904226.
    assert_eq!(spatial_hash([1, 0, 0]), 1);
    assert_eq!(spatial_hash([0, 1, 0]), 2_654_435_761);
    assert_eq!(spatial_hash([0, 0, 1]), 805_459_861);
    assert_eq!(spatial_hash([0, 2, 0]), 1_013_904_226);
    for c in [[3u32, 7, 11], [1751, 1750, 2], [123_456, 654_321, 999_999], [u32::MAX, 5, 17]] {
        assert_eq!(spatial_hash(c) as u64, hash_u64(c.map(|v| v as u64)), "corner {c:?}");
    }
}

#[test]
fn coarse_levels_are_dense_and_fine_levels_hashed() {
    let config = HashGridConfig::default();
    let resolutions: Vec<u32> = (0..16).map(|l| config.level(l).resolution).collect();
    // ⌊4 · 1.5^l⌋, worked out by hand.
    let want = [4, 6, 9, 13, 20, 30, 45, 68, 102, 153, 230, 345, 518, 778, 1167, 1751];
    assert_eq!(resolutions, want);
    // (N + 1)³ ≤ 2^17 = 131072 holds up to N = 49.
    let dense: Vec<bool> = (0..16).map(|l| config.level(l).dense).collect();
    assert_eq!(dense, [[true; 7].as_slice(), &[false; 9]].concat());
}

#[test]
fn lookup_rows_follow_the_dense_layout_and_the_hash() {
    let config = HashGridConfig::default();
    let aabb = Aabb::new([-0.5, -1.0, 0.0], [0.5, 1.0, 0.25]).unwrap();
    let points = random_points(50, &aabb, 3);
    let lookup = HashGridLookup::new(&config, &aabb, &points).unwrap();
    let t = 1u64 << 17;
    for (i, p) in points.iter().enumerate() {
        for (l, &n) in
            [4u64, 6, 9, 13, 20, 30, 45, 68, 102, 153, 230, 345, 518, 778, 1167, 1751].iter().enumerate()
        {
            let cell: [u64; 3] = std::array::from_fn(|k| {
                let u = (p[k] as f64 - aabb.min[k] as f64) / (aabb.max[k] as f64 - aabb.min[k] as f64);
                ((u * n as f64).floor() as u64).min(n - 1)
            });
            for corner in 0..8usize {
                let c: [u64; 3] = std::array::from_fn(|k| cell[k] + (corner as u64 >> k & 1));
                let index = if (n + 1).pow(3) <= t {
                    c[0] + (n + 1) * c[1] + (n + 1) * (n + 1) * c[2]
                } else {
                    hash_u64(c) % t
                };
                let got = lookup.rows()[(l * points.len() + i) * 8 + corner] as u64;
                assert_eq!(got, l as u64 * t + index, "point {i} level {l} corner {corner}");
            }
        }
    }
}

/// Three levels in a 64-row table: level 0 (3³ corners) is dense, levels 1 and 2 are hashed
/// with many collisions, so rows gather entries from many points and levels.
fn small_hashed() -> HashGridConfig {
    HashGridConfig { levels: 3, log2_table_size: 6, base_resolution: 2, growth: 2.0, features_per_level: 2 }
}

#[test]
fn a_hashed_corner_returns_its_hashed_row() {
    let config = small_hashed();
    let aabb = Aabb::new([0.0; 3], [1.0; 3]).unwrap();
    // (0.5, 1, 0) is a corner at every level: (1,2,0), (2,4,0), (4,8,0).
    let lookup = HashGridLookup::new(&config, &aabb, &[[0.5, 1.0, 0.0]]).unwrap();
    let table: Vec<f64> = (0..config.table_rows()).flat_map(|r| [r as f64, -(r as f64)]).collect();
    let flex = Device::flex();
    let got = values(
        encode(&lookup.to_device(&flex, DType::F64).unwrap(), table_f64(&table, &config, &flex)).unwrap(),
    );
    let rows = [1 + 3 * 2, 64 + hash_u64([2, 4, 0]) % 64, 128 + hash_u64([4, 8, 0]) % 64];
    for (l, &row) in rows.iter().enumerate() {
        assert_eq!(got[l * 2..l * 2 + 2], [row as f64, -(row as f64)], "level {l}");
    }
}

/// `Σ encode(table) · weights` on plain Flex in f64.
fn loss(lookup: &mannequin_avatar::hash_grid::DeviceLookup, table: Tensor<2>, weights: &Tensor<2>) -> f64 {
    (encode(lookup, table).unwrap() * weights.clone()).sum().into_scalar::<f64>()
}

#[test]
fn the_backward_pass_matches_central_finite_differences() {
    for features_per_level in [1, 2, 8] {
        let config = HashGridConfig { features_per_level, ..small_hashed() };
        let aabb = Aabb::new([-1.0; 3], [1.0; 3]).unwrap();
        let points = random_points(40, &aabb, 4);
        let host = HashGridLookup::new(&config, &aabb, &points).unwrap();
        let table = random_values(config.table_rows() * features_per_level, 5);
        let shape = [points.len(), config.output_dim()];
        let w = random_values(shape[0] * shape[1], 6);
        let device = Device::flex().autodiff();
        let lookup = host.to_device(&device, DType::F64).unwrap();
        let leaf = table_f64(&table, &config, &device).require_grad();
        let weights = Tensor::from_data(TensorData::new(w.clone(), shape), (&device, DType::F64));
        let grads = (encode(&lookup, leaf.clone()).unwrap() * weights).sum().backward();
        let got = values(leaf.grad(&grads).unwrap());

        let flex = Device::flex();
        let lookup = host.to_device(&flex, DType::F64).unwrap();
        let weights = Tensor::from_data(TensorData::new(w, shape), (&flex, DType::F64));
        let h = 1e-3;
        let mut nonzero = 0;
        for (j, g) in got.iter().enumerate() {
            let at = |d: f64| {
                let mut t = table.clone();
                t[j] += d;
                loss(&lookup, table_f64(&t, &config, &flex), &weights)
            };
            let fd = (at(h) - at(-h)) / (2.0 * h);
            assert!(
                (g - fd).abs() < 1e-9,
                "F = {features_per_level}, entry {j}: {g} vs finite difference {fd}"
            );
            nonzero += usize::from(fd != 0.0);
        }
        // The check means something only if most rows are used.
        assert!(nonzero > got.len() / 2, "F = {features_per_level}: only {nonzero} entries have a gradient");
    }
}

/// Forward features and table gradient for a random linear loss on `device`.
fn forward_backward(
    host: &HashGridLookup,
    table: &[f64],
    w: &[f64],
    device: &Device,
) -> (Vec<f64>, Vec<f64>) {
    let config = host.config();
    let device = device.clone().autodiff();
    let lookup = host.to_device(&device, DType::F32).unwrap();
    let leaf = table_f32(table, config, &device).require_grad();
    let features = encode(&lookup, leaf.clone()).unwrap();
    let shape = features.dims();
    let weights = Tensor::from_data(
        TensorData::new(w.iter().map(|&v| v as f32).collect::<Vec<_>>(), shape),
        (&device, DType::F32),
    );
    let grads = (features.clone() * weights).sum().backward();
    (values(features), values(leaf.grad(&grads).unwrap()))
}

fn close(what: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let scale = want.iter().fold(1e-6f64, |m, v| m.max(v.abs()));
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!((g - w).abs() <= tol * scale, "{what}[{i}]: {g} vs {w} (scale {scale})");
    }
}

#[test]
fn flex_and_wgpu_agree_forward_and_backward() {
    let config = HashGridConfig {
        levels: 4,
        log2_table_size: 10,
        base_resolution: 4,
        growth: 2.0,
        features_per_level: 4,
    };
    let aabb = Aabb::new([-0.3, 0.0, -0.2], [0.3, 1.8, 0.2]).unwrap();
    let points = random_points(300, &aabb, 7);
    let host = HashGridLookup::new(&config, &aabb, &points).unwrap();
    let table = random_values(config.table_rows() * 4, 8);
    let w = random_values(points.len() * config.output_dim(), 9);
    let (f_cpu, d_cpu) = forward_backward(&host, &table, &w, &Device::flex());
    let (f_gpu, d_gpu) = forward_backward(&host, &table, &w, &wgpu());
    close("features", &f_gpu, &f_cpu, 1e-5);
    close("table gradient", &d_gpu, &d_cpu, 1e-5);
}

#[test]
fn the_flex_backward_is_bit_identical_across_runs_and_thread_counts() {
    let config = HashGridConfig::default();
    let aabb = Aabb::new([-1.0; 3], [1.0; 3]).unwrap();
    let points = random_points(3000, &aabb, 10);
    let host = HashGridLookup::new(&config, &aabb, &points).unwrap();
    let table = random_values(config.table_rows() * 2, 11);
    let w = random_values(points.len() * config.output_dim(), 12);
    let run = || forward_backward(&host, &table, &w, &Device::flex()).1;
    let bits = |v: Vec<f64>| v.iter().map(|x| (*x as f32).to_bits()).collect::<Vec<_>>();
    let first = bits(run());
    assert_eq!(first, bits(run()), "two runs differ");
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    assert_eq!(first, bits(one_thread.install(run)), "one thread differs from the default pool");
    assert!(first.iter().filter(|&&b| b != 0).count() > 10_000, "the gradient is mostly empty");
}

#[test]
fn the_table_initialisation_is_seeded_and_small() {
    let config = HashGridConfig { log2_table_size: 8, ..Default::default() };
    let flex = Device::flex();
    let a = values(init_table(&config, 42, &flex));
    assert_eq!(a.len(), config.table_rows() * 2);
    assert_eq!(a, values(init_table(&config, 42, &flex)));
    assert_ne!(a, values(init_table(&config, 43, &flex)));
    assert!(a.iter().all(|v| v.abs() <= INIT_SCALE));
    let spread = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(spread > 0.9 * INIT_SCALE, "values fill the range: largest {spread}");
}

#[test]
fn bad_input_is_reported() {
    let config = small_hashed();
    let aabb = Aabb::new([0.0; 3], [1.0; 3]).unwrap();
    let ok = [0.5f32, 0.5, 0.5];
    match HashGridLookup::new(&config, &aabb, &[ok, ok, [0.1, f32::NAN, 0.2]]) {
        Err(HashGridError::NonFinite { index: 2, .. }) => {}
        other => panic!("NaN point: {other:?}"),
    }
    match HashGridLookup::new(&config, &aabb, &[ok, [1.01, 0.5, 0.5]]) {
        Err(e @ HashGridError::Outside { index: 1, .. }) => assert!(e.to_string().contains("point 1")),
        other => panic!("point outside the box: {other:?}"),
    }
    assert!(matches!(HashGridLookup::new(&config, &aabb, &[]), Err(HashGridError::NoPoints)));
    let no_levels = HashGridConfig { levels: 0, ..config };
    assert!(matches!(HashGridLookup::new(&no_levels, &aabb, &[ok]), Err(HashGridError::Config(_))));
    let three_features = HashGridConfig { features_per_level: 3, ..config };
    assert!(matches!(HashGridLookup::new(&three_features, &aabb, &[ok]), Err(HashGridError::Config(_))));
    let shrinking = HashGridConfig { growth: 0.5, ..config };
    assert!(matches!(HashGridLookup::new(&shrinking, &aabb, &[ok]), Err(HashGridError::Config(_))));
    assert!(matches!(Aabb::new([0.0; 3], [1.0, 0.0, 1.0]), Err(HashGridError::Aabb(_))));
    assert!(matches!(Aabb::enclosing(&[ok, ok], 0.1), Err(HashGridError::Aabb(_))));

    let host = HashGridLookup::new(&config, &aabb, &[ok]).unwrap();
    let flex = Device::flex();
    assert!(matches!(host.to_device(&flex, DType::F16), Err(HashGridError::UnsupportedDtype(DType::F16))));
    let lookup = host.to_device(&flex, DType::F32).unwrap();
    let wrong_rows = Tensor::<2>::zeros([config.table_rows() - 1, 2], (&flex, DType::F32));
    match encode(&lookup, wrong_rows) {
        Err(HashGridError::TableShape { expected: [192, 2], found: [191, 2] }) => {}
        other => panic!("wrong table shape: {other:?}"),
    }
    let wrong_features = Tensor::<2>::zeros([config.table_rows(), 3], (&flex, DType::F32));
    assert!(matches!(encode(&lookup, wrong_features), Err(HashGridError::TableShape { .. })));
    let wrong_dtype = Tensor::<2>::zeros([config.table_rows(), 2], (&flex, DType::F64));
    assert!(matches!(encode(&lookup, wrong_dtype), Err(HashGridError::TableDtype { .. })));
}

#[test]
fn an_enclosing_box_holds_its_points_with_a_margin() {
    let points = [[0.0, 1.0, -2.0], [1.0, 3.0, -2.0], [0.5, 2.0, -2.0]];
    let aabb = Aabb::enclosing(&points, 0.1).unwrap();
    // The largest side is 2, so every side grows by 0.2 (the flat z axis too).
    let want = Aabb::new([-0.2, 0.8, -2.2], [1.2, 3.2, -1.8]).unwrap();
    for k in 0..3 {
        assert!((aabb.min[k] - want.min[k]).abs() < 1e-6 && (aabb.max[k] - want.max[k]).abs() < 1e-6);
    }
    assert!(HashGridLookup::new(&HashGridConfig::default(), &aabb, &points).is_ok());
}
