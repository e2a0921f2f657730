//! Writer → reader round trips of the dataset layout, and the errors a broken folder gives.

use std::path::{Path, PathBuf};

use mannequin_data::{
    Camera, Cameras, Dataset, DatasetWriter, DepthMap, Frame, Image, Mask, NormalMap, Poses, SplitRange,
    Splits,
};
use mannequin_mesh::TriMesh;

const W: usize = 12;
const H: usize = 8;
const FRAMES: usize = 5;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mq-data-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A pseudo-random but reproducible value in [0, 1) for each (frame, pixel, channel).
fn hash01(a: usize, b: usize, c: usize) -> f32 {
    let mut x = (a as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (b as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9)
        ^ c as u64;
    x ^= x >> 31;
    x = x.wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 29;
    (x >> 40) as f32 / (1u64 << 24) as f32
}

fn frame(i: usize) -> Frame {
    let mask = Mask { width: W, height: H, values: (0..W * H).map(|p| hash01(i, p, 7) > 0.4).collect() };
    let image = Image {
        width: W,
        height: H,
        pixels: (0..W * H).map(|p| [0, 1, 2].map(|c| hash01(i, p, c))).collect(),
    };
    let normals = (0..W * H)
        .map(|p| {
            if !mask.values[p] {
                return [0.0; 3];
            }
            let v = glam::Vec3::new(hash01(i, p, 3) - 0.5, hash01(i, p, 4) - 0.5, -0.6).normalize();
            v.to_array()
        })
        .collect();
    let depth = (0..W * H).map(|p| if mask.values[p] { 2.0 + hash01(i, p, 5) } else { 0.0 }).collect();
    Frame {
        index: i,
        image,
        mask,
        normals: Some(NormalMap { width: W, height: H, normals }),
        depth: Some(DepthMap { width: W, height: H, depth }),
    }
}

fn poses(n: usize, seed: usize) -> Poses {
    Poses {
        betas: (0..10).map(|k| hash01(seed, k, 9) - 0.5).collect(),
        global_orient: (0..n).map(|f| [0, 1, 2].map(|c| hash01(seed, f, 10 + c))).collect(),
        body_pose: (0..n * 69).map(|k| hash01(seed, k, 20) - 0.5).collect(),
        transl: (0..n).map(|f| [0, 1, 2].map(|c| hash01(seed, f, 30 + c))).collect(),
    }
}

fn camera() -> Camera {
    let mut c = Camera::look_at([0.2, 1.1, 3.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], 0.9, W, H);
    c.intrinsic[0][2] += 0.25;
    c
}

fn splits() -> Splits {
    [("train".to_string(), SplitRange::new(0, 4, 2)), ("test".to_string(), SplitRange::new(1, 3, 2))].into()
}

fn write_dataset(root: &Path) {
    let w = DatasetWriter::new(root);
    w.write_cameras(&Cameras::Static(camera())).unwrap();
    w.write_splits(&splits()).unwrap();
    w.write_poses("train", &poses(3, 1)).unwrap();
    w.write_poses("test", &poses(2, 2)).unwrap();
    for i in 0..FRAMES {
        w.write_frame(&frame(i)).unwrap();
        let mut mesh =
            TriMesh::new(vec![[0.0, 0.0, i as f32], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]], vec![[0, 1, 2]]);
        mesh.colors = Some(vec![[1.0, 0.0, 0.0]; 3]);
        w.write_mesh(i, &mesh).unwrap();
    }
}

#[test]
fn writer_then_reader_gives_identical_arrays() {
    let root = temp_dir("roundtrip");
    write_dataset(&root);
    let ds = Dataset::open(&root, 1).unwrap();
    assert_eq!(ds.frame_count, FRAMES);
    assert_eq!(ds.cameras, Cameras::Static(camera()));
    assert_eq!(ds.splits, splits());
    let train = ds.split("train").unwrap();
    assert_eq!(train.frames, vec![0, 2, 4]);
    assert_eq!(train.poses, poses(3, 1));
    assert_eq!(ds.split("test").unwrap().poses, poses(2, 2));
    assert!(ds.has_normals && ds.has_depth && ds.has_meshes);
    for i in 0..FRAMES {
        let want = frame(i);
        let got = ds.frame(i).unwrap();
        assert_eq!(got.image, want.image.quantized());
        assert_eq!(got.mask, want.mask);
        assert_eq!(got.depth, want.depth);
        // Normals go through 8 bits: same background, and within half a step per channel.
        let (gn, wn) = (got.normals.unwrap(), want.normals.unwrap());
        assert_eq!(gn.mask(), want.mask);
        for (a, b) in gn.normals.iter().zip(&wn.normals) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 1.5 / 255.0, "{a:?} vs {b:?}");
            }
        }
        let mesh = ds.mesh(i).unwrap().unwrap().mesh;
        assert_eq!(mesh.positions[0], [0.0, 0.0, i as f32]);
    }
    // A second write of what was read gives the same bytes.
    let again = temp_dir("roundtrip-again");
    let w = DatasetWriter::new(&again);
    let f = ds.frame(3).unwrap();
    w.write_frame(&f).unwrap();
    for rel in
        ["images/image_0003.png", "masks/mask_0003.npy", "normals/normal_0003.png", "depth/depth_0003.npy"]
    {
        assert_eq!(std::fs::read(root.join(rel)).unwrap(), std::fs::read(again.join(rel)).unwrap(), "{rel}");
    }
    std::fs::remove_dir_all(root).unwrap();
    std::fs::remove_dir_all(again).unwrap();
}

