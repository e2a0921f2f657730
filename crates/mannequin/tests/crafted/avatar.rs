//! Crafted bad input for the avatar verbs (issue 42): every array of a training checkpoint, of
//! an avatar and of LPIPS weights spoiled in several ways, each file cut short or replaced by
//! noise, and flags given values outside their meaning. Each case is one command that must be
//! refused in one line naming the file (or flag) and the field, leaving its folder as it was.

use std::path::Path;

use mannequin_data::metrics::lpips::weight_shapes;
use mannequin_io::{NpyArray, NpyData, Npz, NpzWriter};

use super::{Case, Fixtures, broken_bytes, case_dir};
use crate::common::s;

/// One way to spoil an array: its name in case names, the array put in its place (`None`:
/// removed), and what the refusal must say.
struct Spoil {
    name: &'static str,
    array: Option<NpyArray>,
    says: String,
}

/// `a` as f64 with element `i` set to `value`.
fn with(a: &NpyArray, i: usize, value: f64) -> NpyArray {
    let mut v = a.to_f64().expect("a numeric array");
    v[i] = value;
    NpyArray::f64(a.shape.clone(), v)
}

/// The ways every numeric array is spoiled: a NaN first, an infinity last and 1e300 between
/// (where it has elements), the last axis one longer, text in place of numbers, and no array
/// at all. `says` words the value refusals
/// (`None`: the readers' own "element i is NaN" and the like).
fn spoils(a: &NpyArray, says: Option<&str>) -> Vec<Spoil> {
    let n = a.len();
    let value = |text: String| says.map_or(text, str::to_string);
    let mut longer = a.shape.clone();
    if let Some(last) = longer.last_mut() {
        *last += 1;
    }
    let zeros = longer.iter().product();
    let values = (n > 0).then(|| {
        [
            Spoil { name: "nan", array: Some(with(a, 0, f64::NAN)), says: value("element 0 is NaN".into()) },
            Spoil {
                name: "inf",
                array: Some(with(a, n - 1, f64::INFINITY)),
                says: value(format!("element {} is inf", n - 1)),
            },
            // Finite as float64, past float32 (and past any meaning) for what reads it.
            Spoil {
                name: "huge",
                array: Some(with(a, n / 2, 1e300)),
                says: value(format!("element {} is 1", n / 2)),
            },
        ]
    });
    let others = [
        Spoil {
            name: "shape",
            array: Some(NpyArray::f64(longer, vec![0.0; zeros])),
            says: "expected shape".into(),
        },
        Spoil {
            name: "text",
            array: Some(NpyArray { shape: a.shape.clone(), data: NpyData::Str(vec!["1".into(); n]) }),
            says: "expected numbers".into(),
        },
        Spoil { name: "missing", array: None, says: "missing key".into() },
    ];
    values.into_iter().flatten().chain(others).collect()
}

/// `npz` written to `to`, uncompressed (the cases' copies are many), with `key` replaced by
/// `array` or removed; as bytes, since the writer refuses the NaN these files are made of.
fn write_with(npz: &Npz, to: &Path, key: &str, array: Option<&NpyArray>) {
    let mut w = NpzWriter::uncompressed();
    for k in npz.keys().filter(|&k| k != key) {
        w.add(k, npz.get(k).unwrap().clone());
    }
    if let Some(a) = array {
        w.add(key, a.clone());
    }
    std::fs::write(to, w.to_bytes()).unwrap();
}

