//! The shipped person models, run by tract in Rust, held to MediaPipe's own TFLite runtime: the
//! golden fixtures in `tests/data` were made by `tools/person_models/convert.py fixtures` with
//! the original `.tflite` files (network by network on fixed inputs) and with MediaPipe's whole
//! pose pipeline on the two pictures.

use std::path::PathBuf;
use std::sync::OnceLock;

use mannequin_data::Image;
use mannequin_fit::{FaceModels, PersonModels};
use mannequin_io::Npz;

const PICTURES: [&str; 2] = ["astronaut", "camera"];

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn models() -> &'static PersonModels {
    static MODELS: OnceLock<PersonModels> = OnceLock::new();
    MODELS.get_or_init(|| PersonModels::load().unwrap())
}

fn array(npz: &Npz, key: &str) -> Vec<f32> {
    npz.require(key).unwrap().to_f32().unwrap()
}

fn max_diff(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max)
}

/// Runs `network` on a fixture's `input_u8` mapped by `scale`, `offset`; its outputs by name.
fn run(
    network: &mannequin_fit::network::Network,
    npz: &Npz,
    scale: f32,
    offset: f32,
) -> Vec<(usize, Vec<f32>)> {
    let input = array(npz, "input_u8").iter().map(|v| v * scale + offset).collect();
    network.run(input).unwrap().into_iter().map(|o| o.values).enumerate().collect()
}

#[test]
fn the_detector_matches_tflite() {
    let net = &models().detector;
    for picture in PICTURES {
        let npz = Npz::read(data(&format!("detection_{picture}.npz"))).unwrap();
        let out = run(net, &npz, 1.0 / 127.5, -1.0);
        for key in ["regressors", "scores"] {
            let got = &out[net.output_index(key).unwrap()].1;
            let d = max_diff(got, &array(&npz, key));
            // Regressors are in detector-input pixels; the runtimes' float sums differ by ~1e-3.
            assert!(d < 5e-3, "{picture} {key}: max difference {d}");
        }
    }
}

#[test]
fn the_landmarker_matches_tflite() {
    let net = &models().landmarker;
    for picture in PICTURES {
        let npz = Npz::read(data(&format!("landmark_{picture}.npz"))).unwrap();
        let out = run(net, &npz, 1.0 / 255.0, 0.0);
        let get = |k: &str| &out[net.output_index(k).unwrap()].1;
        let d = max_diff(get("landmarks"), &array(&npz, "landmarks"));
        assert!(d < 5e-3, "{picture} landmarks (crop pixels): {d}");
        let d = max_diff(get("world_landmarks"), &array(&npz, "world_landmarks"));
        assert!(d < 1e-4, "{picture} world landmarks (metres): {d}");
        let d = max_diff(get("pose_flag"), &array(&npz, "pose_flag"));
        assert!(d < 1e-4, "{picture} pose flag: {d}");
        // The mask is logits up to ±1700: compare probabilities.
        let sig = |v: &[f32]| v.iter().map(|x| 1.0 / (1.0 + (-x).exp())).collect::<Vec<_>>();
        let d = max_diff(&sig(get("mask")), &sig(&array(&npz, "mask")));
        println!("{picture}: mask probabilities differ by at most {d}");
        assert!(d < 5e-3, "{picture} mask: {d}");
    }
}

#[test]
fn the_segmenter_matches_mediapipe() {
    let net = &models().segmenter;
    for picture in PICTURES {
        let npz = Npz::read(data(&format!("selfie_{picture}.npz"))).unwrap();
        let out = run(net, &npz, 1.0 / 255.0, 0.0);
        let d = max_diff(&out[net.output_index("mask").unwrap()].1, &array(&npz, "mask"));
        assert!(d < 1e-4, "{picture} selfie mask: {d}");
    }
}

