//! `mannequin garment make` and `mannequin dress` as a user runs them: templates made and read
//! back, then pants under a T-shirt on five body shapes (±2 on the first two betas) through a
//! short walk, neither inside the body nor crossing the other or itself, checked by what the run measured
//! and by readers of the outputs' own formats.
//!
//! The issue also asks for strain within the material's limit; that is not met yet (the mean
//! edge strain of denim pants is about 3.3 % against 3 %, and the worst 1 % of edges stretch
//! 25–70 %), so it is reported in metrics.json and not asserted here.

use std::path::Path;

mod common;
use common::{mannequin, ok, one_line_error, read_json, s, scratch, usage_error};
use mannequin_mesh::PointCache;

#[path = "../../../tools/node_checks.rs"]
mod node_checks;
use node_checks::KHRONOS_VALIDATOR;

#[test]
fn a_made_template_reads_back() {
    let dir = scratch("garment_make");
    let file = dir.join("tshirt.garment");
    let out = ok(mannequin(&[
        "garment",
        "make",
        "--category",
        "tshirt",
        "--size",
        "L",
        "--sleeve",
        "0.5",
        "--out",
        s(&file),
        "--obj",
        s(&dir.join("tshirt.obj")),
    ]));
    let made: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(made["boundary_loops"], 4, "{made}");
    let info: serde_json::Value =
        serde_json::from_slice(&ok(mannequin(&["garment", "info", s(&file), "--json"])).stdout).unwrap();
    assert_eq!(info["vertices"], made["vertices"]);
    assert_eq!(info["fit"]["sleeve"], 0.5);
    let obj = mannequin_mesh::read_obj(dir.join("tshirt.obj")).unwrap();
    assert_eq!(obj.vertex_count() as u64, made["vertices"].as_u64().unwrap());

    // A template made on one body model is refused on another, naming the fix.
    let walk = dir.join("walk.npz");
    ok(mannequin(&["motion", "walk", "-o", s(&walk), "--seconds", "0.2"]));
    let lod1 = dir.join("lod1.garment");
    ok(mannequin(&["garment", "make", "--category", "pants", "--body", "default-lod1", "--out", s(&lod1)]));
    let o = mannequin(&["dress", "--garments", s(&lod1), "--motion", s(&walk), "--out", s(&dir.join("x"))]);
    one_line_error(&o, &["lod1.garment", "make it again on this body"]);
    // And the reverse (issue 42: it panicked, layering the template on faces the body lacks).
    let args = ["dress", "--body", "default-lod1", "--garments", s(&file), "--motion", s(&walk)];
    let o = mannequin(&[&args[..], &["--out", s(&dir.join("x"))]].concat());
    one_line_error(&o, &["tshirt.garment", "body: the garment was made on 'default' (", "make it again"]);
    // Pants over a T-shirt (tucked in) are refused with the cloth–cloth contacts on, naming the
    // ways out: the pants blew up.
    let pants = dir.join("pants.garment");
    ok(mannequin(&["garment", "make", "--category", "pants", "--out", s(&pants)]));
    let tucked = format!("{},{}", s(&file), s(&pants));
    let o = mannequin(&["dress", "--garments", &tucked, "--motion", s(&walk), "--out", s(&dir.join("x"))]);
    one_line_error(&o, &["--garments: pants over tshirt", "list tshirt after pants", "--no-self-collision"]);
    // Issue 42: `--settle inf` grew to 24 GB.
    let o =
        mannequin(&["dress", "--garments", s(&file), "--motion", s(&walk), "--settle", "inf", "--out", "x"]);
    usage_error(&o, &["--settle", "expected 0 to 10 seconds"]);
    assert!(!dir.join("x").exists(), "a refused dress writes nothing");
    let o = mannequin(&["dress", "--garments", "tunic", "--motion", s(&walk), "--out", s(&dir.join("x"))]);
    one_line_error(&o, &["tunic", "pants, short-pants, shirt, tshirt, long-coat, skirt, dress"]);
}