/// `avatar.npz` cases: each spoiled copy is loaded by one of the verbs that read an avatar, in
/// turn, writing into the case's folder.
fn avatar_cases(fx: &Fixtures, dir: &Path) -> Vec<Case> {
    let npz = Npz::read(fx.model.join("avatar.npz")).unwrap();
    let mut spoiled: Vec<(String, Option<NpyArray>, String, String)> = Vec::new();
    for key in npz.keys() {
        let a = npz.get(key).unwrap();
        let says = match key {
            "faces" => Some("indexes past the"),
            "parents" => Some("expected an earlier joint"),
            "layer" => Some("named in layer_names"),
            _ => None,
        };
        let file_says = match key {
            // Models saved before these existed load without them.
            "offset_gate" | "layer" => vec!["missing"],
            _ => vec![],
        };
        if let NpyData::Str(_) = a.data {
            let number = NpyArray::f32(vec![1], vec![1.0]);
            spoiled.push((key.into(), Some(number), "number".into(), "expected one string".into()));
            if key != "config" {
                spoiled.push((key.into(), None, "missing".into(), "missing key".into()));
            }
            continue;
        }
        for spoil in spoils(a, says).into_iter().filter(|sp| !file_says.contains(&sp.name)) {
            spoiled.push((key.into(), spoil.array, spoil.name.into(), spoil.says));
        }
    }
    // Values outside their meaning, and settings past their limits.
    let gate = npz.get("offset_gate").unwrap();
    spoiled.push(("offset_gate".into(), Some(with(gate, 1, 2.0)), "above-one".into(), "expected 0–1".into()));
    spoiled.push(("offset_gate".into(), Some(with(gate, 2, -0.5)), "negative".into(), "expected 0–1".into()));
    let config: serde_json::Value = serde_json::from_str(npz.text("config").unwrap()).unwrap();
    for (setting, value, says) in [
        ("sh_degree", serde_json::json!(7), "SH degree 7"),
        ("dilation", serde_json::json!(-1.0), "screen-filter dilation -1"),
        ("hidden", serde_json::json!(1_000_000), "hidden width 1000000"),
        ("hidden", serde_json::json!(0), "hidden width 0"),
        ("hash_levels", serde_json::json!(4096), "4096 hash-grid levels"),
        ("hash_log2_table", serde_json::json!(24), "hash-grid table of"),
        ("hash_log2_table", serde_json::json!(30), "overflow i32 rows"),
        ("hash_features", serde_json::json!(3), "3 features per level"),
        ("hash_growth", serde_json::json!(0.5), "growth 0.5"),
        ("method", serde_json::json!("gaussian"), "unknown variant"),
        ("seed", serde_json::json!(-1), "invalid value"),
    ] {
        let mut c = config.clone();
        c[setting] = value;
        let text = NpyArray::text(&c.to_string());
        spoiled.push(("config".into(), Some(text), format!("{setting}-{}", spoiled.len()), says.into()));
    }
    spoiled.push(("config".into(), Some(NpyArray::text("{")), "not-json".into(), "EOF".into()));

    let base = std::fs::read(fx.model.join("avatar.npz")).unwrap();
    let mut cases = Vec::new();
    let mut add = |name: String, write: &dyn Fn(&Path), says: &[&str]| {
        let d = case_dir(dir, &name);
        let model = d.join("model");
        std::fs::create_dir_all(&model).unwrap();
        write(&model.join("avatar.npz"));
        let args = avatar_command(cases.len(), &model, &d, fx);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        cases.push(Case::refused(format!("avatar/{name}"), &d, &args, says));
    };
    for (key, array, how, says) in &spoiled {
        let name = format!("avatar.npz/{}/{how}", key.replace('/', "."));
        let needle = format!("'{key}'");
        add(name, &|to| write_with(&npz, to, key, array.as_ref()), &["avatar.npz", &needle, says]);
    }
    for (how, bytes) in broken_bytes(&base) {
        for k in 0..3 {
            let write = |to: &Path| std::fs::write(to, &bytes).unwrap();
            add(format!("avatar.npz/{how}/{k}"), &write, &["avatar.npz", "not a readable .npz archive"]);
        }
    }
    cases
}

/// The `k`th of the verbs that load an avatar, reading `model` and writing into `dir`.
fn avatar_command(k: usize, model: &Path, dir: &Path, fx: &Fixtures) -> Vec<String> {
    let out = |name: &str| s(&dir.join(name)).to_string();
    let m = s(model).to_string();
    let args: Vec<String> = match k % 8 {
        0 => vec!["render".into(), "--avatar".into(), m, "-o".into(), out("a.png")],
        1 => vec!["export".into(), "--avatar".into(), m, "-o".into(), out("a.obj")],
        2 => vec!["export".into(), "--avatar".into(), m, "--gaussians".into(), out("g.ply")],
        3 => vec!["export".into(), "--avatar".into(), m, "-o".into(), out("a.glb")],
        4 => {
            let motion = s(&fx.motion).to_string();
            let clip = ["--motion".into(), motion, "--max-frames".into(), "2".into()];
            [vec!["animate".into(), "--avatar".into(), m], clip.to_vec(), vec!["-o".into(), out("frames")]]
                .concat()
        }
        5 => {
            let data = s(&fx.data).to_string();
            vec!["eval".into(), "--avatar".into(), m, "--data".into(), data, "--samples".into(), "100".into()]
        }
        6 => vec!["export".into(), "--avatar".into(), m, "--skinned-gaussians".into(), out("s.ply")],
        _ => vec![
            "render".into(),
            "--avatar".into(),
            m,
            "--what".into(),
            "depth".into(),
            "-o".into(),
            out("d.npy"),
        ],
    };
    args
}

