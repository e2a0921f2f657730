//! Crafted datasets, images, cameras, poses, motions, body models, shape and focal flags and
//! viewer files: each a good fixture with one thing broken, in the ways broken files arrive
//! (a NaN, an infinity, a value past its meaning, a header claiming gigabytes, a cut file,
//! random bytes).

use std::path::{Path, PathBuf};

use mannequin_io::{NpyArray, NpyData, Npz, NpzWriter};

use super::{Case, Fixtures, broken_bytes, case_dir, copy_dir, npz_with};
use crate::common::s;

/// Values that break a number field, with the word the refusal must hold where it names one.
const BAD_NUMBERS: [(&str, f64); 6] = [
    ("nan", f64::NAN),
    ("inf", f64::INFINITY),
    ("neg_inf", f64::NEG_INFINITY),
    ("huge", 1e30),
    ("neg_huge", -1e30),
    ("max", f64::MAX),
];

pub fn cases(fx: &Fixtures, dir: &Path) -> Vec<Case> {
    let mut cases = Vec::new();
    dataset_cases(fx, dir, &mut cases);
    image_cases(fx, dir, &mut cases);
    motion_cases(fx, dir, &mut cases);
    flag_cases(fx, dir, &mut cases);
    model_cases(dir, &mut cases);
    view_cases(fx, dir, &mut cases);
    cases
}

/// The fixture dataset without its test sets and meshes (what `train` reads), copied into a new
/// case folder `name`; returns the case folder and the copy.
fn dataset_copy(fx: &Fixtures, dir: &Path, name: &str) -> (PathBuf, PathBuf) {
    let case = case_dir(dir, name);
    let data = case.join("data");
    std::fs::create_dir_all(&data).unwrap();
    for entry in std::fs::read_dir(&fx.data).unwrap() {
        let entry = entry.unwrap();
        let file_name = entry.file_name();
        if ["test", "meshes"].contains(&file_name.to_str().unwrap()) {
            continue;
        }
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &data.join(&file_name));
        } else {
            std::fs::copy(entry.path(), data.join(&file_name)).unwrap();
        }
    }
    (case, data)
}

/// `train` on a crafted copy of the dataset, refused naming each of `needles`.
fn train_case(name: &str, case: &Path, data: &Path, needles: &[&str]) -> Case {
    let model = case.join("model");
    Case::refused(
        name,
        case,
        &["train", "--data", s(data), "--out", s(&model), "--iters", "2", "--body", "default-lod1"],
        needles,
    )
}

/// An `.npy` file of `array`.
fn write_npy(path: &Path, array: &NpyArray) {
    std::fs::write(path, mannequin_io::npy::write_npy(array)).unwrap();
}

/// The fixture's `poses` file for the train split, whichever layout the subject has.
fn train_poses(data: &Path) -> PathBuf {
    let per_split = data.join("poses/anim_nerf_train.npz");
    if per_split.exists() { per_split } else { data.join("poses.npz") }
}

