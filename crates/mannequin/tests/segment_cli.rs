//! `mannequin segment` as a user runs it (issue 37): garment labels from a dataset's images,
//! person masks and poses alone, held to the synthetic generator's true label maps; the outfit
//! `--garments auto` decides; `capture` labelling its own dataset, so that `train --garments auto`
//! runs on a person's own frames and exports the garment layers; and the inputs refused in one
//! line with nothing written.

use std::path::{Path, PathBuf};

use mannequin_data::labels::LabelMap;

mod common;
use common::{copy_dir, mannequin, ok, one_line_error, read_json, s, scratch};

/// Frames of the test subjects: with fewer, the turn is so fast that the simulated T-shirt rides
/// up the chest.
const FRAMES: usize = 24;

/// A synthetic subject of seed `seed` at 160², [`FRAMES`] frames.
fn subject(dir: &Path, seed: &str) -> PathBuf {
    let data = dir.join(format!("truth-{seed}"));
    ok(mannequin(&[
        "synth",
        "--no-self-collision",
        "--seed",
        seed,
        "--size",
        "160",
        "--frames",
        &FRAMES.to_string(),
        "--train",
        &(FRAMES - 4).to_string(),
        "--out",
        s(&data),
    ]));
    data
}

/// What a user has of `truth`: images, person masks, cameras and poses (no labels, no normals).
fn user_copy(truth: &Path, out: &Path) {
    for name in ["images", "masks", "poses"] {
        copy_dir(&truth.join(name), &out.join(name));
    }
    for name in ["cameras.npz", "splits.json"] {
        std::fs::copy(truth.join(name), out.join(name)).unwrap();
    }
}

