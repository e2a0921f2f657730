//! A `.ply` written the way the INRIA 3DGS code writes it (`tools/oracles/splat_ply.py`) reads
//! back as the Gaussians it holds, and what we write reads back the same.

use mannequin_io::Npz;
use mannequin_splat::SplatScene;

fn fixture(name: &str) -> String {
    format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn close(what: &str, got: &[f32], want: &[f64], rel: f64) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!((*g as f64 - w).abs() <= rel * (1.0 + w.abs()), "{what}[{i}]: {g} vs {w}");
    }
}

#[test]
fn inria_files_read_as_their_gaussians() {
    let s = SplatScene::read_ply(fixture("splat_inria.ply")).unwrap();
    let npz = Npz::read(fixture("splat_inria.npz")).unwrap();
    let get = |k: &str| npz.require(k).unwrap().to_f64().unwrap();
    assert_eq!(s.sh_degree, get("sh_degree")[0] as usize);
    assert_eq!(s.len(), 20);
    close("means", &s.means, &get("means"), 0.0);
    close("quaternions", &s.quaternions, &get("quaternions"), 0.0);
    close("SH", &s.sh, &get("sh"), 0.0);
    close("scales", &s.scales, &get("scales"), 1e-6);
    close("opacities", &s.opacities, &get("opacities"), 1e-6);
}

#[test]
fn what_we_write_reads_back_byte_for_byte_in_the_inria_layout() {
    let s = SplatScene::read_ply(fixture("splat_inria.ply")).unwrap();
    let dir = std::env::temp_dir().join(format!("mq-splat-plyrt-{}", std::process::id()));
    let path = dir.join("again.ply");
    s.write_ply(&path).unwrap();
    let ours = std::fs::read(&path).unwrap();
    let theirs = std::fs::read(fixture("splat_inria.ply")).unwrap();
    std::fs::remove_dir_all(dir).unwrap();
    // Same header, and the same records up to the last bit of the log/logit round trips.
    let header_end = |b: &[u8]| b.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    assert_eq!(ours[..header_end(&ours)], theirs[..header_end(&theirs)]);
    let floats = |b: &[u8]| -> Vec<f32> {
        b[header_end(b)..].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect()
    };
    let (a, b) = (floats(&ours), floats(&theirs));
    assert_eq!(a.len(), b.len());
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!((x - y).abs() <= 1e-5 * (1.0 + y.abs()), "value {i}: {x} vs {y}");
    }
}