#[test]
fn the_whole_pipeline_finds_mediapipes_landmarks() {
    for picture in PICTURES {
        let npz = Npz::read(data(&format!("pipeline_{picture}.npz"))).unwrap();
        assert_eq!(array(&npz, "found"), [1.0], "the fixture found a person in {picture}");
        let image = Image::read(&data(&format!("{picture}.png"))).unwrap();
        let people = models().people(&image, None).unwrap();
        assert!(!people.is_empty(), "{picture}: nobody found");
        let p = &people[0].landmarks;
        let want = array(&npz, "landmarks_px");
        let roi = array(&npz, "roi");
        let w = image.width as f32;
        let crop_d =
            [p.roi.cx - roi[0] * w, p.roi.cy - roi[1] * w, p.roi.width - roi[2] * w, p.roi.rotation - roi[4]];
        println!("{picture}: crop centre, side, rotation differ by {crop_d:?}");
        assert!(crop_d[..3].iter().all(|d| d.abs() < 2.0), "{picture} crop {:?} vs {roi:?}", p.roi);
        assert!(crop_d[3].abs() < 2e-3, "{picture} crop rotation");
        let mut worst = (0.0f32, 0);
        for (i, got) in p.points.iter().enumerate() {
            let e = (got[0] - want[5 * i]).hypot(got[1] - want[5 * i + 1]);
            if e > worst.0 {
                worst = (e, i);
            }
            assert!((p.visibility[i] - want[5 * i + 3]).abs() < 0.02, "{picture} landmark {i} visibility");
        }
        println!("{picture}: worst landmark {} off by {:.3} px", worst.1, worst.0);
        assert!(worst.0 < 0.75, "{picture}: landmark {} is {:.2} px from MediaPipe's", worst.1, worst.0);
        let world = array(&npz, "world_landmarks");
        let flat: Vec<f32> = p.world.iter().flatten().copied().collect();
        let d = max_diff(&flat, &world);
        assert!(d < 5e-3, "{picture} world landmarks: {d} m");
        let seg = array(&npz, "segmentation");
        let mean = p.mask.iter().zip(&seg).map(|(a, b)| (a - b).abs()).sum::<f32>() / seg.len() as f32;
        assert!(mean < 5e-3, "{picture} mask: mean difference {mean}");
    }
}

fn face_models() -> &'static FaceModels {
    static MODELS: OnceLock<FaceModels> = OnceLock::new();
    MODELS.get_or_init(|| FaceModels::load().unwrap())
}

#[test]
fn the_face_networks_match_tflite() {
    let (detector, landmarker) = (&face_models().detector, &face_models().landmarker);
    for picture in PICTURES {
        let npz = Npz::read(data(&format!("face_detection_{picture}.npz"))).unwrap();
        let out = run(detector, &npz, 1.0 / 127.5, -1.0);
        for key in ["regressors", "scores"] {
            let d = max_diff(&out[detector.output_index(key).unwrap()].1, &array(&npz, key));
            assert!(d < 2e-3, "{picture} face {key}: max difference {d}");
        }
        let npz = Npz::read(data(&format!("face_landmark_{picture}.npz"))).unwrap();
        let out = run(landmarker, &npz, 1.0 / 255.0, 0.0);
        for key in ["landmarks", "face_flag"] {
            let d = max_diff(&out[landmarker.output_index(key).unwrap()].1, &array(&npz, key));
            assert!(d < 2e-3, "{picture} face {key}: max difference {d}");
        }
    }
}

