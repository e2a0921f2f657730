//! A clothed avatar (issue 20) as a user makes one: `train --garments auto` reconstructs each
//! garment in the label maps (NGD) and trains the avatar over them as layers of their own;
//! `export` takes the layers apart (`.obj` files, `.glb` nodes) and `eval` scores each garment
//! against its ground-truth mesh.

use std::path::Path;

mod common;
use common::{mannequin, ok, one_line_error, read_json, s, scratch};

#[path = "../../../tools/node_checks.rs"]
mod node_checks;
use node_checks::KHRONOS_VALIDATOR;

/// The JSON chunk of a `.glb` (its first chunk, after the 12-byte header and 8-byte chunk header).
fn glb_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + length]).unwrap()
}

fn train(data: &Path, model: &Path, garments: &str, iters: &str) -> std::process::Output {
    mannequin(&[
        "train",
        "--data",
        s(data),
        "--out",
        s(model),
        "--garments",
        garments,
        "--iters",
        iters,
        "--checkpoint-every",
        "2",
        "--garment-iters",
        "40",
    ])
}

#[test]
fn a_clothed_avatar_trains_exports_and_scores_its_garment_layers() {
    let dir = scratch("clothed");
    let (data, model) = (dir.join("data"), dir.join("model"));
    // Seed 0 wears pants under a T-shirt.
    ok(mannequin(&[
        "synth",
        "--no-self-collision",
        "--seed",
        "0",
        "--size",
        "96",
        "--frames",
        "10",
        "--train",
        "8",
        "--out",
        s(&data),
    ]));
    ok(train(&data, &model, "auto", "2"));
    let fitted =
        |c: &str| mannequin_mesh::read_obj(model.join("garments").join(c).join("garment.obj")).unwrap();
    let (pants, tshirt) = (fitted("pants"), fitted("tshirt"));

    // Resuming reads the garments kept in the model folder instead of fitting them again; other
    // garments are another run.
    let resumed = ok(train(&data, &model, "auto", "2"));
    let log = String::from_utf8_lossy(&resumed.stderr);
    assert!(log.contains("resuming") && log.contains("reusing it") && !log.contains("fitted the"), "{log}");
    one_line_error(&train(&data, &model, "upper:tshirt", "2"), &["checkpoint.npz", "garments", "--restart"]);

    // The `.obj` export: the whole clothed mesh, and each garment beside it, with the fitted
    // garment's topology.
    let obj = dir.join("avatar.obj");
    ok(mannequin(&["export", "--avatar", s(&model), "-o", s(&obj)]));
    let whole = mannequin_mesh::read_obj(&obj).unwrap();
    for (name, garment) in [("pants", &pants), ("tshirt", &tshirt)] {
        let layer = mannequin_mesh::read_obj(dir.join(format!("avatar.{name}.obj"))).unwrap();
        assert_eq!(layer.faces, garment.faces, "{name}");
        // The layer is the fitted garment moved by the avatar's offsets (two iterations' worth).
        let moved = layer
            .positions
            .iter()
            .zip(&garment.positions)
            .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>().sqrt());
        let most = moved.fold(0.0f32, f32::max);
        assert!(most < 0.01, "{name}: a vertex moved {most} m from the fit");
    }
    // The rest is the body, as `body info` counts its faces.
    let info: serde_json::Value =
        serde_json::from_slice(&ok(mannequin(&["body", "info", "--json"])).stdout).unwrap();
    let body_faces = info["faces"].as_u64().unwrap() as usize;
    assert_eq!(whole.face_count(), body_faces + pants.face_count() + tshirt.face_count());

    // The `.glb`: body and garments as skinned nodes of their own, valid.
    let glb = dir.join("avatar.glb");
    ok(mannequin(&["export", "--avatar", s(&model), "-o", s(&glb)]));
    let doc = glb_json(&glb);
    let skinned: Vec<&str> = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n.get("skin").is_some())
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    assert_eq!(skinned, ["body", "pants", "tshirt"]);
    if let Some(report) = KHRONOS_VALIDATOR.run(&glb) {
        assert!(report.contains(" 0 errors, 0 warnings"), "{report}");
    }

    // `eval` scores each garment layer against the dataset's ground-truth garment meshes.
    let scores_path = dir.join("scores.json");
    ok(mannequin(&[
        "eval",
        "--avatar",
        s(&model),
        "--data",
        s(&data),
        "--samples",
        "4000",
        "--json",
        s(&scores_path),
    ]));
    let scores = read_json(&scores_path);
    for name in ["pants", "tshirt"] {
        let chamfer = scores["geometry"]["garments"][name]["chamfer_cm"].as_f64().unwrap();
        let nc = scores["geometry"]["garments"][name]["normal_consistency"].as_f64().unwrap();
        println!("{name}: Chamfer {chamfer:.2} cm, normal consistency {nc:.3}");
        // `eval` scores the layer the fit made, against the same truth: the fit's own score of its
        // garment on the test frames agrees (the avatar's two iterations barely move it).
        let fit = read_json(&model.join("garments").join(name).join("fit.json"));
        let after = fit["geometry"]["after"]["test"]["chamfer_cm"].as_f64().unwrap();
        assert!((chamfer - after).abs() < 0.25, "{name}: eval's Chamfer {chamfer} cm, the fit's {after} cm");
        // At this size (fitted at 48 px, a pixel spans about 4 cm) the template already lies within
        // 1–1.4 cm of the simulated garment, finer than the images resolve, so the fit is held to
        // half a pixel here; `dress_cli`'s fit at 128 px holds it to beating its template.
        assert!(chamfer < 2.0, "{name}: Chamfer {chamfer} cm");
        assert!(nc > 0.5, "{name}: normal consistency {nc}");
    }
    assert!(model.join("eval/novel_view/meshes/garment_tshirt_0000.ply").exists());

    // Bad input: a garment on the wrong body part, one the label maps do not show, and a dataset
    // without label maps are refused before anything trains.
    let other = dir.join("other");
    one_line_error(&train(&data, &other, "lower:tshirt", "2"), &["tshirt is not worn on the lower body"]);
    one_line_error(&train(&data, &other, "dress", "2"), &["subject.json", "no 'dress'"]);
    std::fs::remove_dir_all(data.join("labels")).unwrap();
    one_line_error(&train(&data, &other, "auto", "2"), &["label maps", "train without --garments"]);
    assert!(!other.exists(), "a refused run writes nothing");
    std::fs::remove_dir_all(dir).ok();
}
