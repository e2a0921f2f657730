//! JPEG frames: a dataset and an evaluation folder whose images are `.jpg` read as their PNG
//! twins do, within JPEG's error; files are decoded by content, and a folder that mixes
//! extensions, an image that is neither format, or a JPEG normal map is an error naming the file.

use std::path::{Path, PathBuf};

use mannequin_data::evaluation::{EvalOptions, evaluate};
use mannequin_data::image::quantize;
use mannequin_data::{Camera, Cameras, Dataset, DatasetWriter, Frame, Image, Mask, NormalMap};

const W: usize = 48;
const H: usize = 32;
const FRAMES: usize = 3;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mq-jpeg-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Smooth colour ramps (JPEG's blocks reproduce them closely), different in each frame.
fn frame(i: usize) -> Frame {
    let pixels = (0..W * H)
        .map(|p| {
            let (x, y) = ((p % W) as f32 / W as f32, (p / W) as f32 / H as f32);
            [0.2 + 0.6 * x, 0.3 + 0.5 * y, 0.5 + 0.1 * i as f32 * (x - y)]
        })
        .collect();
    let mask = Mask { width: W, height: H, values: (0..W * H).map(|p| p % W > W / 3).collect() };
    let normals = NormalMap { width: W, height: H, normals: vec![[0.0, 0.0, -1.0]; W * H] };
    Frame {
        index: i,
        image: Image { width: W, height: H, pixels },
        mask,
        normals: Some(normals),
        depth: None,
    }
}

fn jpeg_bytes(img: &Image, color: jpeg_encoder::ColorType) -> Vec<u8> {
    let data: Vec<u8> = match color {
        jpeg_encoder::ColorType::Luma => img.pixels.iter().map(|p| quantize(p[1])).collect(),
        _ => img.pixels.iter().flat_map(|p| p.map(quantize)).collect(),
    };
    let mut out = Vec::new();
    jpeg_encoder::Encoder::new(&mut out, 95).encode(&data, W as u16, H as u16, color).unwrap();
    out
}

/// A dataset written as PNG, then each image replaced by a JPEG named `image_NNNN.<ext>`.
fn jpeg_dataset(name: &str, ext: &str) -> PathBuf {
    let root = temp_dir(name);
    let w = DatasetWriter::new(&root);
    let camera = Camera::look_at([0.0, 0.0, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 0.8, W, H);
    w.write_cameras(&Cameras::Static(camera)).unwrap();
    for i in 0..FRAMES {
        w.write_frame(&frame(i)).unwrap();
        let png = image_path(&root, i, "png");
        std::fs::remove_file(&png).unwrap();
        std::fs::write(image_path(&root, i, ext), jpeg_bytes(&frame(i).image, jpeg_encoder::ColorType::Rgb))
            .unwrap();
    }
    root
}

fn image_path(root: &Path, frame: usize, ext: &str) -> PathBuf {
    root.join("images").join(format!("image_{frame:04}.{ext}"))
}

/// Largest and mean absolute difference over all channels.
fn differences(a: &Image, b: &Image) -> (f32, f32) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let d: Vec<f32> =
        a.pixels.iter().zip(&b.pixels).flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs())).collect();
    (d.iter().copied().fold(0.0, f32::max), d.iter().sum::<f32>() / d.len() as f32)
}

#[test]
fn a_jpeg_dataset_opens_and_its_pixels_are_within_jpeg_error() {
    for ext in ["jpg", "jpeg"] {
        let root = jpeg_dataset(&format!("dataset-{ext}"), ext);
        let ds = Dataset::open(&root, 1).unwrap();
        assert_eq!(ds.frame_count, FRAMES);
        assert_eq!(ds.image_path(1), image_path(&root, 1, ext));
        for i in 0..FRAMES {
            let got = ds.frame(i).unwrap();
            let (max, mean) = differences(&got.image, &frame(i).image.quantized());
            // Quality 95 on smooth ramps: a few levels at most, well under one level on average.
            assert!(max < 12.0 / 255.0 && mean < 2.0 / 255.0, "frame {i}: max {max}, mean {mean}");
            assert_eq!(got.mask, frame(i).mask);
        }
        // Downscaling works on decoded JPEG frames as on PNG ones.
        assert_eq!(Dataset::open(&root, 2).unwrap().frame(0).unwrap().image.width, W / 2);
        std::fs::remove_dir_all(root).unwrap();
    }
}

#[test]
fn content_decides_the_decoder_not_the_extension() {
    let root = temp_dir("content");
    let img = frame(0).image;
    // PNG bytes under a .jpg name read exactly; grey JPEG is replicated to RGB.
    let png_named_jpg = root.join("a.jpg");
    std::fs::create_dir_all(&root).unwrap();
    std::fs::write(&png_named_jpg, img.encode_png()).unwrap();
    assert_eq!(Image::read(&png_named_jpg).unwrap(), img.quantized());
    let grey = root.join("grey.png");
    std::fs::write(&grey, jpeg_bytes(&img, jpeg_encoder::ColorType::Luma)).unwrap();
    let back = Image::read(&grey).unwrap();
    assert!(back.pixels.iter().all(|p| p[0] == p[1] && p[1] == p[2]));
    let (max, _) =
        differences(&back, &Image { pixels: img.pixels.iter().map(|p| [p[1]; 3]).collect(), ..img });
    assert!(max < 12.0 / 255.0, "{max}");
    std::fs::remove_dir_all(root).unwrap();
}