#[test]
fn pants_and_a_tshirt_walk_on_five_body_shapes() {
    let dir = scratch("dress_shapes");
    let walk = dir.join("walk.npz");
    ok(mannequin(&["motion", "walk", "-o", s(&walk), "--seconds", "1"]));
    let cache = dir.join("cache");
    for (i, betas) in ["0,0", "2,0", "-2,0", "0,2", "0,-2"].iter().enumerate() {
        let out = dir.join(format!("shape_{i}"));
        let frames = if i == 0 { &[][..] } else { &["--no-frames"][..] };
        let args = ["--garments", "pants,tshirt", "--betas", betas, "--motion", s(&walk), "--out", s(&out)];
        ok(dress(&[&args[..], frames].concat(), &cache));
        let metrics = read_json(&out.join("metrics.json"));
        assert_eq!(metrics["frames"], 30);
        for g in metrics["garments"].as_array().unwrap() {
            let name = g["name"].as_str().unwrap();
            // The T-shirt's contacts hold it off the pants (without them it crosses in 30–86 pairs).
            assert_holds(g, &format!("betas {betas}"));
            let cache = PointCache::read(&out.join(format!("{name}.pc2"))).unwrap();
            assert_eq!(cache.frames.len(), 30);
            assert_eq!(cache.frames[0].len() as u64, g["vertices"].as_u64().unwrap());
        }
        if i == 0 {
            // Skinning alone (Eqs. 3.2-3.3) leaves cloth inside the body, which the simulator resolved.
            let skinned = dir.join("skinned");
            let args = ["--garments", "pants,tshirt", "--motion", s(&walk), "--no-simulation", "--no-frames"];
            ok(dress(&[&args[..], &["--out", s(&skinned)]].concat(), &cache));
            let inside: u64 = read_json(&skinned.join("metrics.json"))["garments"]
                .as_array()
                .unwrap()
                .iter()
                .map(|g| g["max_vertices_inside_body"].as_u64().unwrap())
                .sum();
            assert!(inside > 0, "skinning alone left no cloth inside the body");
            assert!(out.join("frames/frame_0029.png").exists());
            // Fails the test on any validator error.
            KHRONOS_VALIDATOR.run(&out.join("dressed.glb"));
        }
    }
}

/// A T-shirt over a skirt on the jog: the hands, swinging in front of the hips, press the
/// T-shirt's hem against the skirt's waist. Stopped outright where it met the skirt, the hem was
/// run through by it from the first motion frame (48 pairs crossing, 33 vertices inside the
/// body) and the arms then dragged the T-shirt off over a shoulder; carried with the skirt, it
/// holds.
#[test]
fn a_tshirt_over_a_skirt_holds_on_the_jog() {
    let dir = scratch("dress_jog");
    let jog = dir.join("jog.npz");
    ok(mannequin(&["motion", "jog", "-o", s(&jog), "--seconds", "0.5"]));
    let out = dir.join("out");
    let args = ["--garments", "skirt,tshirt", "--motion", s(&jog), "--no-frames", "--out", s(&out)];
    ok(dress(&args, &dir.join("cache")));
    let metrics = read_json(&out.join("metrics.json"));
    assert_eq!(metrics["frames"], 15);
    for g in metrics["garments"].as_array().unwrap() {
        assert_holds(g, "the jog");
    }
}

/// Issue 38: T-shirts of size L and XL slid off the shoulders within a second of walking. An XL
/// T-shirt on the jog holds, and its top tenth (the shoulders and neckline) ends within 8 cm on
/// average of where skinning alone (Eq. 3.3) carries it: it sags 5–7 cm onto the shoulders, where
/// a coat sliding off a shirt ends 17 cm or more away.
#[test]
fn an_xl_tshirt_stays_on_the_shoulders_on_the_jog() {
    let dir = scratch("dress_xl");
    let jog = dir.join("jog.npz");
    ok(mannequin(&["motion", "jog", "-o", s(&jog), "--seconds", "1"]));
    let cache = dir.join("cache");
    let worn = |out: &Path, more: &[&str]| {
        let args =
            ["--garments", "tshirt", "--size", "XL", "--motion", s(&jog), "--no-frames", "--out", s(out)];
        ok(dress(&[&args[..], more].concat(), &cache));
        PointCache::read(&out.join("tshirt.pc2")).unwrap().frames
    };
    let simulated = worn(&dir.join("simulated"), &[]);
    let skinned = worn(&dir.join("skinned"), &["--no-simulation"]);
    let metrics = read_json(&dir.join("simulated/metrics.json"));
    assert_holds(&metrics["garments"][0], "XL on the jog");
    let mut heights: Vec<f32> = skinned[0].iter().map(|p| p[1]).collect();
    heights.sort_by(f32::total_cmp);
    let top = heights[heights.len() * 9 / 10];
    let (last, on_body) = (simulated.last().unwrap(), skinned.last().unwrap());
    let away: Vec<f32> = (0..on_body.len())
        .filter(|&v| skinned[0][v][1] >= top)
        .map(|v| (0..3).map(|i| (last[v][i] - on_body[v][i]).powi(2)).sum::<f32>().sqrt())
        .collect();
    let mean = away.iter().sum::<f32>() / away.len() as f32;
    assert!(mean < 0.08, "the XL T-shirt's top tenth ends {mean} m from its skinned place");
}