fn legend(data: &Path) -> Vec<String> {
    read_json(&data.join("subject.json"))["labels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect()
}

/// The intersection over union, over all frames, of the pixels labelled `name` in both datasets.
fn iou(truth: &Path, estimate: &Path, name: &str) -> f64 {
    let index = |data: &Path| legend(data).iter().position(|n| n == name).unwrap() as u8;
    let (a, b) = (index(truth), index(estimate));
    let (mut inter, mut union) = (0usize, 0usize);
    for frame in 0..FRAMES {
        let file = format!("labels/label_{frame:04}.png");
        let t = LabelMap::read_png(&truth.join(&file)).unwrap();
        let e = LabelMap::read_png(&estimate.join(&file)).unwrap();
        for (&x, &y) in t.labels.iter().zip(&e.labels) {
            inter += usize::from(x == a && y == b);
            union += usize::from(x == a || y == b);
        }
    }
    inter as f64 / union as f64
}

#[test]
fn segment_finds_the_garments_a_subject_wears() {
    let dir = scratch("segment_outfits");
    // Seed 3 wears a skirt under a T-shirt, seed 1 a dress.
    for (seed, garments) in [("3", vec!["skirt", "tshirt"]), ("1", vec!["dress"])] {
        let truth = subject(&dir, seed);
        let data = dir.join(format!("user-{seed}"));
        user_copy(&truth, &data);
        let out = ok(mannequin(&["segment", "--data", s(&data)]));
        let log = String::from_utf8_lossy(&out.stderr);
        assert!(log.contains(&format!("decided {}", garments.join(" + "))), "{log}");
        assert_eq!(legend(&data)[4..], garments[..]);
        for g in &garments {
            let v = iou(&truth, &data, g);
            // 0.81–0.96 here at 160²; the 0.85 is held at 540² by the garments_from_images bench.
            assert!(v > 0.75, "seed {seed}, {g}: label IoU {v:.3}");
        }
        // The hands are skin where the fitted body's hands are drawn.
        let hands = mannequin_data::maps::read_mask_npy(&data.join("hands/hand_0000.npy")).unwrap();
        assert!(hands.count() > 0);
        let record = read_json(&data.join("labels/segmentation.json"));
        assert_eq!(record["result"]["frames"], FRAMES);

        // Label maps already there are not overwritten unless asked.
        let before = std::fs::read(data.join("labels/label_0000.png")).unwrap();
        one_line_error(&mannequin(&["segment", "--data", s(&data)]), &["labels", "--replace"]);
        assert_eq!(std::fs::read(data.join("labels/label_0000.png")).unwrap(), before);
        // A named outfit overrides the decision.
        if seed == "3" {
            ok(mannequin(&[
                "segment",
                "--data",
                s(&data),
                "--replace",
                "--garments",
                "upper:shirt,lower:skirt",
            ]));
            assert_eq!(legend(&data)[4..], ["skirt", "shirt"]);
        }
    }
}

#[test]
fn bad_segmentation_input_is_refused_in_one_line_and_nothing_is_written() {
    let dir = scratch("segment_refusals");
    let truth = subject(&dir, "2");
    let data = dir.join("user");
    user_copy(&truth, &data);
    let nothing_written = |data: &Path| {
        assert!(!data.join("labels").exists() && !data.join("hands").exists());
        assert!(!data.join("subject.json").exists());
    };
    // An outfit that is no outfit.
    for spec in ["upper:cape,lower:pants", "tshirt", "pants,skirt"] {
        one_line_error(&mannequin(&["segment", "--data", s(&data), "--garments", spec]), &["--garments"]);
        nothing_written(&data);
    }
    // No person masks.
    let unmasked = dir.join("unmasked");
    user_copy(&truth, &unmasked);
    std::fs::remove_dir_all(unmasked.join("masks")).unwrap();
    one_line_error(&mannequin(&["segment", "--data", s(&unmasked)]), &["unmasked", "masks"]);
    nothing_written(&unmasked);

    // The label maps garment fit reads: a legend naming no category, and a map of the wrong size.
    ok(mannequin(&["segment", "--data", s(&data)]));
    let fit = |data: &Path| {
        mannequin(&[
            "garment",
            "fit",
            "--data",
            s(data),
            "--category",
            "tshirt",
            "--iters",
            "1",
            "--out",
            s(&dir.join("fit")),
        ])
    };
    let subject_json = data.join("subject.json");
    let good = std::fs::read(&subject_json).unwrap();
    let mut json = read_json(&subject_json);
    json["labels"][4] = "cape".into();
    std::fs::write(&subject_json, json.to_string()).unwrap();
    one_line_error(&fit(&data), &["subject.json", "labels[4]", "'cape'"]);
    std::fs::write(&subject_json, good).unwrap();
    let label = data.join("labels/label_0003.png");
    LabelMap { width: 7, height: 5, labels: vec![0; 35] }.write_png(&label).unwrap();
    one_line_error(&fit(&data), &["label_0003.png", "7×5"]);
    assert!(!dir.join("fit").exists());
}

#[test]
fn a_captured_dataset_is_labelled_and_trains_with_its_garments() {
    let dir = scratch("segment_capture");
    let truth = subject(&dir, "2");
    let frames = dir.join("frames");
    copy_dir(&truth.join("images"), &frames);
    let data = dir.join("captured");
    ok(mannequin(&["capture", "--frames", s(&frames), "--out", s(&data)]));
    // Seed 2 wears pants under a T-shirt; from the images alone the labels still find them.
    assert_eq!(legend(&data)[4..], ["pants", "tshirt"]);
    for g in ["pants", "tshirt"] {
        let v = iou(&truth, &data, g);
        assert!(v > 0.7, "{g}: label IoU {v:.3} from the images alone");
    }
    let model = dir.join("model");
    let out = ok(mannequin(&[
        "train",
        "--data",
        s(&data),
        "--out",
        s(&model),
        "--garments",
        "auto",
        "--iters",
        "2",
        "--garment-iters",
        "6",
    ]));
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(log.contains("fitting the label maps alone"), "{log}");
    let obj = dir.join("avatar.obj");
    ok(mannequin(&["export", "--avatar", s(&model), "-o", s(&obj)]));
    for g in ["pants", "tshirt"] {
        let layer = mannequin_mesh::read_obj(dir.join(format!("avatar.{g}.obj"))).unwrap();
        assert!(layer.faces.len() > 100, "{g}");
    }
}
