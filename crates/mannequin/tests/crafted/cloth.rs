//! Crafted bad input for cloth and garments: garment meshes with each defect the solver cannot
//! hold, pin files, `.garment` files and both simulating commands' checkpoints with each field
//! broken in the ways broken files arrive, and the size-like flags of `cloth simulate` and
//! `dress` past their limits. The good files they start from (a band around the light body's
//! hips, a coarse T-shirt template, and a checkpoint of each command, kept by a run whose last
//! output was blocked) are made once, then copied and broken per case.

use std::path::{Path, PathBuf};

use mannequin_body::BodyModel;
use mannequin_io::{NpyArray, Npz};

use super::{Case, Fixtures, broken_bytes, case_dir};
use crate::common::{mannequin, s};

/// The good files every case breaks a copy of.
struct Base {
    /// A band around the light body's hips (.obj) that `cloth simulate` accepts.
    band: PathBuf,
    /// A coarse T-shirt template made on the light body.
    tshirt: PathBuf,
    /// `cloth simulate`'s checkpoint of [`CLOTH_FLAGS`] with `band`.
    cloth_checkpoint: PathBuf,
    /// `dress`'s checkpoint of [`DRESS_FLAGS`] with `tshirt`.
    dress_checkpoint: PathBuf,
}

/// What the base `cloth simulate` run and its checkpoint cases share (after the garment,
/// motion and output flags): a short clip, so a run takes a second.
const CLOTH_FLAGS: [&str; 10] = [
    "--body",
    "default-lod1",
    "--max-frames",
    "6",
    "--settle",
    "0.1",
    "--substeps",
    "2",
    "--checkpoint-every",
    "2",
];

/// The same for `dress`.
const DRESS_FLAGS: [&str; 11] = [
    "--body",
    "default-lod1",
    "--max-frames",
    "3",
    "--settle",
    "0.1",
    "--substeps",
    "2",
    "--checkpoint-every",
    "2",
    "--no-frames",
];

/// Values that break a number field, by name.
const BAD_FLOATS: [(&str, f32); 5] = [
    ("nan", f32::NAN),
    ("inf", f32::INFINITY),
    ("neg_inf", f32::NEG_INFINITY),
    ("huge", 1e30),
    ("neg_huge", -1e30),
];

pub fn cases(fx: &Fixtures, dir: &Path) -> Vec<Case> {
    let base = make_base(fx, &dir.join("base"));
    let mut cases = Vec::new();
    mesh_cases(fx, dir, &mut cases);
    pin_cases(fx, dir, &base, &mut cases);
    flag_cases(fx, dir, &base, &mut cases);
    cloth_checkpoint_cases(fx, dir, &base, &mut cases);
    dress_checkpoint_cases(fx, dir, &base, &mut cases);
    garment_file_cases(fx, dir, &base, &mut cases);
    cases
}

/// Makes the base files under `dir`; each checkpoint is kept by a run whose `metrics.json` is
/// blocked by a folder of that name, so the run fails at its very end.
fn make_base(fx: &Fixtures, dir: &Path) -> Base {
    std::fs::create_dir_all(dir).unwrap();
    let band = dir.join("band.obj");
    std::fs::write(&band, band_obj()).unwrap();
    let tshirt = dir.join("tshirt.garment");
    let made = mannequin(&[
        "garment",
        "make",
        "--category",
        "tshirt",
        "--body",
        "default-lod1",
        "--edge-length",
        "0.05",
        "--out",
        s(&tshirt),
    ]);
    assert!(made.status.success(), "{}", String::from_utf8_lossy(&made.stderr));
    let blocked_run = |name: &str, args: Vec<&str>| {
        let out = dir.join(name);
        std::fs::create_dir_all(out.join("metrics.json")).unwrap();
        let o = mannequin(&[&args[..], &["--out", s(&out)]].concat());
        let checkpoint = out.join("checkpoint.npz");
        assert!(checkpoint.exists(), "{name}: no checkpoint kept: {}", String::from_utf8_lossy(&o.stderr));
        checkpoint
    };
    let cloth =
        [&["cloth", "simulate", "--garment", s(&band), "--motion", s(&fx.motion)][..], &CLOTH_FLAGS].concat();
    let dress = [&["dress", "--garments", s(&tshirt), "--motion", s(&fx.motion)][..], &DRESS_FLAGS].concat();
    let (cloth_checkpoint, dress_checkpoint) = (blocked_run("cloth", cloth), blocked_run("dress", dress));
    Base { band, tshirt, cloth_checkpoint, dress_checkpoint }
}