/// `mannequin dress ARGS` run to its end, with its garment cache in `cache`.
fn dress(args: &[&str], cache: &Path) -> std::process::Output {
    dress_command(args, cache).output().unwrap()
}

/// `mannequin dress ARGS` with its garment cache in `cache`, apart from the user's.
fn dress_command(args: &[&str], cache: &Path) -> std::process::Command {
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_mannequin"));
    command.arg("dress").args(args).env("XDG_CACHE_HOME", cache);
    command
}

/// A garment of a run's metrics.json (`what` names the run) that held at every frame: no vertex
/// inside the body, no pair crossing the layers under it or itself.
fn assert_holds(g: &serde_json::Value, what: &str) {
    let name = g["name"].as_str().unwrap();
    for key in ["max_vertices_inside_body", "max_crossings_with_inner_layers", "max_self_intersecting_pairs"]
    {
        assert_eq!(g[key], 0, "{what}, {name}: {key}");
    }
}

/// A run killed once a checkpoint holds both layers under way and run again with the same command
/// goes on from it and ends with the same frames, bit for bit, as a run never stopped; a
/// changed option is refused naming it.
#[test]
fn a_killed_dress_resumes_to_the_same_frames() {
    let dir = scratch("dress_resume");
    let walk = dir.join("walk.npz");
    ok(mannequin(&["motion", "walk", "-o", s(&walk), "--seconds", "0.5"]));
    let cache = dir.join("cache");
    let run = |out: &Path, extra: &[&str]| {
        let args = ["--garments", "pants,tshirt", "--motion", s(&walk), "--settle", "0.4", "--no-frames"];
        let args = [&args[..], &["--checkpoint-every", "5", "--out", s(out)], extra].concat();
        dress_command(&args, &cache)
    };
    let whole = dir.join("whole");
    ok(run(&whole, &[]).output().unwrap());

    let resumed = dir.join("resumed");
    let mut child = run(&resumed, &[]).stderr(std::process::Stdio::null()).spawn().unwrap();
    let checkpoint = resumed.join("checkpoint.npz");
    let holds_both_layers = || mannequin_io::Npz::read(&checkpoint).is_ok_and(|npz| npz.contains("frames_1"));
    let start = std::time::Instant::now();
    while !holds_both_layers() && start.elapsed().as_secs() < 300 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(holds_both_layers(), "no checkpoint within 5 minutes");
    assert!(!resumed.join("metrics.json").exists(), "killed before the end");

    let o = run(&resumed, &["--substeps", "10"]).output().unwrap();
    one_line_error(&o, &["checkpoint.npz", "substeps was 20, now 10", "--restart"]);

    let o = ok(run(&resumed, &[]).output().unwrap());
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(log.contains("resuming"), "{log}");
    assert!(!checkpoint.exists(), "a finished run leaves no checkpoint");
    for garment in ["pants", "tshirt"] {
        let read = |d: &Path| std::fs::read(d.join(format!("{garment}.pc2"))).unwrap();
        assert!(
            read(&whole) == read(&resumed),
            "{garment}: resumed frames differ from the uninterrupted run's"
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

/// `garment fit` (NGD's first slice) on a small synthetic subject: the T-shirt's Jacobian field,
/// fitted to the label maps, covers them better than the template it starts from; a category the
/// dataset does not wear and a dataset without a legend are refused in one line.
#[test]
fn garment_fit_brings_the_template_closer_to_the_label_maps() {
    let dir = scratch("garment_fit");
    let data = dir.join("data");
    ok(mannequin(&[
        "synth",
        "--no-self-collision",
        "--seed",
        "0",
        "--size",
        "128",
        "--frames",
        "10",
        "--train",
        "8",
        "--out",
        s(&data),
    ]));
    let out = dir.join("tshirt");
    ok(mannequin(&[
        "garment",
        "fit",
        "--data",
        s(&data),
        "--category",
        "tshirt",
        "--iters",
        "60",
        "--remesh-every",
        "20",
        "--downscale",
        "1",
        "--out",
        s(&out),
    ]));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("fit.json")).unwrap()).unwrap();
    let (before, after) = (
        report["mean_mask_iou"]["before"].as_f64().unwrap(),
        report["mean_mask_iou"]["after"].as_f64().unwrap(),
    );
    println!("mask IoU {before:.3} → {after:.3}");
    assert!(after > before + 0.01, "mask IoU {before} → {after}");
    // Against the synthetic ground-truth garment meshes (simulated cloth, not the template), on
    // the frames it was fitted to.
    let chamfer = |when: &str| report["geometry"][when]["train"]["chamfer_cm"].as_f64().unwrap();
    println!("Chamfer {:.3} → {:.3} cm", chamfer("before"), chamfer("after"));
    assert!(
        chamfer("after") < chamfer("before") - 0.05,
        "Chamfer {} → {}",
        chamfer("before"),
        chamfer("after")
    );
    let mesh = mannequin_mesh::read_obj(out.join("garment.obj")).unwrap();
    assert!(mesh.vertex_count() > 1000, "{} vertices", mesh.vertex_count());
    // Remeshing added faces and kept an oriented manifold with the T-shirt's four openings
    // (neck, hem, two sleeves).
    let (base, fitted) =
        (report["faces"]["base"].as_u64().unwrap(), report["faces"]["fitted"].as_u64().unwrap());
    assert_eq!(fitted as usize, mesh.face_count());
    assert!(fitted > base, "remeshing added no faces: {base} → {fitted}");
    mannequin_mesh::manifold::check_manifold(&mesh.positions, &mesh.faces).unwrap();
    assert_eq!(mannequin_mesh::adjacency::boundary_loops(&mesh.faces).len(), 4);
    // The scene of the training frames: a point cache of the fitted garment per training frame,
    // and the glTF beside it, valid.
    let cache = mannequin_mesh::PointCache::read(&out.join("tshirt.pc2")).unwrap();
    assert_eq!(cache.frames.len(), 8);
    assert!(cache.frames.iter().all(|f| f.len() == mesh.vertex_count()));
    assert!(cache.frames[0] != cache.frames[7], "the garment moves with the body");
    if let Some(report) = KHRONOS_VALIDATOR.run(&out.join("fitted.glb")) {
        assert!(report.contains(" 0 errors, 0 warnings"), "{report}");
    }
    // Pants fitted to the T-shirt's label maps: warned about after the first pass, not silent.
    let mismatch = mannequin(&[
        "garment",
        "fit",
        "--data",
        s(&data),
        "--category",
        "pants",
        "--label",
        "tshirt",
        "--iters",
        "10",
        "--downscale",
        "1",
        "--out",
        s(&dir.join("mismatch")),
    ]);
    let log = String::from_utf8_lossy(&mismatch.stderr);
    assert!(mismatch.status.success(), "{log}");
    assert!(log.contains("WARN") && log.contains("may not mark a garment of category pants"), "{log}");
    one_line_error(
        &mannequin(&[
            "garment",
            "fit",
            "--data",
            s(&data),
            "--category",
            "dress",
            "--out",
            s(&dir.join("dress")),
        ]),
        &["subject.json", "labels", "'dress'"],
    );
    std::fs::remove_file(data.join("subject.json")).unwrap();
    one_line_error(
        &mannequin(&[
            "garment",
            "fit",
            "--data",
            s(&data),
            "--category",
            "tshirt",
            "--out",
            s(&dir.join("none")),
        ]),
        &["subject.json", "no label legend"],
    );
    assert!(!dir.join("dress").exists() && !dir.join("none").exists(), "a refused fit writes nothing");
}
