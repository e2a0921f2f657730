//! `mannequin cloth simulate` as a user runs it: a skirt tube around the default body's hips, its
//! waist attached, on a short walk. The outputs are read back with readers of their own (PC2 by
//! its header, the .npz by numpy's layout, the .glb by the Khronos validator and three.js), and
//! bad garments are one-line errors before any work.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod common;
use common::{mannequin, ok, one_line_error, s, scratch};
use mannequin_body::BodyModel;
use mannequin_io::{NpyArray, Npz, NpzWriter};
use mannequin_mesh::ring_tube::RingLayout;
use mannequin_mesh::{PointCache, TriMesh, write_obj};

#[path = "../../../tools/node_checks.rs"]
mod node_checks;
use node_checks::{KHRONOS_VALIDATOR, THREE_JS};

/// A 30 cm A-line skirt from the default body's hip line down, on 1.5 cm triangles. Its
/// waistband hugs the body 1 cm out along each ray (attached, it then rides on the body like an
/// elastic band); below, each ring is 2 cm out from the widest body point at or above it (so it
/// never narrows), flaring 25 cm per metre, reached over the first 6 cm.
fn skirt(dir: &Path) -> (PathBuf, usize) {
    let body = BodyModel::default_body().template_mesh();
    let (waist, length) = (-0.12, 0.3);
    let near = |y0: f32, y1: f32| {
        body.positions.iter().filter(move |p| p[1] <= y0 + 0.01 && p[1] >= y1 - 0.01 && p[0].abs() < 0.25)
    };
    let widest_above = |y: f32| {
        near(waist, y).map(|p| (p[0] * p[0] + p[2] * p[2]).sqrt()).fold(0.0f32, f32::max)
            + 0.02
            + 0.25 * (waist - y)
    };
    // The farthest body point along the ray at angle `a` at the waist, within a 4 cm strip.
    let band = |a: f32| {
        let (sin, cos) = a.sin_cos();
        near(waist + 0.01, waist - 0.01)
            .filter(|p| (p[0] * sin - p[2] * cos).abs() < 0.02)
            .map(|p| p[0] * cos + p[2] * sin)
            .fold(0.0f32, f32::max)
            + 0.01
    };
    let radius = widest_above(waist - length);
    let segments = (std::f32::consts::TAU * radius / 0.015).round() as usize;
    let rings = (length / 0.013).round() as usize;
    let layout = RingLayout::uniform(segments, rings);
    let positions = layout
        .ring_of_vertices()
        .enumerate()
        .map(|(v, r)| {
            let a = std::f32::consts::TAU * (v - layout.vertex(r, 0)) as f32 / segments as f32;
            let y = waist - layout.rings[r] * length;
            let t = ((waist - y) / 0.06).min(1.0);
            let r = (1.0 - t) * band(a) + t * widest_above(y).max(band(a));
            [r * a.cos(), y, r * a.sin()]
        })
        .collect();
    let (faces, uv) = layout.tube();
    let mut mesh = TriMesh::new(positions, faces);
    mesh.uv = Some(uv);
    let path = dir.join("skirt.obj");
    write_obj(&path, &mesh).unwrap();
    (path, segments)
}

/// The skirt in `dir`, a pins file attaching its waistband ring, and a walk of `seconds` at 30
/// fps: what each simulation test starts from.
struct SkirtOnAWalk {
    garment: PathBuf,
    pins: PathBuf,
    walk: PathBuf,
    segments: usize,
}

fn skirt_on_a_walk(dir: &Path, seconds: &str) -> SkirtOnAWalk {
    let (garment, segments) = skirt(dir);
    let pins = dir.join("pins.json");
    std::fs::write(&pins, serde_json::json!({ "attached": (0..segments).collect::<Vec<_>>() }).to_string())
        .unwrap();
    let walk = dir.join("walk.npz");
    ok(mannequin(&["motion", "walk", "--seconds", seconds, "--fps", "30", "-o", s(&walk)]));
    SkirtOnAWalk { garment, pins, walk, segments }
}