#[test]
fn downscale_halves_images_and_intrinsics() {
    let root = temp_dir("downscale");
    write_dataset(&root);
    let ds = Dataset::open(&root, 2).unwrap();
    let cam = ds.camera(0);
    let native = camera();
    assert_eq!((cam.width, cam.height), (W / 2, H / 2));
    for (r, c) in [(0, 0), (1, 1), (0, 2), (1, 2)] {
        assert_eq!(cam.intrinsic[r][c], native.intrinsic[r][c] / 2.0);
    }
    assert_eq!(cam.extrinsic, native.extrinsic);
    let f = ds.frame(1).unwrap();
    let full = frame(1).image.quantized();
    assert_eq!((f.image.width, f.image.height, f.mask.width), (W / 2, H / 2, W / 2));
    let block = [full.at(2, 4), full.at(3, 4), full.at(2, 5), full.at(3, 5)];
    for c in 0..3 {
        let mean = block.iter().map(|p| p[c]).sum::<f32>() / 4.0;
        assert!((f.image.at(1, 2)[c] - mean).abs() < 1e-6);
    }
    std::fs::remove_dir_all(root).unwrap();
}

fn open_err(root: &Path) -> String {
    Dataset::open(root, 1).err().map(|e| e.to_string()).unwrap_or_default()
}

#[test]
fn broken_folders_name_the_file() {
    let root = temp_dir("broken");
    write_dataset(&root);
    std::fs::remove_file(root.join("images/image_0002.png")).unwrap();
    let msg = open_err(&root);
    assert!(msg.contains("image_0002.png") && msg.contains("missing frame"), "{msg}");
    DatasetWriter::new(&root).write_frame(&frame(2)).unwrap();

    std::fs::remove_file(root.join("masks/mask_0004.npy")).unwrap();
    let msg = open_err(&root);
    assert!(msg.contains("mask_0004.npy"), "{msg}");
    DatasetWriter::new(&root).write_frame(&frame(4)).unwrap();

    // A split that reaches past the last image.
    let w = DatasetWriter::new(&root);
    w.write_splits(&[("train".to_string(), SplitRange::new(0, 8, 2))].into()).unwrap();
    let msg = open_err(&root);
    assert!(msg.contains("image_0008.png") && msg.contains("'train'"), "{msg}");
    w.write_splits(&splits()).unwrap();

    // Pose counts that disagree with the split.
    w.write_poses("test", &poses(3, 2)).unwrap();
    let msg = Dataset::open(&root, 1).unwrap().split("test").unwrap_err().to_string();
    assert!(
        msg.contains("anim_nerf_test.npz") && msg.contains("3 poses") && msg.contains("2 frames"),
        "{msg}"
    );

    // A mask of the wrong size.
    let mut bad = frame(1);
    bad.mask = Mask { width: W + 1, height: H, values: vec![true; (W + 1) * H] };
    w.write_frame(&bad).unwrap();
    let msg = Dataset::open(&root, 1).unwrap().frame(1).unwrap_err().to_string();
    assert!(msg.contains("mask_0001.npy") && msg.contains("13×8"), "{msg}");
    std::fs::remove_dir_all(root).unwrap();
}

#[test]
fn per_frame_cameras_round_trip() {
    let root = temp_dir("perframe");
    write_dataset(&root);
    let cams: Vec<Camera> = (0..FRAMES)
        .map(|i| Camera::look_at([i as f64, 1.0, 3.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], 0.8, W, H))
        .collect();
    DatasetWriter::new(&root).write_cameras(&Cameras::PerFrame(cams.clone())).unwrap();
    let ds = Dataset::open(&root, 1).unwrap();
    assert_eq!(ds.cameras, Cameras::PerFrame(cams[..].to_vec()));
    DatasetWriter::new(&root).write_cameras(&Cameras::PerFrame(cams[..3].to_vec())).unwrap();
    let msg = open_err(&root);
    assert!(msg.contains("cameras.npz") && msg.contains("3 per-frame cameras"), "{msg}");
    std::fs::remove_dir_all(root).unwrap();
}