/// A band of 24 segments and 3 rings, 2 cm outside the light body's hips, as OBJ text.
fn band_obj() -> String {
    let body = BodyModel::default_body_lod1().template_mesh();
    let hips = -0.12f32;
    let radius = body
        .positions
        .iter()
        .filter(|p| (p[1] - hips).abs() < 0.08 && p[0].abs() < 0.25)
        .map(|p| (p[0] * p[0] + p[2] * p[2]).sqrt())
        .fold(0.0f32, f32::max)
        + 0.02;
    let (segments, rings) = (24usize, 3usize);
    let mut text = String::new();
    for r in 0..rings {
        for k in 0..segments {
            let a = std::f32::consts::TAU * k as f32 / segments as f32;
            text += &format!("v {} {} {}\n", radius * a.cos(), hips - 0.03 * r as f32, radius * a.sin());
        }
    }
    let at = |r: usize, k: usize| r * segments + k % segments + 1;
    for r in 0..rings - 1 {
        for k in 0..segments {
            let (a, b, c, d) = (at(r, k), at(r, k + 1), at(r + 1, k + 1), at(r + 1, k));
            text += &format!("f {a} {c} {b}\nf {a} {d} {c}\n");
        }
    }
    text
}

/// `cloth simulate` of the garment `garment` (and pins), writing into `case/out`.
fn simulate(fx: &Fixtures, case: &Path, garment: &Path, pins: Option<&Path>, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = ["cloth", "simulate", "--garment", s(garment), "--motion", s(&fx.motion)]
        .iter()
        .map(|x| x.to_string())
        .collect();
    if let Some(p) = pins {
        a.extend(["--pin".to_string(), s(p).to_string()]);
    }
    a.extend(["--out".to_string(), s(&case.join("out")).to_string()]);
    a.extend(extra.iter().map(|x| x.to_string()));
    a
}

/// A fresh folder for the case `name`, named by a hash of it: a refusal must name the field
/// in its words, not by quoting a path that happens to hold them.
fn folder(dir: &Path, name: &str) -> PathBuf {
    let hash =
        name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
    case_dir(dir, &format!("{hash:016x}"))
}

fn refused(name: &str, case: &Path, args: &[String], needles: &[&str]) -> Case {
    Case::refused(
        format!("cloth/{name}"),
        case,
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        needles,
    )
}