#[test]
fn a_skirt_walks_with_the_body() {
    let dir = scratch("cloth-skirt");
    let SkirtOnAWalk { garment, pins, walk, segments } = skirt_on_a_walk(&dir, "0.5");
    let out = dir.join("sim");
    let run = |extra: &[&str]| {
        let mut a =
            vec!["cloth", "simulate", "--garment", s(&garment), "--pin", s(&pins), "--motion", s(&walk)];
        a.extend_from_slice(&["--settle", "0.5", "--out", s(&out)]);
        a.extend_from_slice(extra);
        mannequin(&a)
    };
    ok(run(&[]));

    let cache = PointCache::read(&out.join("garment.pc2")).unwrap();
    let motion = mannequin_body::Motion::read(&walk).unwrap();
    assert_eq!(cache.frames.len(), motion.num_frames());
    let obj = mannequin_mesh::read_obj(&garment).unwrap();
    assert_eq!(cache.frames[0].len(), obj.vertex_count());

    let npz = mannequin_io::Npz::read(out.join("garment.npz")).unwrap();
    let (shape, positions) = npz.f64_with_shape("positions", &[None, None, Some(3)]).unwrap();
    assert_eq!(shape, vec![cache.frames.len(), obj.vertex_count(), 3]);
    let last = cache.frames.last().unwrap();
    let offset = (cache.frames.len() - 1) * obj.vertex_count() * 3;
    assert!(last.iter().flatten().zip(&positions[offset..]).all(|(a, &b)| *a == b as f32), "npz = pc2");

    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["frames"], cache.frames.len());
    assert_eq!(metrics["per_frame"].as_array().unwrap().len(), cache.frames.len());
    assert!(metrics["max_self_intersecting_pairs"].as_u64().is_some(), "{metrics}");
    assert_eq!(metrics["max_vertices_inside_body"], 0, "{metrics}");
    // Cotton keeps its length on average; single edges in the folds of the flare move more
    // (0.50 at most here, without self-collision the folds pass through each other).
    assert!(metrics["mean_edge_strain"].as_f64().unwrap() < 0.05, "{metrics}");
    assert!(metrics["max_edge_strain"].as_f64().unwrap() < 1.0, "{metrics}");
    // The p99 stretch is reported beside the limit of the fabric it is held to (an .obj is cotton).
    let cotton = mannequin_cloth::Material::named("cotton").unwrap().strain_limit;
    assert_eq!(metrics["strain_limit"].as_f64().unwrap() as f32, cotton, "{metrics}");
    let p99 = metrics["max_p99_edge_stretch"].as_f64().unwrap();
    assert!(p99 > 0.0 && p99 <= metrics["max_edge_strain"].as_f64().unwrap(), "{metrics}");

    // The attached waist stays on the walking body: within 2 cm of where its rest binding puts it,
    // which moves with the hips (the walk's root moves several cm over the clip).
    let first_waist: Vec<[f32; 3]> = cache.frames[0][..segments].to_vec();
    let moved =
        last[..segments].iter().zip(&first_waist).map(|(a, b)| (a[2] - b[2]).abs()).fold(0.0, f32::max);
    assert!(moved > 0.01, "the waist follows the walk forward ({moved} m)");

    let glb = out.join("scene.glb");
    if let Some(report) = KHRONOS_VALIDATOR.run(&glb) {
        assert!(report.contains(" 0 errors, 0 warnings"), "{report}");
    }
    if let Some(report) = THREE_JS.run(&glb) {
        assert!(report.contains("1 skinned mesh(es), 1 animation(s)"), "{report}");
        // The UV seam's column is written twice: one vertex more per ring.
        let seam = obj.uv.as_ref().unwrap().coords.iter().filter(|t| t[0] == 0.0).count();
        let written = obj.vertex_count() + seam;
        let targets = format!("morph mesh 'garment': {written} vertices, {} targets", cache.frames.len());
        assert!(report.contains(&targets), "{report}");
    }
    std::fs::remove_dir_all(dir).ok();
}

/// Self-collision (on by default) keeps the skirt's folds apart: no self-intersecting triangle
/// pairs at any frame, where the same run with `--no-self-collision` has some.
#[test]
fn self_collision_keeps_the_folds_apart() {
    let dir = scratch("cloth-skirt-self");
    let SkirtOnAWalk { garment, pins, walk, .. } = skirt_on_a_walk(&dir, "0.3");
    let pairs = |extra: &[&str]| {
        let out = dir.join("sim");
        let (g, p, w, o) = (s(&garment), s(&pins), s(&walk), s(&out));
        let mut a = vec!["cloth", "simulate", "--garment", g, "--pin", p, "--motion", w, "--settle", "0.5"];
        a.extend_from_slice(&["--restart", "--out", o]);
        a.extend_from_slice(extra);
        ok(mannequin(&a));
        let metrics: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
        assert_eq!(metrics["max_vertices_inside_body"], 0, "{metrics}");
        metrics["max_self_intersecting_pairs"].as_u64().unwrap()
    };
    let (with, without) = (pairs(&[]), pairs(&["--no-self-collision"]));
    assert!(with == 0 && without > 0, "{with} pairs with self-collision, {without} without");
    std::fs::remove_dir_all(dir).ok();
}