/// Checkpoint cases: `train` resuming the fixture's run from a spoiled copy of its checkpoint.
fn checkpoint_cases(fx: &Fixtures, dir: &Path) -> Vec<Case> {
    let path = fx.model.join("checkpoint.npz");
    let npz = Npz::read(&path).unwrap();
    let iters = npz.get("iteration").unwrap().to_i64().unwrap()[0];
    let mut spoiled: Vec<(String, Option<NpyArray>, String, String)> = Vec::new();
    for key in npz.keys().filter(|k| k.contains('/')) {
        let a = npz.get(key).unwrap();
        for spoil in spoils(a, None) {
            spoiled.push((key.into(), spoil.array, spoil.name.into(), spoil.says));
        }
        if key.starts_with("adam_v/") {
            let says = "expected 0–";
            spoiled.push((key.into(), Some(with(a, a.len() / 2, -1e-3)), "negative".into(), says.into()));
        }
    }
    let range = format!("expected an iteration from 0 to {iters}");
    for (key, array, how, says) in [
        ("iteration", NpyArray::i64(vec![1], vec![-5]), "negative", range.as_str()),
        ("iteration", NpyArray::i64(vec![1], vec![1 << 62]), "huge", range.as_str()),
        ("iteration", NpyArray::i64(vec![1], vec![iters + 1]), "past-the-run", range.as_str()),
        ("iteration", NpyArray::f64(vec![1], vec![1.5]), "fraction", "expected one integer"),
        ("iteration", NpyArray::f64(vec![1], vec![f64::NAN]), "nan", "expected one integer"),
        ("iteration", NpyArray::i64(vec![2], vec![1, 1]), "two", "expected one integer"),
        ("iteration", NpyArray::text("3"), "text", "expected one integer"),
        ("adam_step", NpyArray::i64(vec![1], vec![0]), "behind", "one optimiser step per iteration"),
        ("adam_step", NpyArray::i64(vec![1], vec![-1]), "negative", range.as_str()),
        ("adam_step", NpyArray::f64(vec![1], vec![f64::INFINITY]), "inf", "expected one integer"),
        ("run", NpyArray::text("{"), "not-json", "expected the run's settings as JSON"),
        ("run", NpyArray::f32(vec![1], vec![0.0]), "number", "expected one string"),
    ] {
        spoiled.push((key.into(), Some(array), how.into(), says.into()));
    }
    for key in ["iteration", "adam_step"] {
        spoiled.push((key.into(), None, "missing".into(), "missing key".into()));
    }
    spoiled.push(("run".into(), None, "missing".into(), "holds no record of its run".into()));
    let mut other = serde_json::from_str::<serde_json::Value>(npz.text("run").unwrap()).unwrap();
    other["options"]["iters"] = serde_json::json!(iters + 7);
    let says = format!("options.iters was {}, now {iters}", iters + 7);
    spoiled.push(("run".into(), Some(NpyArray::text(&other.to_string())), "other-run".into(), says));

    let mut cases = Vec::new();
    let mut add = |name: String, write: &dyn Fn(&Path), says: &[&str]| {
        let d = case_dir(dir, &name);
        let out = d.join("model");
        std::fs::create_dir_all(&out).unwrap();
        write(&out.join("checkpoint.npz"));
        let iters = iters.to_string();
        let args = [
            "train",
            "--data",
            s(&fx.data),
            "--out",
            s(&out),
            "--body",
            "default-lod1",
            "--iters",
            &iters,
            "--checkpoint-every",
            &iters,
        ];
        cases.push(Case::refused(format!("checkpoint/{name}"), &d, &args, says));
    };
    for (key, array, how, says) in &spoiled {
        let name = format!("{}/{how}", key.replace('/', "."));
        let needle = format!("'{key}'");
        // A record that is missing or of another run is named by what it lacks or holds.
        let by_record = key == "run" && (array.is_none() || how == "other-run");
        let needles: &[&str] = if by_record { &[] } else { &[&needle] };
        let write = |to: &Path| write_with(&npz, to, key, array.as_ref());
        add(name, &write, &[&["checkpoint.npz", says.as_str(), "--restart"][..], needles].concat());
    }
    for (how, bytes) in broken_bytes(&std::fs::read(&path).unwrap()) {
        let write = |to: &Path| std::fs::write(to, &bytes).unwrap();
        add(format!("file/{how}"), &write, &["checkpoint.npz", "not a readable .npz archive"]);
    }
    cases
}

