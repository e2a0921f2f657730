//! Chamfer (point-to-surface both ways), P2S and normal consistency against trimesh + libigl +
//! SciPy on the same samples
//! (fixture by tools/oracles/data_geometry.py). Also reads trimesh's binary PLY output.

use glam::DVec3;
use mannequin_data::metrics::geometry::{geometry_metrics, metrics_from_samples};
use mannequin_data::metrics::surface_distance::TriangleBvh;
use mannequin_data::metrics::surface_sampling::samples_on_faces;
use mannequin_io::Npz;
use mannequin_mesh::ply;

const FIX: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/");

fn points(npz: &Npz, key: &str) -> Vec<DVec3> {
    npz.require(key)
        .unwrap()
        .to_f64()
        .unwrap()
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect()
}

fn faces(npz: &Npz, key: &str) -> Vec<u32> {
    npz.require(key).unwrap().to_i64().unwrap().into_iter().map(|f| f as u32).collect()
}

#[test]
fn metrics_match_trimesh_and_libigl_on_the_same_samples() {
    let npz = Npz::read(format!("{FIX}geometry.npz")).unwrap();
    let gt = ply::read(format!("{FIX}geometry_gt.ply")).unwrap().mesh;
    let pred = ply::read(format!("{FIX}geometry_pred.ply")).unwrap().mesh;
    assert_eq!((gt.vertex_count(), gt.face_count()), (642, 1280));
    let sp = samples_on_faces(
        &pred.positions,
        &pred.faces,
        points(&npz, "pred_points"),
        faces(&npz, "pred_faces"),
    );
    let sg = samples_on_faces(&gt.positions, &gt.faces, points(&npz, "gt_points"), faces(&npz, "gt_faces"));
    // Point by point, the surface distance equals libigl's.
    let bvh = TriangleBvh::new(&gt.positions, &gt.faces);
    let want_d = npz.require("p2s_point_m").unwrap().to_f64().unwrap();
    for (p, want) in sp.points.iter().zip(&want_d) {
        let d = bvh.closest(*p).unwrap().distance_squared.sqrt();
        assert!((d - want).abs() < 1e-9, "{p}: {d} vs {want}");
    }
    let m = metrics_from_samples(&sp, &sg, &pred, &gt);
    let scalar = |k: &str| npz.require(k).unwrap().to_f64().unwrap()[0];
    assert!((m.chamfer_cm - scalar("chamfer_cm")).abs() < 1e-9, "{m:?}");
    assert!((m.p2s_cm - scalar("p2s_cm")).abs() < 1e-9, "{m:?}");
    assert!((m.normal_consistency - scalar("normal_consistency")).abs() < 1e-9, "{m:?}");
}

#[test]
fn own_samples_agree_with_the_oracle_within_sampling_noise() {
    let npz = Npz::read(format!("{FIX}geometry.npz")).unwrap();
    let gt = ply::read(format!("{FIX}geometry_gt.ply")).unwrap().mesh;
    let pred = ply::read(format!("{FIX}geometry_pred.ply")).unwrap().mesh;
    let m = geometry_metrics(&pred, &gt, 20_000, 3);
    let scalar = |k: &str| npz.require(k).unwrap().to_f64().unwrap()[0];
    // 20k samples instead of 2k: point-to-surface means do not depend on the sample density.
    assert!((m.p2s_cm - scalar("p2s_cm")).abs() < 0.05 * scalar("p2s_cm"), "{m:?}");
    assert!((m.chamfer_cm - scalar("chamfer_cm")).abs() < 0.05 * scalar("chamfer_cm"), "{m:?}");
    assert!((m.normal_consistency - scalar("normal_consistency")).abs() < 0.01, "{m:?}");
    let same = geometry_metrics(&gt, &gt, 5000, 3);
    assert!(same.chamfer_cm < 1e-6 && same.p2s_cm < 1e-6 && same.normal_consistency > 0.99, "{same:?}");
}