fn dataset_cases(fx: &Fixtures, dir: &Path, cases: &mut Vec<Case>) {
    // splits.json: sizes no dataset has, and shapes that are no split.
    let splits: [(&str, &str, &str); 9] = [
        (
            "end_u64_max",
            r#"{"train": {"start": 0, "end": 18446744073709551615, "step": 1}}"#,
            "missing frame",
        ),
        ("end_1e18", r#"{"train": {"start": 0, "end": 1000000000000000000, "step": 1}}"#, "missing frame"),
        ("end_past", r#"{"train": {"start": 0, "end": 10, "step": 1}}"#, "missing frame"),
        ("step_zero", r#"{"train": {"start": 0, "end": 5, "step": 0}}"#, "step"),
        ("backwards", r#"{"train": {"start": 5, "end": 2, "step": 1}}"#, "end ≥ start"),
        ("negative", r#"{"train": {"start": -1, "end": 5, "step": 1}}"#, "splits.json"),
        ("float", r#"{"train": {"start": 0, "end": 5.5, "step": 1}}"#, "splits.json"),
        ("not_json", "{\"train\": ", "splits.json"),
        ("step_huge", r#"{"train": {"start": 0, "end": 9, "step": 18446744073709551615}}"#, "poses"),
    ];
    for (what, text, needle) in splits {
        let (case, data) = dataset_copy(fx, dir, &format!("splits/{what}"));
        std::fs::write(data.join("splits.json"), text).unwrap();
        cases.push(train_case(&format!("inputs/splits/{what}"), &case, &data, &[needle]));
    }

    // Masks: values no mask has, and arrays that are no mask.
    let h = 96;
    let masks: Vec<(String, NpyArray, &str)> = vec![
        ("nan".into(), NpyArray::f32(vec![h, h], vec![f32::NAN; h * h]), "expected a mask value"),
        ("negative".into(), NpyArray::f64(vec![h, h], vec![-1.0; h * h]), "expected a mask value"),
        ("two".into(), NpyArray::f32(vec![h, h], vec![2.0; h * h]), "expected a mask value"),
        ("inf".into(), NpyArray::f64(vec![h, h], vec![f64::INFINITY; h * h]), "expected a mask value"),
        ("int_300".into(), NpyArray::i64(vec![h, h], vec![300; h * h]), "expected a mask value"),
        ("int_negative".into(), NpyArray::i64(vec![h, h], vec![-5; h * h]), "expected a mask value"),
        ("shape_3d".into(), NpyArray::f32(vec![h, h, 3], vec![1.0; h * h * 3]), "shape"),
        ("shape_small".into(), NpyArray::f32(vec![4, 4], vec![1.0; 16]), "mask is 4×4"),
        ("text".into(), NpyArray::text("mask"), "mask_0000.npy"),
    ];
    for (what, array, needle) in masks {
        let (case, data) = dataset_copy(fx, dir, &format!("masks/{what}"));
        write_npy(&data.join("masks/mask_0000.npy"), &array);
        cases.push(train_case(&format!("inputs/masks/{what}"), &case, &data, &["mask_0000.npy", needle]));
    }
    for (what, bytes) in broken_bytes(&std::fs::read(fx.data.join("masks/mask_0000.npy")).unwrap()) {
        let (case, data) = dataset_copy(fx, dir, &format!("masks/bytes_{what}"));
        std::fs::write(data.join("masks/mask_0000.npy"), bytes).unwrap();
        cases.push(train_case(&format!("inputs/masks/bytes_{what}"), &case, &data, &["mask_0000.npy"]));
    }

    // Depth maps, where the subject has them.
    if fx.data.join("depth/depth_0000.npy").exists() {
        for (what, v) in [("nan", f32::NAN), ("inf", f32::INFINITY), ("negative", -1.0)] {
            let (case, data) = dataset_copy(fx, dir, &format!("depth/{what}"));
            write_npy(&data.join("depth/depth_0000.npy"), &NpyArray::f32(vec![h, h], vec![v; h * h]));
            cases.push(train_case(
                &format!("inputs/depth/{what}"),
                &case,
                &data,
                &["depth_0000.npy", "depth"],
            ));
        }
    }

    // cameras.npz: every number of the intrinsics and extrinsics broken, and sizes past the limits.
    let cameras = fx.data.join("cameras.npz");
    let npz = Npz::read(&cameras).unwrap();
    let k = npz.get("intrinsic").unwrap().to_f64().unwrap();
    let e = npz.get("extrinsic").unwrap().to_f64().unwrap();
    // One matrix entry of every camera set to `v`.
    let mut broken_camera = |key: &str, entry: usize, name: &str, what: &str, v: f64| {
        let (values, width) = if key == "intrinsic" { (&k, 9) } else { (&e, 16) };
        let shape = npz.get(key).unwrap().shape.clone();
        let (case, data) = dataset_copy(fx, dir, &format!("cameras/{name}_{what}"));
        let mut values = values.clone();
        values.chunks_exact_mut(width).for_each(|camera| camera[entry] = v);
        npz_with(&cameras, &data.join("cameras.npz"), key, Some(NpyArray::f64(shape, values)));
        cases.push(train_case(&format!("inputs/cameras/{name}_{what}"), &case, &data, &["cameras.npz"]));
    };
    // A principal point may sit anywhere near the image (0 is a corner); a focal length may not
    // be zero, negative or a pinhole's millionth.
    for (entry, name) in [(0, "fx"), (2, "cx"), (4, "fy"), (5, "cy")] {
        let focal = entry == 0 || entry == 4;
        let extra: &[(&str, f64)] =
            if focal { &[("zero", 0.0), ("negative", -500.0), ("tiny", 1e-9)] } else { &[("far", -1e6)] };
        for (what, v) in BAD_NUMBERS.iter().chain(extra) {
            broken_camera("intrinsic", entry, name, what, *v);
        }
    }
    // A rotation entry scaled is no rotation, a last row but 0 0 0 1 no rigid motion, and a
    // translation of a thousand kilometres no room.
    for (entry, name) in [(0, "r00"), (3, "tx"), (11, "tz"), (15, "w")] {
        let rotation = entry == 0 || entry == 15;
        let extra: &[(&str, f64)] = if rotation { &[("scaled", 3.0)] } else { &[("far", 1e6)] };
        for (what, v) in BAD_NUMBERS.iter().chain(extra) {
            broken_camera("extrinsic", entry, name, what, *v);
        }
    }
    for (key, v) in [
        ("width", 0.0),
        ("width", 1e9),
        ("width", 65535.0),
        ("height", -96.0),
        ("height", f64::NAN),
        ("height", 96.5),
    ] {
        let what = format!("{key}_{v}");
        let (case, data) = dataset_copy(fx, dir, &format!("cameras/{what}"));
        npz_with(&cameras, &data.join("cameras.npz"), key, Some(NpyArray::f64(vec![], vec![v])));
        cases.push(train_case(&format!("inputs/cameras/{what}"), &case, &data, &["cameras.npz"]));
    }
    for key in ["intrinsic", "extrinsic", "width"] {
        let (case, data) = dataset_copy(fx, dir, &format!("cameras/missing_{key}"));
        npz_with(&cameras, &data.join("cameras.npz"), key, None);
        cases.push(train_case(&format!("inputs/cameras/missing_{key}"), &case, &data, &["cameras.npz", key]));
    }
    for (what, bytes) in broken_bytes(&std::fs::read(&cameras).unwrap()) {
        let (case, data) = dataset_copy(fx, dir, &format!("cameras/bytes_{what}"));
        std::fs::write(data.join("cameras.npz"), bytes).unwrap();
        cases.push(train_case(&format!("inputs/cameras/bytes_{what}"), &case, &data, &["cameras.npz"]));
    }

    // Poses: every array of the train split broken.
    let poses = train_poses(&fx.data);
    let poses_name = poses.file_name().unwrap().to_str().unwrap().to_string();
    let pnpz = Npz::read(&poses).unwrap();
    for key in ["global_orient", "body_pose", "transl", "betas"] {
        let a = pnpz.get(key).unwrap();
        let values = a.to_f64().unwrap();
        for (what, v) in BAD_NUMBERS {
            if key == "global_orient" || key == "body_pose" {
                // A finite rotation of any size is a rotation.
                if v.is_finite() {
                    continue;
                }
            }
            let (case, data) = dataset_copy(fx, dir, &format!("poses/{key}_{what}"));
            let mut broken = values.clone();
            let mid = broken.len() / 2;
            broken[mid] = v;
            let target = train_poses(&data);
            npz_with(&poses, &target, key, Some(NpyArray::f64(a.shape.clone(), broken)));
            cases.push(train_case(&format!("inputs/poses/{key}_{what}"), &case, &data, &[&poses_name, key]));
        }
        let (case, data) = dataset_copy(fx, dir, &format!("poses/{key}_missing"));
        npz_with(&poses, &train_poses(&data), key, None);
        cases.push(train_case(&format!("inputs/poses/{key}_missing"), &case, &data, &[&poses_name, key]));
        let (case, data) = dataset_copy(fx, dir, &format!("poses/{key}_text"));
        npz_with(&poses, &train_poses(&data), key, Some(NpyArray::text("zero")));
        cases.push(train_case(&format!("inputs/poses/{key}_text"), &case, &data, &[&poses_name, key]));
    }
    for (what, bytes) in broken_bytes(&std::fs::read(&poses).unwrap()) {
        let (case, data) = dataset_copy(fx, dir, &format!("poses/bytes_{what}"));
        std::fs::write(train_poses(&data), bytes).unwrap();
        cases.push(train_case(&format!("inputs/poses/bytes_{what}"), &case, &data, &[&poses_name]));
    }

    // Label maps past their legend, for the garment fit.
    let subject = crate::common::read_json(&fx.data.join("subject.json"));
    let legend: Vec<String> = subject["labels"]
        .as_array()
        .map(|l| l.iter().filter_map(|v| v.as_str().map(String::from)).collect())
        .unwrap_or_default();
    let garment = ["dress", "tshirt", "pants", "skirt"].into_iter().find(|g| legend.iter().any(|l| l == g));
    if let Some(garment) = garment.filter(|_| fx.data.join("labels/label_0000.png").exists()) {
        for value in [200u8, 255] {
            let (case, data) = dataset_copy(fx, dir, &format!("labels/value_{value}"));
            let path = data.join("labels/label_0000.png");
            let map = mannequin_data::labels::LabelMap::read_png(&path).unwrap();
            let broken = mannequin_data::labels::LabelMap { labels: vec![value; map.labels.len()], ..map };
            broken.write_png(&path).unwrap();
            let out = case.join("fit");
            cases.push(Case::refused(
                format!("inputs/labels/value_{value}"),
                &case,
                &[
                    "garment",
                    "fit",
                    "--data",
                    s(&data),
                    "--category",
                    garment,
                    "--body",
                    "default-lod1",
                    "--iters",
                    "2",
                    "--out",
                    s(&out),
                ],
                &["label_0000.png", "legend"],
            ));
        }
    }
}

/// A PNG whose header claims `w`×`h`, followed by a few bytes of image data: what a decoder
/// sees before it asks for the pixels' memory.
fn png_claiming(w: u32, h: u32) -> Vec<u8> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    let mut writer = encoder.write_header().unwrap();
    writer.write_chunk(png::chunk::IDAT, &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01]).unwrap();
    drop(writer);
    out
}

/// A JPEG of the fixture's first frame.
fn jpeg_of(path: &Path) -> Vec<u8> {
    let img = mannequin_data::Image::read(path).unwrap();
    let rgb: Vec<u8> = img.pixels.iter().flat_map(|p| p.map(mannequin_data::image::quantize)).collect();
    let mut out = Vec::new();
    jpeg_encoder::Encoder::new(&mut out, 90)
        .encode(&rgb, img.width as u16, img.height as u16, jpeg_encoder::ColorType::Rgb)
        .unwrap();
    out
}

fn image_cases(fx: &Fixtures, dir: &Path, cases: &mut Vec<Case>) {
    let first = fx.data.join("images/image_0000.png");
    let jpeg = jpeg_of(&first);
    let mut bad_images: Vec<(String, Vec<u8>, &str)> = vec![
        ("bomb_65535".into(), png_claiming(65535, 65535), "at most"),
        ("bomb_wide".into(), png_claiming(1 << 20, 1), "at most"),
        ("bomb_17k".into(), png_claiming(17000, 17000), "at most"),
        ("jpeg_cut_half".into(), jpeg[..jpeg.len() / 2].to_vec(), "JPEG"),
        ("jpeg_cut_tail".into(), jpeg[..jpeg.len() - 40].to_vec(), "JPEG"),
        ("jpeg_header_only".into(), jpeg[..jpeg.len().min(300)].to_vec(), "JPEG"),
    ];
    for (what, bytes) in broken_bytes(&std::fs::read(&first).unwrap()) {
        bad_images.push((format!("png_{what}"), bytes, "image_0000"));
    }
    for (what, bytes, needle) in &bad_images {
        // In a dataset, as `train` reads it.
        let (case, data) = dataset_copy(fx, dir, &format!("images/train_{what}"));
        std::fs::write(data.join("images/image_0000.png"), bytes).unwrap();
        cases.push(train_case(&format!("inputs/images/train_{what}"), &case, &data, &["image_0000", needle]));
        // As a photo, as `fit` reads it.
        let case = case_dir(dir, &format!("images/fit_{what}"));
        let photo = case.join("photo.png");
        std::fs::write(&photo, bytes).unwrap();
        let out = case.join("out");
        cases.push(Case::refused(
            format!("inputs/images/fit_{what}"),
            &case,
            &["fit", "--image", s(&photo), "--out", s(&out)],
            &["photo.png"],
        ));
        // As a clip's frame, as `capture` reads it.
        let case = case_dir(dir, &format!("images/capture_{what}"));
        let frames = case.join("frames");
        copy_dir(&fx.data.join("images"), &frames);
        std::fs::write(frames.join("image_0003.png"), bytes).unwrap();
        let out = case.join("out");
        cases.push(Case::refused(
            format!("inputs/images/capture_{what}"),
            &case,
            &["capture", "--frames", s(&frames), "--out", s(&out)],
            &["image_0003.png"],
        ));
    }
    // A clip whose frames differ in size is refused before anything is written.
    let case = case_dir(dir, "images/capture_mixed_sizes");
    let frames = case.join("frames");
    copy_dir(&fx.data.join("images"), &frames);
    let small = mannequin_data::Image { width: 64, height: 64, pixels: vec![[0.3; 3]; 64 * 64] };
    small.write_png(&frames.join("image_0005.png")).unwrap();
    let out = case.join("out");
    cases.push(Case::refused(
        "inputs/images/capture_mixed_sizes",
        &case,
        &["capture", "--frames", s(&frames), "--out", s(&out)],
        &["image_0005.png", "64×64"],
    ));
}

/// An AMASS motion of `frames` frames of 22 joints, with `poses`, `trans` and the rate given.
fn amass(path: &Path, poses: NpyArray, trans: NpyArray, fps: f64, betas: Option<NpyArray>) {
    let mut w = NpzWriter::new();
    w.add("poses", poses).add("trans", trans).add("mocap_framerate", NpyArray::f64(vec![], vec![fps]));
    if let Some(b) = betas {
        w.add("betas", b);
    }
    std::fs::write(path, w.to_bytes()).unwrap();
}

/// Writes a crafted file at the path given.
type WriteFile = Box<dyn Fn(&Path)>;

fn motion_cases(fx: &Fixtures, dir: &Path, cases: &mut Vec<Case>) {
    let zeros = |f: usize, w: usize| NpyArray::f32(vec![f, w], vec![0.0; f * w]);
    let good_poses = move || zeros(10, 66);
    let good_trans = move || zeros(10, 3);
    let with = |f: usize, w: usize, i: usize, v: f32| {
        let mut d = vec![0.0f32; f * w];
        d[i] = v;
        NpyArray::f32(vec![f, w], d)
    };
    let mut motions: Vec<(String, WriteFile, &str)> = vec![
        (
            "two_million_frames".into(),
            Box::new(move |p| amass(p, zeros(2_000_000, 3), zeros(2_000_000, 3), 30.0, None)),
            "poses",
        ),
        (
            "past_limit_frames".into(),
            Box::new(move |p| amass(p, zeros(100_001, 3), zeros(100_001, 3), 30.0, None)),
            "at most 100000",
        ),
        (
            "no_frames".into(),
            Box::new(move |p| amass(p, zeros(0, 66), zeros(0, 3), 30.0, None)),
            "at least one frame",
        ),
        (
            "width_4".into(),
            Box::new(move |p| amass(p, zeros(10, 4), good_trans(), 30.0, None)),
            "3 values per joint",
        ),
        ("trans_short".into(), Box::new(move |p| amass(p, good_poses(), zeros(9, 3), 30.0, None)), "trans"),
        (
            "fps_text".into(),
            Box::new(move |p| {
                let mut w = NpzWriter::new();
                w.add("poses", good_poses())
                    .add("trans", good_trans())
                    .add("mocap_framerate", NpyArray::text("fast"));
                w.write(p).unwrap();
            }),
            "mocap_framerate",
        ),
    ];
    for (what, fps) in
        [("fps_zero", 0.0), ("fps_negative", -30.0), ("fps_nan", f64::NAN), ("fps_inf", f64::INFINITY)]
    {
        motions.push((
            what.into(),
            Box::new(move |p| amass(p, good_poses(), good_trans(), fps, None)),
            "mocap_framerate",
        ));
    }
    for (what, v) in [("nan", f32::NAN), ("inf", f32::INFINITY), ("neg_inf", f32::NEG_INFINITY)] {
        motions.push((
            format!("pose_{what}"),
            Box::new(move |p| amass(p, with(10, 66, 70, v), good_trans(), 30.0, None)),
            "poses",
        ));
    }
    for (what, v) in [("nan", f32::NAN), ("inf", f32::INFINITY), ("huge", 1e30), ("far", 1e5)] {
        motions.push((
            format!("trans_{what}"),
            Box::new(move |p| amass(p, good_poses(), with(10, 3, 4, v), 30.0, None)),
            "trans",
        ));
    }
    for (what, v) in [("nan", f64::NAN), ("huge", 1e30), ("eleven", 11.0), ("neg_inf", f64::NEG_INFINITY)] {
        motions.push((
            format!("betas_{what}"),
            Box::new(move |p| {
                amass(p, good_poses(), good_trans(), 30.0, Some(NpyArray::f64(vec![3], vec![0.0, v, 0.0])))
            }),
            "betas",
        ));
    }
    for (what, bytes) in broken_bytes(&std::fs::read(&fx.motion).unwrap()) {
        motions.push((
            format!("bytes_{what}"),
            Box::new(move |p| std::fs::write(p, &bytes).unwrap()),
            "motion.npz",
        ));
    }
    for (what, make, needle) in &motions {
        let verbs: [(&str, Vec<&str>); 3] = [
            ("body_animate", vec!["body", "animate", "--body", "default-lod1", "--motion"]),
            ("export", vec!["export", "--avatar", s(&fx.model), "--animation"]),
            ("animate", vec!["animate", "--avatar", s(&fx.model), "--max-frames", "2", "--motion"]),
        ];
        for (verb, args) in verbs {
            let case = case_dir(dir, &format!("motion/{verb}_{what}"));
            let motion = case.join("motion.npz");
            make(&motion);
            let out = case.join("out");
            let out_file = case.join("out.glb");
            let mut args: Vec<&str> = args;
            match verb {
                "body_animate" => args.extend([s(&motion), "-o", s(&out_file)]),
                "export" => args.extend([s(&motion), "-o", s(&out_file)]),
                _ => args.extend([s(&motion), "-o", s(&out)]),
            }
            cases.push(Case::refused(
                format!("inputs/motion/{verb}_{what}"),
                &case,
                &args,
                &["motion.npz", needle],
            ));
        }
    }
}

fn flag_cases(fx: &Fixtures, dir: &Path, cases: &mut Vec<Case>) {
    // --betas: values no body has, on every verb that takes them.
    for (what, value) in [
        ("1e6", "1e6"),
        ("1e30", "1e30"),
        ("nan", "NaN"),
        ("inf", "inf"),
        ("minus_11", "-11"),
        ("text", "tall"),
    ] {
        let verbs: [(&str, Vec<&str>); 3] = [
            ("body_pose", vec!["body", "pose", "--body", "default-lod1", "--named-pose", "t-pose", "-o"]),
            (
                "garment_make",
                vec!["garment", "make", "--category", "tshirt", "--body", "default-lod1", "--out"],
            ),
            (
                "body_animate",
                vec!["body", "animate", "--body", "default-lod1", "--motion", s(&fx.motion), "-o"],
            ),
        ];
        for (verb, args) in verbs {
            let case = case_dir(dir, &format!("flags/betas_{verb}_{what}"));
            let out = case.join(if verb == "garment_make" {
                "t.garment"
            } else if verb == "body_pose" {
                "out.obj"
            } else {
                "out.glb"
            });
            let mut args = args;
            args.extend([s(&out), "--betas", value]);
            cases.push(Case::usage(format!("inputs/flags/betas_{verb}_{what}"), &case, &args, &["--betas"]));
        }
    }
    // --focal: lengths no camera has.
    let photo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mannequin-fit/tests/data/camera.png");
    for (what, value) in [("1e30", "1e30"), ("tiny", "1e-5"), ("one", "1"), ("1e7", "1e7")] {
        let case = case_dir(dir, &format!("flags/focal_{what}"));
        let out = case.join("out");
        cases.push(Case::refused(
            format!("inputs/flags/focal_{what}"),
            &case,
            &["fit", "--image", s(&photo), "--focal", value, "--out", s(&out)],
            &["--focal", "expected"],
        ));
    }
    for (what, value) in [("nan", "NaN"), ("inf", "inf"), ("zero", "0"), ("negative", "-500")] {
        let case = case_dir(dir, &format!("flags/focal_{what}"));
        let out = case.join("out");
        let focal = format!("--focal={value}");
        cases.push(Case::refused(
            format!("inputs/flags/focal_{what}"),
            &case,
            &["fit", "--image", s(&photo), &focal, "--out", s(&out)],
            &["--focal"],
        ));
    }
    // Camera JSON files: sizes and numbers no camera has, for `render` and `splat render`.
    let good = serde_json::json!({
        "width": 96, "height": 96,
        "intrinsic": [[100.0, 0.0, 48.0], [0.0, 100.0, 48.0], [0.0, 0.0, 1.0]],
        "extrinsic": [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 1.0], [0.0, 0.0, -1.0, 3.0], [0.0, 0.0, 0.0, 1.0]],
    });
    let mut cameras: Vec<(String, serde_json::Value)> = Vec::new();
    for (w, h) in [(32768, 32768), (16384, 16384), (5000, 5000), (100000, 10)] {
        let mut c = good.clone();
        c["width"] = w.into();
        c["height"] = h.into();
        c["intrinsic"][0][2] = (w / 2).into();
        c["intrinsic"][1][2] = (h / 2).into();
        c["intrinsic"][0][0] = (w as f64).into();
        c["intrinsic"][1][1] = (w as f64).into();
        cameras.push((format!("size_{w}x{h}"), c));
    }
    for (what, v) in [("fx_1e300", 1e300), ("fx_tiny", 1e-6), ("fx_zero", 0.0), ("fx_negative", -100.0)] {
        let mut c = good.clone();
        c["intrinsic"][0][0] = v.into();
        cameras.push((what.into(), c));
    }
    for (what, v) in [("cx_far", -1e9), ("cx_1e300", 1e300)] {
        let mut c = good.clone();
        c["intrinsic"][0][2] = v.into();
        cameras.push((what.into(), c));
    }
    for (what, v) in [("tz_far", 1e7), ("r_scaled", 2.0)] {
        let mut c = good.clone();
        if what == "tz_far" {
            c["extrinsic"][2][3] = v.into();
        } else {
            c["extrinsic"][0][0] = v.into();
        }
        cameras.push((what.into(), c));
    }
    let mut no_width = good.clone();
    no_width.as_object_mut().unwrap().remove("width");
    cameras.push(("no_width".into(), no_width));
    for (what, camera) in &cameras {
        let case = case_dir(dir, &format!("camera/{what}"));
        let path = case.join("cam.json");
        std::fs::write(&path, serde_json::to_vec(camera).unwrap()).unwrap();
        let out = case.join("out.png");
        cases.push(Case::refused(
            format!("inputs/camera/render_{what}"),
            &case,
            &[
                "render",
                "--avatar",
                s(&fx.model),
                "--named-pose",
                "a-pose",
                "--camera",
                s(&path),
                "-o",
                s(&out),
            ],
            &["cam.json"],
        ));
    }
}

/// Body models as `--body FILE`: header bombs, sizes past the limits, broken bytes.
fn model_cases(dir: &Path, cases: &mut Vec<Case>) {
    // Headers with no data after them, as a crafted file sends them.
    let header = |shape: Vec<usize>, data: NpyData| mannequin_io::npy::write_npy(&NpyArray { shape, data });
    let bombs = [
        ("v_template_200m", header(vec![200_000_000, 3], NpyData::F32(vec![]))),
        ("shapedirs_huge", header(vec![6890, 3, 100_000], NpyData::F64(vec![]))),
        ("weights_overflow", header(vec![1 << 62, 4], NpyData::F64(vec![]))),
    ];
    for (what, member) in bombs {
        let case = case_dir(dir, &format!("model/{what}"));
        let path = case.join("model.npz");
        let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let key = what.split('_').next().unwrap();
        zip.start_file(format!("{key}.npy"), zip::write::SimpleFileOptions::default()).unwrap();
        std::io::Write::write_all(&mut zip, &member).unwrap();
        std::fs::write(&path, zip.finish().unwrap().into_inner()).unwrap();
        cases.push(Case::refused(
            format!("inputs/model/{what}"),
            &case,
            &["body", "info", "--body", s(&path)],
            &["model.npz", key],
        ));
    }
    // Two arrays each within the limit that together are past the archive's.
    let case = case_dir(dir, "model/archive_total");
    let path = case.join("model.npz");
    let n = mannequin_io::limits::MAX_ARRAY_ELEMENTS;
    let mut w = NpzWriter::new();
    w.add("a", NpyArray { shape: vec![n], data: NpyData::U8(vec![0; n]) });
    w.add("b", NpyArray { shape: vec![n], data: NpyData::U8(vec![0; n]) });
    w.add("c", NpyArray { shape: vec![n], data: NpyData::U8(vec![0; n]) });
    w.write(&path).unwrap();
    cases.push(Case::refused(
        "inputs/model/archive_total",
        &case,
        &["body", "info", "--body", s(&path)],
        &["model.npz", "in all"],
    ));
}

/// Files `view` would serve: each must parse before the server starts.
fn view_cases(fx: &Fixtures, dir: &Path, cases: &mut Vec<Case>) {
    let glb_path = fx.root.join("view_good.glb");
    if !glb_path.exists() {
        crate::common::ok(crate::common::mannequin(&[
            "body",
            "pose",
            "--body",
            "default-lod1",
            "--named-pose",
            "t-pose",
            "-o",
            s(&fx.root.join("view_good.obj")),
        ]));
        crate::common::ok(crate::common::mannequin(&[
            "body",
            "animate",
            "--body",
            "default-lod1",
            "--motion",
            s(&fx.motion),
            "--max-frames",
            "2",
            "-o",
            s(&glb_path),
        ]));
    }
    let good = std::fs::read(&glb_path).unwrap();
    let mut samples = broken_bytes(&good);
    let mut long = good.clone();
    long.extend_from_slice(&[0u8; 16]);
    samples.push(("trailing".into(), long));
    let mut bad_json = good.clone();
    bad_json[20] = b'!';
    samples.push(("json".into(), bad_json));
    for (what, bytes) in samples {
        for ext in ["glb", "ply"] {
            if ext == "ply" && what == "json" {
                continue;
            }
            let case = case_dir(dir, &format!("view/{ext}_{what}"));
            let path = case.join(format!("scene.{ext}"));
            std::fs::write(&path, &bytes).unwrap();
            cases.push(Case::refused(
                format!("inputs/view/{ext}_{what}"),
                &case,
                &["view", s(&path), "--port", "0"],
                &[&format!("scene.{ext}")],
            ));
        }
    }
}