/// LPIPS weights cases: `eval` of the fixture's own frames with a spoiled weights file, refused
/// as it loads (before anything is scored).
fn lpips_cases(fx: &Fixtures, dir: &Path) -> Vec<Case> {
    let shapes = weight_shapes();
    // Small constant weights: a valid file that compresses to almost nothing.
    let good: Vec<(String, NpyArray)> = shapes
        .iter()
        .map(|(k, shape)| (k.clone(), NpyArray::f32(shape.clone(), vec![0.01; shape.iter().product()])))
        .collect();
    let write = |to: &Path, key: &str, array: Option<&NpyArray>| {
        let mut w = NpzWriter::new();
        for (k, a) in good.iter().filter(|(k, _)| k != key) {
            w.add(k, a.clone());
        }
        if let Some(a) = array {
            w.add(key, a.clone());
        }
        std::fs::write(to, w.to_bytes()).unwrap();
    };
    let mut cases = Vec::new();
    let mut add = |name: String, fill: &dyn Fn(&Path), says: &[&str]| {
        let d = case_dir(dir, &name);
        let weights = d.join("alex.npz");
        fill(&weights);
        let args = ["eval", "--pred", s(&fx.data), "--gt", s(&fx.data), "--lpips-weights", s(&weights)];
        cases.push(Case::refused(format!("lpips/{name}"), &d, &args, says));
    };
    for (key, a) in &good {
        let needle = format!("'{key}'");
        let mut all = spoils(a, None);
        if key.starts_with("lin") {
            all.push(Spoil { name: "negative", array: Some(with(a, 3, -0.5)), says: "expected 0–".into() });
        }
        for spoil in all {
            let fill = |to: &Path| write(to, key, spoil.array.as_ref());
            add(format!("{key}/{}", spoil.name), &fill, &["alex.npz", &needle, &spoil.says]);
        }
    }
    let mut bytes = Vec::new();
    write(&dir.join("lpips-good.npz"), "", None);
    bytes.extend(std::fs::read(dir.join("lpips-good.npz")).unwrap());
    std::fs::remove_file(dir.join("lpips-good.npz")).unwrap();
    for (how, broken) in broken_bytes(&bytes) {
        let fill = |to: &Path| std::fs::write(to, &broken).unwrap();
        add(format!("file/{how}"), &fill, &["alex.npz", "not a readable .npz archive"]);
    }
    cases
}