#[test]
fn the_face_pipeline_finds_mediapipes_face_mesh() {
    for picture in PICTURES {
        let npz = Npz::read(data(&format!("face_pipeline_{picture}.npz"))).unwrap();
        assert_eq!(array(&npz, "found"), [1.0], "the fixture found a face in {picture}");
        let image = Image::read(&data(&format!("{picture}.png"))).unwrap();
        let faces = face_models().faces(&image).unwrap();
        assert!(!faces.is_empty(), "{picture}: no face found");
        let (w, h) = (image.width as f32, image.height as f32);
        let d = &faces[0].detection;
        let want = array(&npz, "detection");
        let got = [d.bbox[0] / w, d.bbox[1] / h, (d.bbox[2] - d.bbox[0]) / w, (d.bbox[3] - d.bbox[1]) / h];
        let box_d = max_diff(&got, &want[1..5]);
        let keys: Vec<f32> = d.keypoints.iter().flat_map(|k| [k[0] / w, k[1] / h]).collect();
        let key_d = max_diff(&keys, &want[5..]);
        println!("{picture}: face box off by {box_d}, keypoints by {key_d} (of the picture)");
        assert!(box_d < 1e-3 && key_d < 1e-3, "{picture}: detection {got:?} {keys:?} vs {want:?}");
        let face = &faces[0].landmarks;
        let roi = array(&npz, "roi");
        let crop_d = [
            face.roi.cx - roi[0] * w,
            face.roi.cy - roi[1] * h,
            face.roi.width - roi[2] * w,
            face.roi.rotation - roi[4],
        ];
        println!("{picture}: face crop centre, side, rotation differ by {crop_d:?}");
        assert!(crop_d[..3].iter().all(|d| d.abs() < 0.01), "{picture} face crop {:?} vs {roi:?}", face.roi);
        assert!(crop_d[3].abs() < 2e-3, "{picture} face crop rotation");
        let want = array(&npz, "landmarks_px");
        let (mut worst, mut depth) = ((0.0f32, 0), 0.0f32);
        for (i, got) in face.points.iter().enumerate() {
            let e = (got[0] - want[3 * i]).hypot(got[1] - want[3 * i + 1]);
            if e > worst.0 {
                worst = (e, i);
            }
            depth = depth.max((got[2] - want[3 * i + 2]).abs());
        }
        println!("{picture}: worst face point {} off by {:.3} px, depth by {depth:.3}", worst.1, worst.0);
        assert!(worst.0 < 0.05, "{picture}: face point {} is {:.3} px from MediaPipe's", worst.1, worst.0);
        assert!(depth < 0.05, "{picture}: face depth off by {depth}");
    }
}

/// MediaPipe's face tracking over a moving window of `astronaut.png`: each frame after the first
/// is read in the crop the previous frame's landmarks made, and both the crops and the points
/// match the original graph's. A difference carries from crop to crop: 0.0006 px on the first
/// frame, 0.05 px by the eighth.
#[test]
fn face_tracking_follows_mediapipes_crops() {
    let npz = Npz::read(data("face_track_astronaut.npz")).unwrap();
    let photo = Image::read(&data("astronaut.png")).unwrap();
    let n = array(&npz, "window")[0] as usize;
    let (offsets, landmarks, rois) =
        (array(&npz, "offsets"), array(&npz, "landmarks_px"), array(&npz, "next_roi_px"));
    let mut previous = None;
    for (k, offset) in offsets.chunks_exact(2).enumerate() {
        let (x0, y0) = (offset[0] as usize, offset[1] as usize);
        let pixels =
            (0..n).flat_map(|y| (0..n).map(move |x| (x, y))).map(|(x, y)| photo.at(x0 + x, y0 + y)).collect();
        let frame = Image { width: n, height: n, pixels };
        let face = face_models().track(&frame, previous).unwrap().expect("a face in every frame");
        let want = &landmarks[k * 468 * 3..(k + 1) * 468 * 3];
        let worst = face
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| (p[0] - want[3 * i]).hypot(p[1] - want[3 * i + 1]))
            .fold(0.0, f32::max);
        let roi = face.next_roi();
        let got = [roi.cx, roi.cy, roi.width, roi.height, roi.rotation];
        let crop_d = max_diff(&got, &rois[k * 5..k * 5 + 5]);
        println!("frame {k}: points within {worst} px, next crop within {crop_d}");
        assert!(worst < 0.1, "frame {k}: a point is {worst} px from MediaPipe's");
        assert!(crop_d < 0.1, "frame {k}: next crop {got:?} vs {:?}", &rois[k * 5..k * 5 + 5]);
        previous = Some(roi);
    }
}
