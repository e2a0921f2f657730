//! LPIPS (AlexNet) against the `lpips` package with the same random weights (fixture by
//! tools/oracles/data_lpips.py; the weights are regenerated here with SplitMix64).

use mannequin_data::Image;
use mannequin_data::metrics::lpips::{Lpips, weight_shapes};
use mannequin_io::rng::SplitMix64;
use mannequin_io::{NpyArray, Npz, NpzWriter};

fn fixture() -> Npz {
    Npz::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/lpips_alex.npz")).unwrap()
}

/// The weights file the oracle script built in memory: parameter k gets seed 1000 + k.
fn weights_file(npz: &Npz) -> std::path::PathBuf {
    let keys = match &npz.require("keys").unwrap().data {
        mannequin_io::NpyData::Str(v) => v.clone(),
        other => panic!("keys: {other:?}"),
    };
    let shapes = npz.require("shapes").unwrap().to_i64().unwrap();
    let ranks = npz.require("ranks").unwrap().to_i64().unwrap();
    let mut w = NpzWriter::new();
    for (k, key) in keys.iter().enumerate() {
        let shape: Vec<usize> =
            shapes[4 * k..4 * k + ranks[k] as usize].iter().map(|&d| d as usize).collect();
        let n: usize = shape.iter().product();
        let mut rng = SplitMix64::new(1000 + k as u64);
        let fan_in: usize = shape[1..].iter().product();
        let values: Vec<f32> = (0..n)
            .map(|_| {
                let u = rng.uniform();
                let v = if key.starts_with("lin") {
                    u
                } else if key.ends_with(".bias") {
                    (2.0 * u - 1.0) * 0.1
                } else {
                    (2.0 * u - 1.0) * (6.0 / fan_in as f64).sqrt()
                };
                v as f32
            })
            .collect();
        w.add(key, NpyArray::f32(shape, values));
    }
    let path = std::env::temp_dir().join(format!("mq-lpips-{}.npz", std::process::id()));
    w.write(&path).unwrap();
    path
}

fn image(npz: &Npz, key: &str) -> Image {
    let a = npz.require(key).unwrap();
    let (h, w) = (a.shape[0], a.shape[1]);
    let v = a.to_f32().unwrap();
    Image {
        width: w,
        height: h,
        pixels: v.chunks_exact(3).map(|c| [c[0] / 255.0, c[1] / 255.0, c[2] / 255.0]).collect(),
    }
}

#[test]
fn expected_keys_are_the_reference_parameters() {
    let npz = fixture();
    let keys = match &npz.require("keys").unwrap().data {
        mannequin_io::NpyData::Str(v) => v.clone(),
        other => panic!("keys: {other:?}"),
    };
    let shapes = npz.require("shapes").unwrap().to_i64().unwrap();
    let ranks = npz.require("ranks").unwrap().to_i64().unwrap();
    let mut reference: Vec<(String, Vec<usize>)> = keys
        .iter()
        .enumerate()
        .map(|(k, key)| {
            (key.clone(), shapes[4 * k..4 * k + ranks[k] as usize].iter().map(|&d| d as usize).collect())
        })
        .collect();
    let mut ours = weight_shapes();
    reference.sort();
    ours.sort();
    assert_eq!(ours, reference);
}

#[test]
fn lpips_matches_the_reference_package() {
    let npz = fixture();
    let path = weights_file(&npz);
    let model = Lpips::load(&path).unwrap();
    std::fs::remove_file(path).unwrap();
    for i in 0..2 {
        let (a, b) = (image(&npz, &format!("a{i}")), image(&npz, &format!("b{i}")));
        let layers = model.per_layer(&a, &b).unwrap();
        let want = npz.require(&format!("layers{i}")).unwrap().to_f64().unwrap();
        for (l, (got, want)) in layers.iter().zip(&want).enumerate() {
            assert!((got - want).abs() < 1e-5 * want.abs().max(1e-3), "pair {i} layer {l}: {got} vs {want}");
        }
        let total = npz.require(&format!("total{i}")).unwrap().to_f64().unwrap()[0];
        let got = model.distance(&a, &b).unwrap();
        assert!((got - total).abs() < 1e-5 * total, "pair {i}: {got} vs {total}");
        assert_eq!(model.distance(&a, &a).unwrap(), 0.0);
    }
}

#[test]
fn missing_weights_name_the_key() {
    let path = std::env::temp_dir().join(format!("mq-lpips-bad-{}.npz", std::process::id()));
    let mut w = NpzWriter::new();
    w.add("net.slice1.0.weight", NpyArray::f32(vec![64, 3, 11, 11], vec![0.0; 64 * 3 * 121]));
    w.write(&path).unwrap();
    let msg = Lpips::load(&path).err().unwrap().to_string();
    std::fs::remove_file(&path).unwrap();
    assert!(msg.contains("net.slice1.0.bias") && msg.contains("mq-lpips-bad"), "{msg}");
}