/// Flags given values outside their meaning: refused by the argument parser (exit 2) or in one
/// line naming the flag, before any file is written.
fn flag_cases(fx: &Fixtures, dir: &Path) -> Vec<Case> {
    let (data, model, motion) = (s(&fx.data), s(&fx.model), s(&fx.motion));
    let mut cases = Vec::new();
    let mut add = |name: &str, args: &dyn Fn(&Path) -> Vec<String>, usage: bool, says: &[&str]| {
        let d = case_dir(dir, name);
        let args = args(&d);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let name = format!("flags/{name}");
        cases.push(if usage {
            Case::usage(name, &d, &args, says)
        } else {
            Case::refused(name, &d, &args, says)
        });
    };
    let words = |list: &[&str]| list.iter().map(|w| w.to_string()).collect::<Vec<_>>();
    for samples in ["0", "-1", "1000001", "1e6", "lots"] {
        let args = |d: &Path| {
            let json = s(&d.join("s.json")).to_string();
            let mut a = words(&["eval", "--pred", data, "--gt", data, "--json"]);
            a.extend([json, format!("--samples={samples}")]);
            a
        };
        add(&format!("eval-samples-{samples}"), &args, true, &["--samples"]);
    }
    for background in ["2,0,0", "nan,0,0", "0,0", "red", "-1,0,0"] {
        let flag = format!("--background={background}");
        let args = |_: &Path| words(&["eval", "--pred", data, "--gt", data, &flag]);
        add(&format!("eval-background-{background}"), &args, false, &["--background"]);
    }
    let train = |d: &Path, extra: &[&str]| {
        let out = s(&d.join("model")).to_string();
        let mut a = words(&["train", "--data", data, "--body", "default-lod1", "--out"]);
        a.push(out);
        a.extend(words(extra));
        a
    };
    for (name, extra, usage, says) in [
        ("iters-0", &["--iters", "0"][..], false, "--iters"),
        ("checkpoint-every-0", &["--checkpoint-every", "0"], false, "--checkpoint-every"),
        ("iters-negative", &["--iters=-3"], true, "--iters"),
        ("dilation-nan", &["--dilation", "nan"], true, "--dilation"),
        ("dilation-negative", &["--dilation=-0.5"], true, "--dilation"),
        ("dilation-inf", &["--dilation", "inf"], true, "--dilation"),
        ("subdivide-9", &["--subdivide", "9"], true, "--subdivide"),
        ("method-unknown", &["--method", "nerf"], true, "--method"),
        ("skirt-unknown", &["--skirt", "maybe"], true, "--skirt"),
    ] {
        add(&format!("train-{name}"), &|d| train(d, extra), usage, &[says]);
    }
    let export = |d: &Path, extra: &[&str]| {
        let mut a = words(&["export", "--avatar", model]);
        a.extend(extra.iter().map(|e| e.replace("OUT", s(d))));
        a
    };
    for (name, extra, usage, says) in [
        ("gaussians-not-ply", &["--gaussians", "OUT/g.txt"][..], false, &["g.txt", ".ply"][..]),
        ("skinned-not-ply", &["--skinned-gaussians", "OUT/g.splat"], false, &["g.splat", ".ply"]),
        ("mesh-format", &["-o", "OUT/a.stl"], false, &["a.stl", "unknown mesh format"]),
        ("glb-posed", &["-o", "OUT/a.glb", "--named-pose", "squat"], false, &["a.glb", "bind pose"]),
        ("animation-obj", &["-o", "OUT/a.obj", "--animation", motion], false, &["--animation", ".glb"]),
        ("frame-without-motion", &["-o", "OUT/a.obj", "--frame", "3"], false, &["--frame", "--motion"]),
        (
            "frame-past-motion",
            &["-o", "OUT/a.obj", "--motion", motion, "--frame", "99999"],
            false,
            &["frame 99999"],
        ),
        ("named-pose-unknown", &["-o", "OUT/a.obj", "--named-pose", "cartwheel"], true, &["cartwheel"]),
        ("no-output", &[], true, &["--output"]),
    ] {
        add(&format!("export-{name}"), &|d| export(d, extra), usage, says);
    }
    let animate = |d: &Path, extra: &[&str]| {
        let out = s(&d.join("frames")).to_string();
        let mut a = words(&["animate", "--avatar", model, "--motion", motion, "-o"]);
        a.push(out);
        a.extend(words(extra));
        a
    };
    for (name, extra, usage, says) in [
        ("max-frames-0", &["--max-frames", "0"][..], false, "--max-frames"),
        ("fps-0", &["--fps", "0"], true, "--fps"),
        ("fps-nan", &["--fps", "nan"], true, "--fps"),
        ("fps-negative", &["--fps", "-5"], true, "--fps"),
        ("fps-huge", &["--fps", "1e9"], false, "frame rate"),
        ("what-unknown", &["--what", "x-ray"], true, "x-ray"),
    ] {
        add(&format!("animate-{name}"), &|d| animate(d, extra), usage, &[says]);
    }
    let render = |d: &Path, extra: &[&str]| {
        let out = s(&d.join("a.png")).to_string();
        let mut a = words(&["render", "--avatar", model, "-o"]);
        a.push(out);
        a.extend(words(extra));
        a
    };
    for (name, extra, usage, says) in [
        ("frame-without-motion", &["--frame", "2"][..], false, "--frame"),
        ("frame-past-split", &["--data", data, "--frame", "9999"], false, "frame 9999"),
        ("split-unknown", &["--data", data, "--split", "holdout"], false, "holdout"),
    ] {
        add(&format!("render-{name}"), &|d| render(d, extra), usage, &[says]);
    }
    cases
}

/// Every crafted avatar, checkpoint, LPIPS and flag case, made under `dir`.
pub fn cases(fx: &Fixtures, dir: &Path) -> Vec<Case> {
    let mut all = checkpoint_cases(fx, &dir.join("checkpoint"));
    all.extend(avatar_cases(fx, &dir.join("avatar")));
    all.extend(lpips_cases(fx, &dir.join("lpips")));
    all.extend(flag_cases(fx, &dir.join("flags")));
    all
}