/// The height of the simulated garment's highest vertex in `out`'s first and last frames.
fn top_heights(out: &Path) -> (f64, f64) {
    let npz = Npz::read(out.join("garment.npz")).unwrap();
    let (shape, positions) = npz.f64_with_shape("positions", &[None, None, Some(3)]).unwrap();
    let top =
        |k: usize| (0..shape[1]).map(|v| positions[(k * shape[1] + v) * 3 + 1]).fold(f64::MIN, f64::max);
    (top(0), top(shape[0] - 1))
}

/// A library garment (`garment make`'s .garment) is simulated as `dress` wears it: put on the
/// body, its waistband attached, in its own fabric, so a skirt stays on the hips through the walk
/// with nothing inside the body. `--pin` is for a bare .obj.
#[test]
fn a_library_garment_is_worn_as_dress_wears_it() {
    let dir = scratch("cloth-library");
    let (garment, walk, out) = (dir.join("skirt.garment"), dir.join("walk.npz"), dir.join("sim"));
    ok(mannequin(&["garment", "make", "--category", "skirt", "--out", s(&garment)]));
    ok(mannequin(&["motion", "walk", "--seconds", "0.5", "-o", s(&walk)]));
    let a = ["cloth", "simulate", "--garment", s(&garment), "--motion", s(&walk), "--settle", "0.5"];
    ok(mannequin(&a.iter().chain(&["--out", s(&out)]).copied().collect::<Vec<_>>()));
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["max_vertices_inside_body"], 0, "{metrics}");
    // Held at the waist, the skirt's top stays at the hips: its highest vertex drops < 3 cm.
    let (first, last) = top_heights(&out);
    assert!(first - last < 0.03, "the skirt's top fell from {first} m to {last} m");
    let pins = dir.join("pins.json");
    std::fs::write(&pins, r#"{"attached": [0]}"#).unwrap();
    let pinned = [&a[..], &["--pin", s(&pins), "--out", s(&out)]].concat();
    one_line_error(&mannequin(&pinned), &["--pin", "skirt.garment", "carries its own attachments"]);
    std::fs::remove_dir_all(dir).ok();
}

