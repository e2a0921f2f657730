//! `evaluate` on small folders whose scores are known without computing them: a perfect
//! prediction, a ground truth at twice the size, exactly the frames asked for, and errors.

use std::path::PathBuf;

use mannequin_data::evaluation::{EvalOptions, evaluate};
use mannequin_data::{Camera, Cameras, DatasetWriter, Frame, Image, Mask, NormalMap};
use mannequin_mesh::TriMesh;

const BG: [f32; 3] = [1.0, 1.0, 1.0];

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mq-eval-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A frame with a square person in the middle on a grey backdrop; `size` pixels square.
fn frame(index: usize, size: usize) -> Frame {
    let inside = |p: usize| {
        let (x, y) = (p % size, p / size);
        (size / 4..3 * size / 4).contains(&x) && (size / 4..3 * size / 4).contains(&y)
    };
    let mask = Mask { width: size, height: size, values: (0..size * size).map(inside).collect() };
    // Colours constant over 2×2 blocks, so a 2× box downscale is exact.
    let colour = |p: usize| {
        let (x, y) = ((p % size) / 2, (p / size) / 2);
        [((x * 7 + y * 3 + index) % 16) as f32 / 15.0, (y % 5) as f32 / 4.0, 0.5]
    };
    let image = Image {
        width: size,
        height: size,
        pixels: (0..size * size).map(|p| if inside(p) { colour(p) } else { [0.4; 3] }).collect(),
    };
    let normals = NormalMap {
        width: size,
        height: size,
        normals: (0..size * size).map(|p| if inside(p) { [0.0, 0.0, -1.0] } else { [0.0; 3] }).collect(),
    };
    Frame { index, image, mask, normals: Some(normals), depth: None }
}

