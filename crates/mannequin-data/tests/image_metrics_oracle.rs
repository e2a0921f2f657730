//! PSNR and SSIM against scikit-image (fixture by tools/oracles/data_image_metrics.py).

use mannequin_data::Image;
use mannequin_data::metrics::{
    psnr::psnr,
    ssim::{ssim, ssim_direct},
};
use mannequin_io::Npz;

fn fixture() -> Npz {
    Npz::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/image_metrics.npz")).unwrap()
}

/// Image `n` of a padded (N, 40, 48, 3) uint8 stack, cropped to `h × w`.
fn image(npz: &Npz, key: &str, n: usize, h: usize, w: usize) -> Image {
    let a = npz.require(key).unwrap();
    let (ph, pw) = (a.shape[1], a.shape[2]);
    let v = a.to_f32().unwrap();
    let pixels = (0..h * w)
        .map(|p| {
            let (y, x) = (p / w, p % w);
            let base = ((n * ph + y) * pw + x) * 3;
            [v[base] / 255.0, v[base + 1] / 255.0, v[base + 2] / 255.0]
        })
        .collect();
    Image { width: w, height: h, pixels }
}

#[test]
fn psnr_and_ssim_match_scikit_image() {
    let npz = fixture();
    let sizes = npz.require("sizes").unwrap().to_i64().unwrap();
    let want_psnr = npz.require("psnr").unwrap().to_f64().unwrap();
    let want_ssim = npz.require("ssim").unwrap().to_f64().unwrap();
    assert_eq!(want_psnr.len(), 3);
    for i in 0..want_psnr.len() {
        let (h, w) = (sizes[2 * i] as usize, sizes[2 * i + 1] as usize);
        let (gt, pred) = (image(&npz, "gt", i, h, w), image(&npz, "pred", i, h, w));
        let p = psnr(&gt, &pred).unwrap();
        assert!((p - want_psnr[i]).abs() < 1e-5, "pair {i}: PSNR {p} vs {}", want_psnr[i]);
        let (s, sd) = (ssim(&gt, &pred).unwrap(), ssim_direct(&gt, &pred).unwrap());
        assert!((s - want_ssim[i]).abs() < 1e-6, "pair {i}: SSIM {s} vs {}", want_ssim[i]);
        assert!((sd - want_ssim[i]).abs() < 1e-6, "pair {i}: direct SSIM {sd} vs {}", want_ssim[i]);
    }
}