/// A loose garment stays on: an XL T-shirt, its folds held apart by the self-collision on by
/// default, walks with nothing inside the body, nothing crossed and no edge doubled, and its top
/// stays on the shoulders. (With the contacts of a substep that re-anchors its search taken as
/// those within reach at its start, rather than those the last substep's moves were bringing
/// near, the safe step held the shirt back against the walking body: 36 vertices inside, an edge
/// at 3.8× its length.)
#[test]
fn a_loose_tshirt_walks_with_its_folds_apart_and_nothing_inside_the_body() {
    let dir = scratch("cloth-tshirt-xl");
    let (garment, walk, out) = (dir.join("tshirt.garment"), dir.join("walk.npz"), dir.join("sim"));
    ok(mannequin(&["garment", "make", "--category", "tshirt", "--size", "XL", "--out", s(&garment)]));
    ok(mannequin(&["motion", "walk", "--seconds", "0.5", "-o", s(&walk)]));
    ok(mannequin(&["cloth", "simulate", "--garment", s(&garment), "--motion", s(&walk), "--out", s(&out)]));
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["max_vertices_inside_body"], 0, "{metrics}");
    assert_eq!(metrics["max_self_intersecting_pairs"], 0, "{metrics}");
    assert!(metrics["max_edge_strain"].as_f64().unwrap() < 1.0, "{metrics}");
    let (first, last) = top_heights(&out);
    assert!(first - last < 0.03, "the T-shirt's top fell from {first} m to {last} m");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bad_garments_are_one_line_errors() {
    let dir = scratch("cloth-bad");
    let walk = dir.join("walk.npz");
    ok(mannequin(&["motion", "walk", "--seconds", "0.2", "-o", s(&walk)]));
    let simulate = |garment: &Path, pins: Option<&Path>| {
        let mut a = vec!["cloth", "simulate", "--garment", s(garment), "--motion", s(&walk)];
        if let Some(p) = pins {
            a.extend_from_slice(&["--pin", s(p)]);
        }
        let out = dir.join("out");
        a.extend_from_slice(&["--out", s(&out)]);
        mannequin(&a)
    };
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    // Three triangles on one edge, around the hips.
    let fan =
        "v 0 0 0.2\nv 0.1 0 0.2\nv 0 0.1 0.2\nv 0.1 0.1 0.2\nv 0.05 0.05 0.25\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
    let nonmanifold = write("fan.obj", fan);
    one_line_error(&simulate(&nonmanifold, None), &["fan.obj", "edge", "3"]);
    let degenerate = write("flat.obj", "v 0 0 0.2\nv 0.1 0 0.2\nv 0.2 0 0.2\nf 1 2 3\n");
    one_line_error(&simulate(&degenerate, None), &["flat.obj", "faces[0]", "degenerate"]);
    let far = write("far.obj", "v 5 0 0\nv 5.1 0 0\nv 5 0.1 0\nf 1 2 3\n");
    one_line_error(&simulate(&far, None), &["far.obj", "far from the body"]);
    let square = write("square.obj", "v 0 0 0.2\nv 0.1 0 0.2\nv 0 0.1 0.2\nf 1 2 3\n");
    let pins = write("pins.json", r#"{"fixed": [0, 7]}"#);
    one_line_error(&simulate(&square, Some(&pins)), &["pins.json", "fixed", "vertex 7", "3 vertices"]);
    let nan = write("nan.obj", "v 0 0 0.2\nv nan 0 0.2\nv 0 0.1 0.2\nf 1 2 3\n");
    one_line_error(&simulate(&nan, None), &["nan.obj"]);
    // Issue 42: each of these was simulated.
    let corners = "v 0 0 0.2\nv 0.1 0 0.2\nv 0.1 0.1 0.2\nv 0 0.1 0.2\n";
    let bowtie = write("bowtie.obj", &format!("{corners}v -0.1 0 0.2\nv -0.1 -0.1 0.2\nf 1 2 3\nf 1 5 6\n"));
    one_line_error(&simulate(&bowtie, None), &["bowtie.obj", "faces", "vertex 0", "more than one fan"]);
    let flipped = write("flipped.obj", &format!("{corners}f 1 2 3\nf 1 4 3\n"));
    one_line_error(&simulate(&flipped, None), &["flipped.obj", "faces 0 and 1", "the same way"]);
    let loose = write("loose.obj", &format!("{corners}f 1 2 3\n"));
    one_line_error(&simulate(&loose, None), &["loose.obj", "vertex 3 is in no triangle"]);
    let both = write("both.json", r#"{"fixed": [1, 2], "attached": [0, 2]}"#);
    one_line_error(&simulate(&square, Some(&both)), &["both.json", "attached", "vertex 2 is also fixed"]);
    assert!(!dir.join("out").exists(), "a refused run writes nothing");
    std::fs::remove_dir_all(dir).ok();
}

/// Issue 42: a run whose outputs cannot all be written leaves none of them and keeps its last
/// checkpoint; a checkpoint that is not what this run saves (a frame counter past the motion,
/// frames cut short or outnumbering it, velocities of 1e30) is refused naming the field, and the
/// good one resumes to every frame of the motion.
#[test]
fn a_failed_run_leaves_no_outputs_and_a_bad_checkpoint_is_refused() {
    let dir = scratch("cloth-checkpoint");
    let SkirtOnAWalk { garment, pins, walk, .. } = skirt_on_a_walk(&dir, "0.5");
    let out = dir.join("sim");
    let run = || {
        let a = ["cloth", "simulate", "--garment", s(&garment), "--pin", s(&pins), "--motion", s(&walk)];
        let b = ["--settle", "0.1", "--checkpoint-every", "5", "--substeps", "5", "--out", s(&out)];
        mannequin(&a.iter().chain(&b).copied().collect::<Vec<_>>())
    };
    std::fs::create_dir_all(out.join("metrics.json")).unwrap();
    one_line_error(&run(), &["metrics.json", "a folder is in the way"]);
    let mut left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["checkpoint.npz", "metrics.json"], "only the checkpoint is new");
    std::fs::remove_dir(out.join("metrics.json")).unwrap();

    // Settling takes 3 frames before the motion's; the last checkpoint is at a multiple of 5.
    let motion_frames = mannequin_body::Motion::read(&walk).unwrap().num_frames();
    let last = 3 + motion_frames - 1;
    let recorded = last / 5 * 5 - 3;
    let checkpoint = out.join("checkpoint.npz");
    let good = dir.join("good.npz");
    std::fs::copy(&checkpoint, &good).unwrap();
    let npz = Npz::read(&good).unwrap();
    let (_, frames) = npz.f64_with_shape("frames", &[Some(recorded), None, Some(3)]).unwrap();
    let per_frame = frames.len() / recorded;
    let frames_of = |n: usize| {
        let values = (0..n * per_frame).map(|i| frames[i % frames.len()] as f32).collect();
        NpyArray::f32(vec![n, per_frame / 3, 3], values)
    };
    let (_, v) = npz.f64_with_shape("velocities", &[None, Some(3)]).unwrap();
    let fast = NpyArray::f32(vec![v.len() / 3, 3], vec![1e30; v.len()]);
    let expected = |n: usize| format!("frames: {n} frames; expected {recorded}");
    for (key, array, needle) in [
        ("next", NpyArray::i64(vec![1], vec![last as i64 + 20]), format!("next: {}", last + 20)),
        ("frames", frames_of(recorded - 2), expected(recorded - 2)),
        ("frames", frames_of(motion_frames + 5), expected(motion_frames + 5)),
        ("velocities", fast, "state.velocities: entry 0".into()),
    ] {
        let mut w = NpzWriter::new();
        for k in npz.keys().filter(|&k| k != key) {
            w.add(k, npz.get(k).unwrap().clone());
        }
        w.add(key, array);
        w.write(&checkpoint).unwrap();
        let o = run();
        one_line_error(&o, &["checkpoint.npz", &needle]);
        assert!(!out.join("garment.pc2").exists(), "a refused resume writes nothing");
    }
    std::fs::copy(&good, &checkpoint).unwrap();
    ok(run());
    assert_eq!(PointCache::read(&out.join("garment.pc2")).unwrap().frames.len(), motion_frames);
    assert!(!checkpoint.exists(), "a finished run leaves no checkpoint");
    std::fs::remove_dir_all(dir).ok();
}

/// A run killed after a checkpoint and run again with the same command ends with the same
/// frames, bit for bit, as a run never stopped; a changed option is refused naming it.
#[test]
fn a_killed_run_resumes_to_the_same_frames() {
    let dir = scratch("cloth-resume");
    let SkirtOnAWalk { garment, pins, walk, .. } = skirt_on_a_walk(&dir, "0.4");
    let args = |out: &Path| -> Vec<String> {
        let a = ["cloth", "simulate", "--garment", s(&garment), "--pin", s(&pins), "--motion", s(&walk)];
        let b = ["--settle", "0.3", "--checkpoint-every", "4", "--out", s(out)];
        a.iter().chain(&b).map(|x| x.to_string()).collect()
    };
    let whole = dir.join("whole");
    ok(Command::new(env!("CARGO_BIN_EXE_mannequin")).args(args(&whole)).output().unwrap());

    let resumed = dir.join("resumed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_mannequin"))
        .args(args(&resumed))
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let checkpoint = resumed.join("checkpoint.npz");
    let start = std::time::Instant::now();
    while !checkpoint.exists() && start.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(checkpoint.exists(), "no checkpoint within 2 minutes");
    assert!(!resumed.join("garment.pc2").exists(), "killed before the end");

    let mut changed = args(&resumed);
    changed.extend(["--material".into(), "denim".into()]);
    let o = Command::new(env!("CARGO_BIN_EXE_mannequin")).args(&changed).output().unwrap();
    one_line_error(&o, &["checkpoint.npz", "material was cotton, now denim", "--restart"]);

    let o = ok(Command::new(env!("CARGO_BIN_EXE_mannequin")).args(args(&resumed)).output().unwrap());
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("resuming"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!checkpoint.exists(), "a finished run leaves no checkpoint");
    let read = |d: &Path| std::fs::read(d.join("garment.pc2")).unwrap();
    assert!(read(&whole) == read(&resumed), "resumed frames differ from the uninterrupted run's");
    std::fs::remove_dir_all(dir).ok();
}