fn tetrahedron(shift: f32) -> TriMesh {
    TriMesh::new(
        vec![[shift, 0.0, 0.0], [1.0 + shift, 0.0, 0.0], [shift, 1.0, 0.0], [shift, 0.0, 1.0]],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

fn write_gt(name: &str, size: usize, frames: usize) -> PathBuf {
    let root = temp_dir(name);
    let w = DatasetWriter::new(&root);
    w.write_cameras(&Cameras::Static(Camera::look_at(
        [0.0, 0.0, 3.0],
        [0.0; 3],
        [0.0, 1.0, 0.0],
        0.8,
        size,
        size,
    )))
    .unwrap();
    for i in 0..frames {
        w.write_frame(&frame(i, size)).unwrap();
        w.write_mesh(i, &tetrahedron(0.0)).unwrap();
    }
    root
}

/// What a perfect renderer would output for frame `i`: the ground truth on the background.
fn perfect_prediction(i: usize, size: usize) -> Frame {
    let mut f = frame(i, size);
    f.image = f.image.composite(&f.mask, BG);
    f
}

fn options() -> EvalOptions {
    EvalOptions { background: BG, lpips: None, samples: 5000, seed: 1, compare_meshes: true }
}

#[test]
fn a_perfect_prediction_scores_perfectly_on_the_frames_asked_for() {
    let gt = write_gt("gt-perfect", 32, 3);
    let pred = temp_dir("pred-perfect");
    let w = DatasetWriter::new(&pred);
    for i in [0, 2, 7] {
        w.write_frame(&perfect_prediction(i, 32)).unwrap();
        w.write_mesh(i, &tetrahedron(0.0)).unwrap();
    }
    let seen = std::sync::Mutex::new(Vec::new());
    // Frame 7 is not asked for (a stale file, say), so it is not scored.
    let s = evaluate(&pred, &gt, &[0, 2], &options(), &|f| seen.lock().unwrap().push(f.frame)).unwrap();
    assert_eq!(seen.into_inner().unwrap(), vec![0, 2]);
    assert_eq!(s.frames, 2);
    assert_eq!(s.gt_downscale, 1);
    assert_eq!(s.psnr, f64::INFINITY);
    assert!((s.ssim - 1.0).abs() < 1e-12);
    assert_eq!(s.normal_mse_x1e3, Some(0.0));
    assert!(s.normal_angle_deg.unwrap() < 1e-3);
    assert!(s.p2s_cm.unwrap() < 1e-6);
    // Below 1 only where a sample's nearest neighbour lies across an edge.
    assert!(s.normal_consistency.unwrap() > 0.95);
    assert!(s.lpips.is_none());
    // JSON writes the infinite PSNR as null, and every key is there.
    let json = serde_json::to_value(&s).unwrap();
    for key in ["psnr", "ssim", "lpips", "chamfer_cm", "p2s_cm", "normal_mse_x1e3", "per_frame"] {
        assert!(json.get(key).is_some(), "{key}");
    }

    // Shift the predicted mesh by 1 cm along x: P2S sees at most 1 cm everywhere.
    for i in [0, 2] {
        w.write_mesh(i, &tetrahedron(0.01)).unwrap();
    }
    let s = evaluate(&pred, &gt, &[0, 2], &options(), &|_| {}).unwrap();
    let p2s = s.p2s_cm.unwrap();
    assert!(p2s > 0.1 && p2s <= 1.0 + 1e-6, "{p2s}");
    for d in [gt, pred] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn ground_truth_at_twice_the_size_is_downscaled() {
    let gt = write_gt("gt-double", 64, 1);
    let pred = temp_dir("pred-half");
    // The ground truth's 2×2 blocks are uniform and the mask edges fall on block borders,
    // so the downscaled ground truth is this 32-pixel frame.
    let mut p = perfect_prediction(0, 64);
    p.index = 0;
    p.image = p.image.downscale(2);
    p.mask = p.mask.downscale(2);
    p.normals = p.normals.map(|n| n.downscale(2));
    DatasetWriter::new(&pred).write_frame(&p).unwrap();
    let s = evaluate(&pred, &gt, &[0], &options(), &|_| {}).unwrap();
    assert_eq!(s.gt_downscale, 2);
    // Equal up to float rounding in the block means (and renormalised normals).
    assert!(s.psnr > 100.0, "{}", s.psnr);
    assert!(s.normal_mse_x1e3.unwrap() < 1e-6);
    for d in [gt, pred] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn sizes_that_do_not_divide_name_the_files() {
    let gt = write_gt("gt-odd", 32, 1);
    let pred = temp_dir("pred-odd");
    DatasetWriter::new(&pred).write_frame(&perfect_prediction(0, 24)).unwrap();
    let msg = evaluate(&pred, &gt, &[0], &options(), &|_| {}).err().unwrap().to_string();
    assert!(msg.contains("image_0000.png") && msg.contains("24×24") && msg.contains("32×32"), "{msg}");
    let empty = temp_dir("pred-none");
    std::fs::create_dir_all(empty.join("images")).unwrap();
    // A prediction missing for a frame asked for is an error naming its file, not a skip.
    let msg = evaluate(&empty, &gt, &[0], &options(), &|_| {}).err().unwrap().to_string();
    assert!(msg.contains("pred-none") && msg.contains("image_0000.png"), "{msg}");
    let msg = evaluate(&pred, &gt, &[], &options(), &|_| {}).err().unwrap().to_string();
    assert!(msg.contains("no test frames"), "{msg}");
    for d in [gt, pred, empty] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

/// Garment meshes (`meshes/garment_<name>_%04d.ply`) are scored per garment where both folders
/// have them: a garment only the prediction has is not scored, and the summary is the mean of
/// the frames'.
#[test]
fn each_garment_is_scored_against_its_own_ground_truth() {
    let gt = write_gt("gt-garments", 32, 3);
    let pred = temp_dir("pred-garments");
    let (wg, wp) = (DatasetWriter::new(&gt), DatasetWriter::new(&pred));
    for (i, shift) in [(0, 0.02), (2, 0.0)] {
        wg.write_garment_mesh(i, "skirt", &tetrahedron(0.0)).unwrap();
        wp.write_frame(&perfect_prediction(i, 32)).unwrap();
        wp.write_garment_mesh(i, "skirt", &tetrahedron(shift)).unwrap();
        wp.write_garment_mesh(i, "cape", &tetrahedron(0.0)).unwrap();
    }
    let s = evaluate(&pred, &gt, &[0, 2], &options(), &|_| {}).unwrap();
    let p2s: Vec<f64> = s.per_frame.iter().map(|f| f.garments["skirt"].p2s_cm).collect();
    // Shifted by 2 cm, no point is farther than 2 cm; unshifted, every point is on it.
    assert!(p2s[0] > 0.2 && p2s[0] <= 2.0 + 1e-6, "{p2s:?}");
    assert!(p2s[1] < 1e-6, "{p2s:?}");
    assert!((s.garments["skirt"].p2s_cm - (p2s[0] + p2s[1]) / 2.0).abs() < 1e-12);
    assert_eq!(s.garments.keys().collect::<Vec<_>>(), ["skirt"]);
    assert!(s.per_frame.iter().all(|f| !f.garments.contains_key("cape")));
    for d in [gt, pred] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

/// Geometry scores are numbers or an error, never null: no samples and a mesh without a surface
/// are refused, naming what is wrong.
#[test]
fn geometry_without_samples_or_surface_is_refused() {
    let gt = write_gt("gt-surface", 32, 1);
    let pred = temp_dir("pred-surface");
    let w = DatasetWriter::new(&pred);
    w.write_frame(&perfect_prediction(0, 32)).unwrap();
    w.write_mesh(0, &tetrahedron(0.0)).unwrap();
    let none = EvalOptions { samples: 0, ..options() };
    let msg = evaluate(&pred, &gt, &[0], &none, &|_| {}).err().unwrap().to_string();
    assert!(msg.contains("surface samples per mesh: expected 1 to 1000000, found 0"), "{msg}");

    let mut flat = tetrahedron(0.0);
    flat.faces.clear();
    w.write_mesh(0, &flat).unwrap();
    let msg = evaluate(&pred, &gt, &[0], &options(), &|_| {}).err().unwrap().to_string();
    assert!(msg.contains("mesh_0000.ply: faces: expected a surface to score"), "{msg}");
    flat.faces = vec![[0, 1, 1]];
    w.write_mesh(0, &flat).unwrap();
    let msg = evaluate(&pred, &gt, &[0], &options(), &|_| {}).err().unwrap().to_string();
    assert!(msg.contains("found 1 faces on 4 vertices"), "{msg}");
    for d in [gt, pred] {
        std::fs::remove_dir_all(d).unwrap();
    }
}