fn mesh_cases(fx: &Fixtures, dir: &Path, cases: &mut Vec<Case>) {
    let square = "v 0 0 0.2\nv 0.1 0 0.2\nv 0.1 0.1 0.2\nv 0 0.1 0.2\n";
    let meshes: Vec<(&str, String, &str)> = vec![
        ("bowtie", format!("{square}v -0.1 0 0.2\nv -0.1 -0.1 0.2\nf 1 2 3\nf 1 5 6\n"), "more than one fan"),
        ("flipped", format!("{square}f 1 2 3\nf 1 4 3\n"), "the same way"),
        ("loose_vertex", format!("{square}f 1 2 3\n"), "vertex 3 is in no triangle"),
        ("fin", format!("{square}v 0.05 0.05 0.3\nf 1 2 3\nf 2 1 4\nf 1 2 5\n"), "shared by 3 triangles"),
        ("duplicate", format!("{square}f 1 2 3\nf 1 2 3\nf 1 3 4\n"), "faces"),
        ("duplicate_reversed", format!("{square}f 1 2 3\nf 3 2 1\n"), "the same triangle"),
        ("collinear", "v 0 0 0.2\nv 0.1 0 0.2\nv 0.2 0 0.2\nf 1 2 3\n".into(), "degenerate"),
        ("repeated_corner", format!("{square}f 1 2 2\n"), "degenerate"),
        ("point", "v 0 0 0.2\nv 0 0 0.2\nv 0 0 0.2\nf 1 2 3\n".into(), "degenerate"),
        ("no_faces", square.into(), "g.obj"),
        ("one_vertex", "v 0 0 0.2\n".into(), "g.obj"),
        ("empty", String::new(), "g.obj"),
        ("index_past", format!("{square}f 1 2 9\n"), "g.obj"),
        ("index_zero", format!("{square}f 0 1 2\n"), "g.obj"),
        ("nan", "v 0 0 0.2\nv nan 0 0.2\nv 0 0.1 0.2\nf 1 2 3\n".into(), "g.obj"),
        ("inf", "v 0 0 0.2\nv inf 0 0.2\nv 0 0.1 0.2\nf 1 2 3\n".into(), "g.obj"),
        ("far", "v 5 0 0\nv 5.1 0 0\nv 5 0.1 0\nf 1 2 3\n".into(), "far from the body"),
        ("huge", "v 1e30 0 0\nv 1e30 1 0\nv 1e30 0 1\nf 1 2 3\n".into(), "g.obj"),
        ("text", "v a b c\nf 1 2 3\n".into(), "g.obj"),
    ];
    for (what, text, needle) in meshes {
        let case = folder(dir, &format!("mesh/{what}"));
        let garment = case.join("g.obj");
        std::fs::write(&garment, text).unwrap();
        let args = simulate(fx, &case, &garment, None, &["--body", "default-lod1"]);
        cases.push(refused(&format!("mesh/{what}"), &case, &args, &["g.obj", needle]));
    }
    for (what, bytes) in broken_bytes(band_obj().as_bytes()).into_iter().filter(|(w, _)| w == "random") {
        let case = folder(dir, &format!("mesh/bytes_{what}"));
        let garment = case.join("g.obj");
        std::fs::write(&garment, bytes).unwrap();
        let args = simulate(fx, &case, &garment, None, &["--body", "default-lod1"]);
        cases.push(refused(&format!("mesh/bytes_{what}"), &case, &args, &["g.obj"]));
    }
}

