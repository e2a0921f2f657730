//! The public metrics refuse inputs they cannot score (different sizes, too small for SSIM's
//! window) with an error that names both sizes, instead of panicking.

use mannequin_data::metrics::normal_error::normal_error;
use mannequin_data::metrics::psnr::{mse, psnr};
use mannequin_data::metrics::ssim::{ssim, ssim_direct};
use mannequin_data::{Image, NormalMap};

fn grey(width: usize, height: usize) -> Image {
    Image { width, height, pixels: vec![[0.5; 3]; width * height] }
}

fn facing(width: usize, height: usize) -> NormalMap {
    NormalMap { width, height, normals: vec![[0.0, 0.0, -1.0]; width * height] }
}

#[test]
fn image_metrics_of_different_sizes_are_errors_naming_both_sizes() {
    let (a, b) = (grey(16, 12), grey(12, 16));
    for (name, result) in [
        ("mse", mse(&a, &b)),
        ("psnr", psnr(&a, &b)),
        ("ssim", ssim(&a, &b)),
        ("ssim_direct", ssim_direct(&a, &b)),
    ] {
        let msg = result.expect_err(name).to_string();
        assert!(msg.contains("16×12") && msg.contains("12×16"), "{name}: {msg}");
    }
    assert!(psnr(&a, &a).is_ok() && ssim(&a, &a).is_ok());
}

#[test]
fn ssim_of_images_smaller_than_its_window_is_an_error() {
    let small = grey(10, 30);
    for result in [ssim(&small, &small), ssim_direct(&small, &small)] {
        let msg = result.unwrap_err().to_string();
        assert!(msg.contains("11×11") && msg.contains("10×30"), "{msg}");
    }
}

#[test]
fn normal_error_of_different_sizes_is_an_error_naming_both_sizes() {
    let msg = normal_error(&facing(8, 4), &facing(4, 8)).unwrap_err().to_string();
    assert!(msg.contains("8×4") && msg.contains("4×8"), "{msg}");
    assert_eq!(normal_error(&facing(8, 4), &facing(8, 4)).unwrap().angular_deg, 0.0);
}