#[test]
fn mixed_extensions_unknown_content_and_jpeg_normals_name_the_file() {
    let root = jpeg_dataset("mixed", "jpg");
    // One frame back as PNG: the folder now mixes extensions.
    std::fs::remove_file(image_path(&root, 2, "jpg")).unwrap();
    frame(2).image.write_png(&image_path(&root, 2, "png")).unwrap();
    let msg = Dataset::open(&root, 1).unwrap_err().to_string();
    assert!(
        msg.contains("image_0000.jpg") && msg.contains("image_0002.png") && msg.contains("one extension"),
        "{msg}"
    );
    // A frame that is neither PNG nor JPEG.
    std::fs::remove_file(image_path(&root, 2, "png")).unwrap();
    std::fs::write(image_path(&root, 2, "jpg"), b"GIF89a not really").unwrap();
    let ds = Dataset::open(&root, 1).unwrap();
    let msg = ds.frame(2).unwrap_err().to_string();
    assert!(msg.contains("image_0002.jpg") && msg.contains("expected a PNG or JPEG"), "{msg}");
    // Normal maps must stay lossless PNG, whatever their name.
    let normal = root.join("normals/normal_0001.png");
    std::fs::write(&normal, jpeg_bytes(&frame(1).image, jpeg_encoder::ColorType::Rgb)).unwrap();
    let msg = ds.frame(1).unwrap_err().to_string();
    assert!(msg.contains("normal_0001.png") && msg.contains("expected a PNG, found JPEG"), "{msg}");
    std::fs::remove_dir_all(root).unwrap();
}

#[test]
fn eval_reads_jpeg_predictions_against_a_png_ground_truth() {
    let gt = temp_dir("eval-gt");
    let w = DatasetWriter::new(&gt);
    w.write_cameras(&Cameras::Static(Camera::look_at([0.0, 0.0, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 0.8, W, H)))
        .unwrap();
    // A fully masked ground truth, so the composited image is the frame itself.
    let full = |i| Frame { mask: Mask { width: W, height: H, values: vec![true; W * H] }, ..frame(i) };
    for i in 0..FRAMES {
        w.write_frame(&full(i)).unwrap();
    }
    let pred = jpeg_dataset("eval-pred", "jpg");
    let options =
        EvalOptions { background: [1.0; 3], lpips: None, samples: 100, seed: 0, compare_meshes: true };
    let frames: Vec<usize> = (0..FRAMES).collect();
    let s = evaluate(&pred, &gt, &frames, &options, &|_| {}).unwrap();
    assert_eq!(s.frames, FRAMES);
    assert!(s.psnr > 40.0 && s.ssim > 0.98, "PSNR {} SSIM {}", s.psnr, s.ssim);
    for d in [gt, pred] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

/// A PNG whose header claims `w`×`h` of `color`, followed by a few bytes of image data: what a
/// decoder sees before it asks for the pixels' memory.
fn png_claiming(w: u32, h: u32, color: png::ColorType) -> Vec<u8> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(color);
    let mut writer = encoder.write_header().unwrap();
    writer.write_chunk(png::chunk::IDAT, &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01]).unwrap();
    drop(writer);
    out
}

/// Bad headers and bodies (issue 42): a PNG claiming 65535×65535 is refused by its size before
/// 12.9 GB is asked for, a label map claiming it too, and a JPEG cut in half is an error rather
/// than grey blocks to train on; each names the file.
#[test]
fn a_png_claiming_gigapixels_and_a_truncated_jpeg_are_refused() {
    let dir = temp_dir("bad-headers");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bomb.png");
    std::fs::write(&path, png_claiming(65535, 65535, png::ColorType::Rgb)).unwrap();
    let err = Image::read(&path).unwrap_err().to_string();
    assert!(err.contains("bomb.png") && err.contains("65535×65535") && err.contains("at most"), "{err}");
    std::fs::write(&path, png_claiming(65535, 65535, png::ColorType::Grayscale)).unwrap();
    let err = mannequin_data::labels::LabelMap::read_png(&path).unwrap_err().to_string();
    assert!(err.contains("bomb.png") && err.contains("at most"), "{err}");

    let jpeg = jpeg_bytes(&frame(0).image, jpeg_encoder::ColorType::Rgb);
    let whole = dir.join("whole.jpg");
    std::fs::write(&whole, &jpeg).unwrap();
    assert!(Image::read(&whole).is_ok());
    let cut = dir.join("cut.jpg");
    std::fs::write(&cut, &jpeg[..jpeg.len() / 2]).unwrap();
    let err = Image::read(&cut).unwrap_err().to_string();
    assert!(err.contains("cut.jpg") && err.contains("JPEG"), "{err}");
    std::fs::remove_dir_all(dir).unwrap();
}