fn pin_cases(fx: &Fixtures, dir: &Path, base: &Base, cases: &mut Vec<Case>) {
    let pins: [(&str, &str, &str); 12] = [
        ("fixed_past", r#"{"fixed": [0, 72]}"#, "vertex 72 is out of range"),
        ("attached_past", r#"{"attached": [4294967295]}"#, "out of range"),
        ("both", r#"{"fixed": [3, 5], "attached": [5]}"#, "vertex 5 is also fixed"),
        ("negative", r#"{"fixed": [-1]}"#, "expected"),
        ("fraction", r#"{"fixed": [1.5]}"#, "expected"),
        ("overflow", r#"{"fixed": [4294967296]}"#, "expected"),
        ("text", r#"{"fixed": ["a"]}"#, "expected"),
        ("unknown_key", r#"{"glued": [1]}"#, "expected"),
        ("not_a_list", r#"{"fixed": 3}"#, "expected"),
        ("not_json", "{\"fixed\": [", "expected"),
        ("empty", "", "expected"),
        ("nan", r#"{"fixed": [NaN]}"#, "expected"),
    ];
    for (what, text, needle) in pins {
        let case = folder(dir, &format!("pins/{what}"));
        let file = case.join("pins.json");
        std::fs::write(&file, text).unwrap();
        let args = simulate(fx, &case, &base.band, Some(&file), &["--body", "default-lod1"]);
        cases.push(refused(&format!("pins/{what}"), &case, &args, &["pins.json", needle]));
    }
}

fn flag_cases(fx: &Fixtures, dir: &Path, base: &Base, cases: &mut Vec<Case>) {
    let settle = ["inf", "NaN", "-1", "1e5", "10.5", "-inf", "1e39", "ten"];
    let substeps = ["0", "101", "1000000000", "-1", "4294967296", "2.5"];
    for verb in ["cloth", "dress"] {
        let flags = settle
            .iter()
            .map(|v| ("--settle", *v, "--settle"))
            .chain(substeps.iter().map(|v| ("--substeps", *v, "--substeps")));
        for (flag, value, needle) in flags {
            let name = format!("flags/{verb}_{}_{value}", &flag[2..]);
            let case = folder(dir, &name);
            let args: Vec<String> = match verb {
                "cloth" => simulate(fx, &case, &base.band, None, &[flag, value]),
                _ => dress(fx, &case, &base.tshirt, &[flag, value]),
            };
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            cases.push(Case::usage(format!("cloth/{name}"), &case, &args, &[needle]));
        }
    }
    let case = folder(dir, "flags/cloth_material");
    let args = simulate(fx, &case, &base.band, None, &["--material", "vibranium"]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    cases.push(Case::usage("cloth/flags/cloth_material", &case, &args, &["--material", "vibranium"]));
    // The clip's flags, as these verbs take them.
    // (flag, value, what the refusal names, whether the parser itself refuses it)
    let clip: [(&str, &str, &str, bool); 6] = [
        ("--fps", "0", "--fps", true),
        ("--fps", "inf", "--fps", true),
        ("--fps", "NaN", "--fps", true),
        ("--fps", "-5", "--fps", true),
        ("--fps", "1e9", "expected at most 1000 times", false),
        ("--max-frames", "0", "--max-frames", false),
    ];
    for verb in ["cloth", "dress"] {
        for (flag, value, needle, by_parser) in clip {
            let name = format!("flags/{verb}_{}_{value}", &flag[2..]);
            let case = folder(dir, &name);
            let extra = ["--body", "default-lod1", flag, value];
            let args = match verb {
                "cloth" => simulate(fx, &case, &base.band, None, &extra),
                _ => dress(fx, &case, &base.tshirt, &extra),
            };
            if by_parser {
                let args: Vec<&str> = args.iter().map(String::as_str).collect();
                cases.push(Case::usage(format!("cloth/{name}"), &case, &args, &[needle]));
            } else {
                cases.push(refused(&name, &case, &args, &[needle]));
            }
        }
    }
    // A settling period within the flag's limit is refused by the frames it makes at a rate no
    // motion has (here 1000 fps, resampled from the walk's 30).
    for verb in ["cloth", "dress"] {
        let name = format!("flags/{verb}_settle_frames");
        let case = folder(dir, &name);
        let extra = ["--body", "default-lod1", "--fps", "1000", "--settle", "10", "--max-frames", "2"];
        let args = match verb {
            "cloth" => simulate(fx, &case, &base.band, None, &extra),
            _ => dress(fx, &case, &base.tshirt, &extra),
        };
        cases.push(refused(&name, &case, &args, &["settle", "expected at most 1200"]));
    }
}

/// `dress` of the template `garment` into `case/out`, with `extra` flags after.
fn dress(fx: &Fixtures, case: &Path, garment: &Path, extra: &[&str]) -> Vec<String> {
    let out = case.join("out");
    let a = ["dress", "--garments", s(garment), "--motion", s(&fx.motion), "--out", s(&out)];
    a.iter().chain(extra).map(|x| x.to_string()).collect()
}

/// Ways to break the float array `good` (one value non-finite or past ±`huge`, a row fewer, a
/// column more, flattened, text), each with its name.
fn broken_floats(good: &NpyArray, huge: f32) -> Vec<(String, NpyArray)> {
    let (shape, values) = (good.shape.clone(), good.to_f32().unwrap());
    let mut out: Vec<(String, NpyArray)> = BAD_FLOATS
        .iter()
        .filter(|(_, v)| v.is_nan() || v.abs() > huge)
        .map(|(what, v)| {
            let mut bad = values.clone();
            let middle = bad.len() / 2;
            bad[middle] = *v;
            (what.to_string(), NpyArray::f32(shape.clone(), bad))
        })
        .collect();
    let row: usize = shape[1..].iter().product();
    let mut fewer = shape.clone();
    fewer[0] -= 1;
    out.push(("fewer_rows".into(), NpyArray::f32(fewer, values[row..].to_vec())));
    let mut wide = shape.clone();
    *wide.last_mut().unwrap() += 1;
    out.push(("wider".into(), NpyArray::f32(wide.clone(), vec![0.0; wide.iter().product()])));
    out.push(("flat".into(), NpyArray::f32(vec![values.len()], values)));
    out.push(("text".into(), NpyArray::text("0")));
    out
}

/// Copies of `checkpoint` into a case folder's `out/`, one per broken field, each run with
/// `args` (the case folder given) and refused naming the checkpoint and `needle`.
fn checkpoint_cases(
    dir: &Path,
    group: &str,
    checkpoint: &Path,
    broken: Vec<(String, &str, Option<NpyArray>, String)>,
    args: &dyn Fn(&Path) -> Vec<String>,
    cases: &mut Vec<Case>,
) {
    for (what, key, array, needle) in broken {
        let name = format!("{group}/{key}_{what}");
        let case = folder(dir, &name);
        let out = case.join("out");
        std::fs::create_dir_all(&out).unwrap();
        npz_with(checkpoint, &out.join("checkpoint.npz"), key, array.as_ref());
        cases.push(refused(&name, &case, &args(&case), &["checkpoint.npz", &needle]));
    }
    for (what, bytes) in broken_bytes(&std::fs::read(checkpoint).unwrap()) {
        let name = format!("{group}/bytes_{what}");
        let case = folder(dir, &name);
        std::fs::create_dir_all(case.join("out")).unwrap();
        std::fs::write(case.join("out/checkpoint.npz"), bytes).unwrap();
        cases.push(refused(&name, &case, &args(&case), &["checkpoint.npz"]));
    }
}

/// The `.npz` at `from` written to `to` (uncompressed: the copies are many) with `key` replaced by
/// `array`, or removed. Its bytes are written directly, as the archive writer refuses the
/// non-finite numbers these files are made to hold.
fn npz_with(from: &Path, to: &Path, key: &str, array: Option<&NpyArray>) {
    let npz = Npz::read(from).unwrap();
    let mut w = mannequin_io::NpzWriter::uncompressed();
    for k in npz.keys().filter(|&k| k != key) {
        w.add(k, npz.get(k).unwrap().clone());
    }
    if let Some(a) = array {
        w.add(key, a.clone());
    }
    std::fs::write(to, w.to_bytes()).unwrap();
}

/// The array under `key` in the `.npz` at `path`.
fn array_of(path: &Path, key: &str) -> NpyArray {
    Npz::read(path).unwrap().get(key).unwrap().clone()
}

fn cloth_checkpoint_cases(fx: &Fixtures, dir: &Path, base: &Base, cases: &mut Vec<Case>) {
    let ckpt = &base.cloth_checkpoint;
    let npz = Npz::read(ckpt).unwrap();
    let vertices = array_of(ckpt, "positions").shape[0];
    let frames = array_of(ckpt, "frames").shape;
    let mut broken: Vec<(String, &str, Option<NpyArray>, String)> = Vec::new();
    let next = |v: i64| Some(NpyArray::i64(vec![1], vec![v]));
    for (what, array) in [
        ("negative", next(-5)),
        ("zero", next(0)),
        ("past_motion", next(40)),
        ("two_62", next(1 << 62)),
        ("fraction", Some(NpyArray::f64(vec![1], vec![2.5]))),
        ("nan", Some(NpyArray::f64(vec![1], vec![f64::NAN]))),
        ("two_values", Some(NpyArray::i64(vec![2], vec![2, 4]))),
        ("text", Some(NpyArray::text("8"))),
        ("missing", None),
    ] {
        broken.push((what.into(), "next", array, "next".into()));
    }
    for key in ["positions", "velocities"] {
        for (what, array) in broken_floats(&array_of(ckpt, key), 1e3) {
            broken.push((what, key, Some(array), key.into()));
        }
        broken.push(("missing".into(), key, None, key.into()));
    }
    broken.push((
        "past_sound".into(),
        "velocities",
        Some(NpyArray::f32(vec![vertices, 3], vec![250.0; 3 * vertices])),
        "343 m/s".into(),
    ));
    broken.push((
        "far".into(),
        "positions",
        Some(NpyArray::f32(vec![vertices, 3], vec![1500.0; 3 * vertices])),
        "±1000 m".into(),
    ));
    for (what, array) in broken_floats(&array_of(ckpt, "frames"), 1e3) {
        broken.push((what, "frames", Some(array), "frames".into()));
    }
    let with_frames = |n: usize| Some(NpyArray::f32(vec![n, vertices, 3], vec![0.0; n * vertices * 3]));
    broken.push(("truncated".into(), "frames", with_frames(frames[0] - 1), "frames".into()));
    broken.push(("outnumbering".into(), "frames", with_frames(frames[0] + 7), "frames".into()));
    broken.push(("none".into(), "frames", with_frames(0), "frames".into()));
    broken.push(("missing".into(), "frames", None, "frames".into()));
    let metrics: serde_json::Value = serde_json::from_str(npz.text("metrics").unwrap()).unwrap();
    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut m = metrics.clone();
        f(&mut m);
        Some(NpyArray::text(&m.to_string()))
    };
    for (what, array) in [
        (
            "one_short",
            edit(&|m| {
                m.as_array_mut().unwrap().pop();
            }),
        ),
        (
            "one_more",
            edit(&|m| {
                let last = m[0].clone();
                m.as_array_mut().unwrap().push(last);
            }),
        ),
        ("negative_strain", edit(&|m| m[0]["max_edge_strain"] = (-1.0).into())),
        ("wrong_frame", edit(&|m| m[1]["frame"] = 7.into())),
        ("negative_ms", edit(&|m| m[0]["simulation_ms"] = (-1.0).into())),
        ("not_json", Some(NpyArray::text("[{"))),
        ("nan_text", Some(NpyArray::text(&metrics.to_string().replacen("0.", "NaN", 1)))),
        ("missing", None),
    ] {
        broken.push((what.into(), "metrics", array, "metrics".into()));
    }
    let run: serde_json::Value = serde_json::from_str(npz.text("run").unwrap()).unwrap();
    let mut other = run.clone();
    other["material"] = "denim".into();
    broken.push(("other_run".into(), "run", Some(NpyArray::text(&other.to_string())), "another run".into()));
    broken.push(("not_json".into(), "run", Some(NpyArray::text("{")), "run".into()));
    broken.push(("missing".into(), "run", None, "run".into()));
    let args = |case: &Path| {
        let extra: Vec<&str> = CLOTH_FLAGS.to_vec();
        simulate(fx, case, &base.band, None, &extra)
    };
    checkpoint_cases(dir, "cloth_checkpoint", ckpt, broken, &args, cases);
}

fn dress_checkpoint_cases(fx: &Fixtures, dir: &Path, base: &Base, cases: &mut Vec<Case>) {
    let ckpt = &base.dress_checkpoint;
    let vertices = array_of(ckpt, "positions_0").shape[0];
    let frames = array_of(ckpt, "frames_0").shape;
    let mut broken: Vec<(String, &str, Option<NpyArray>, String)> = Vec::new();
    for key in ["positions_0", "velocities_0"] {
        for (what, array) in broken_floats(&array_of(ckpt, key), 1e3) {
            broken.push((what, key, Some(array), key.into()));
        }
    }
    broken.push((
        "past_sound".into(),
        "velocities_0",
        Some(NpyArray::f32(vec![vertices, 3], vec![1e3; 3 * vertices])),
        "343 m/s".into(),
    ));
    // A layer's frames cut short are an earlier, whole checkpoint: not broken, so not here.
    for (what, array) in
        broken_floats(&array_of(ckpt, "frames_0"), 1e3).into_iter().filter(|(w, _)| w != "fewer_rows")
    {
        broken.push((what, "frames_0", Some(array), "frames_0".into()));
    }
    let with_frames = |n: usize| Some(NpyArray::f32(vec![n, vertices, 3], vec![0.0; n * vertices * 3]));
    broken.push(("outnumbering".into(), "frames_0", with_frames(frames[0] + 500), "layers[0]".into()));
    broken.push(("none".into(), "frames_0", with_frames(0), "layers[0]".into()));
    broken.push(("missing_frames".into(), "frames_0", None, "frames_0".into()));
    broken.push(("missing_state".into(), "velocities_0", None, "velocities_0".into()));
    broken.push(("other_run".into(), "run", Some(NpyArray::text("{\"garments\": []}")), "run".into()));
    let args = |case: &Path| dress(fx, case, &base.tshirt, &DRESS_FLAGS);
    checkpoint_cases(dir, "dress_checkpoint", ckpt, broken, &args, cases);
}

fn garment_file_cases(fx: &Fixtures, dir: &Path, base: &Base, cases: &mut Vec<Case>) {
    let good = &base.tshirt;
    let npz = Npz::read(good).unwrap();
    let n = array_of(good, "positions").shape[0];
    let faces = array_of(good, "faces").shape[0];
    let face_rows = npz.get("faces").unwrap().to_i64().unwrap();
    let recipe: serde_json::Value = serde_json::from_str(npz.text("recipe").unwrap()).unwrap();
    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut r = recipe.clone();
        f(&mut r);
        Some(NpyArray::text(&r.to_string()))
    };
    let with_face = |row: usize, tri: [i64; 3]| {
        let mut rows = face_rows.clone();
        rows[3 * row..3 * row + 3].copy_from_slice(&tri);
        Some(NpyArray::i64(vec![faces, 3], rows))
    };
    let [a, b, c] = [face_rows[0], face_rows[1], face_rows[2]];
    let mut broken: Vec<(String, &str, Option<NpyArray>, &str)> = vec![
        (
            "vibranium".into(),
            "recipe",
            edit(&|r| r["material"] = "vibranium".into()),
            "cotton, denim, silk, jersey, leather",
        ),
        ("edge_negative".into(), "recipe", edit(&|r| r["edge_length"] = (-0.01).into()), "edge_length"),
        ("edge_zero".into(), "recipe", edit(&|r| r["edge_length"] = 0.into()), "edge_length"),
        ("edge_metre".into(), "recipe", edit(&|r| r["edge_length"] = 1.into()), "edge_length"),
        ("edge_null".into(), "recipe", edit(&|r| r["edge_length"] = serde_json::Value::Null), "recipe"),
        ("ease_negative".into(), "recipe", edit(&|r| r["fit"]["ease_chest"] = (-1.0).into()), "ease_chest"),
        ("betas_text".into(), "recipe", edit(&|r| r["betas"] = serde_json::json!(["x"])), "recipe"),
        ("body_empty".into(), "recipe", edit(&|r| r["body_faces"] = 0.into()), "recipe"),
        ("unknown_field".into(), "recipe", edit(&|r| r["colour"] = "red".into()), "recipe"),
        ("category".into(), "recipe", edit(&|r| r["category"] = "cape".into()), "recipe"),
        ("not_json".into(), "recipe", Some(NpyArray::text("{")), "recipe"),
        ("missing".into(), "recipe", None, "recipe"),
        ("other".into(), "format", Some(NpyArray::text("mannequin-garment 9")), "format"),
        ("missing".into(), "format", None, "format"),
        ("one_vertex".into(), "positions", Some(NpyArray::f32(vec![1, 3], vec![0.0; 3])), "faces"),
        ("no_vertices".into(), "positions", Some(NpyArray::f32(vec![0, 3], vec![])), "faces"),
        ("index_past".into(), "faces", with_face(0, [a, b, n as i64]), "faces"),
        ("index_negative".into(), "faces", with_face(0, [a, b, -1]), "faces"),
        ("degenerate".into(), "faces", with_face(0, [a, b, b]), "degenerate"),
        ("duplicate".into(), "faces", with_face(1, [a, b, c]), "faces"),
        ("flipped".into(), "faces", with_face(0, [a, c, b]), "faces"),
        ("no_faces".into(), "faces", Some(NpyArray::i64(vec![0, 3], vec![])), "no triangles"),
        (
            "fraction".into(),
            "faces",
            Some(NpyArray::f64(vec![faces, 3], face_rows.iter().map(|&i| i as f64 + 0.5).collect())),
            "faces",
        ),
        ("body_face_past".into(), "body_faces", Some(NpyArray::i64(vec![n], vec![1 << 40; n])), "body_faces"),
        ("body_face_negative".into(), "body_faces", Some(NpyArray::i64(vec![n], vec![-1; n])), "body_faces"),
        (
            "body_faces_short".into(),
            "body_faces",
            Some(NpyArray::i64(vec![n - 1], vec![0; n - 1])),
            "body_faces",
        ),
        (
            "off_face".into(),
            "body_bary",
            Some(NpyArray::f32(vec![n, 3], [2.0, -1.0, 0.0].repeat(n))),
            "body_bary",
        ),
        ("sum_off".into(), "body_bary", Some(NpyArray::f32(vec![n, 3], vec![0.5; 3 * n])), "body_bary"),
        ("far".into(), "offsets", Some(NpyArray::f32(vec![n, 3], [0.0, 0.0, 5.0].repeat(n))), "offsets"),
        ("uv_faces_short".into(), "uv_faces", Some(NpyArray::i64(vec![1, 3], vec![0, 1, 2])), "uv_faces"),
        (
            "uv_faces_past".into(),
            "uv_faces",
            Some(NpyArray::i64(vec![faces, 3], vec![1 << 40; 3 * faces])),
            "uv_faces",
        ),
        // Written by hand below: a header claiming 200 million rows.
        ("huge_header".into(), "positions", None, "positions"),
        // Body model counts of another topology: refused by dress, which wears it on the light body.
        ("other_body".into(), "recipe", edit(&|r| r["body_vertices"] = 12345.into()), "make it again"),
    ];
    // A row fewer of positions or UVs leaves a face naming the row gone.
    for (key, huge, fewer) in [
        ("positions", 1e3, "faces"),
        ("offsets", 1.0, "offsets"),
        ("body_bary", 1.0, "body_bary"),
        ("uv", f32::MAX, "uv_faces"),
    ] {
        for (what, array) in broken_floats(&array_of(good, key), huge) {
            let needle = if what == "fewer_rows" { fewer } else { key };
            broken.push((what, key, Some(array), needle));
        }
    }
    for (what, key, array, needle) in broken {
        for verb in ["info", "dress"] {
            if what == "other_body" && verb == "info" {
                continue;
            }
            let name = format!("garment_file/{verb}_{key}_{what}");
            let case = folder(dir, &name);
            let file = case.join("g.garment");
            if what == "huge_header" {
                write_claiming_rows(good, &file, 200_000_000);
            } else {
                npz_with(good, &file, key, array.as_ref());
            }
            let args: Vec<String> = match verb {
                "info" => ["garment", "info", s(&file)].iter().map(|x| x.to_string()).collect(),
                _ => dress(fx, &case, &file, &["--body", "default-lod1", "--no-simulation", "--no-frames"]),
            };
            cases.push(refused(&name, &case, &args, &["g.garment", needle]));
        }
    }
    for (what, bytes) in broken_bytes(&std::fs::read(good).unwrap()) {
        let name = format!("garment_file/bytes_{what}");
        let case = folder(dir, &name);
        let file = case.join("g.garment");
        std::fs::write(&file, bytes).unwrap();
        let args: Vec<String> = ["garment", "info", s(&file)].iter().map(|x| x.to_string()).collect();
        cases.push(refused(&name, &case, &args, &["g.garment"]));
    }
}

/// `good` with its `positions` member replaced by a header claiming `rows` rows of three f32
/// and no data: a few bytes that once cost gigabytes. The archive is stored uncompressed, so
/// the header is edited in place (its length kept by taking the longer shape from the padding;
/// the member's checksum no longer matches, which a reader learns only after the header).
fn write_claiming_rows(good: &Path, to: &Path, rows: usize) {
    npz_with(good, to, "positions", Some(&NpyArray::f32(vec![2, 3], vec![0.0; 6])));
    let mut bytes = std::fs::read(to).unwrap();
    let (from, claim) = ("(2, 3), }", format!("({rows}, 3), }}"));
    let at = bytes.windows(from.len()).position(|b| b == from.as_bytes()).unwrap();
    let span = at..at + claim.len();
    assert!(bytes[at + from.len()..span.end].iter().all(|&b| b == b' '), "the padding takes the claim");
    bytes[span].copy_from_slice(claim.as_bytes());
    std::fs::write(to, bytes).unwrap();
}
