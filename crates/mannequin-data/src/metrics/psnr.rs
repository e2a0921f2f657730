//! Peak signal-to-noise ratio with data range 1, as `skimage.metrics.peak_signal_noise_ratio`
//! and `torchmetrics` compute it: `10 log10(1 / MSE)` over all pixels and channels.

use crate::error::DataError;
use crate::image::Image;

/// Mean squared error over all pixels and channels; images of different sizes are an error.
pub fn mse(a: &Image, b: &Image) -> Result<f64, DataError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(DataError::Invalid(format!(
            "PSNR of images of different sizes: {}×{} and {}×{}",
            a.width, a.height, b.width, b.height
        )));
    }
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (0..3).map(|c| (p[c] as f64 - q[c] as f64).powi(2)).sum::<f64>())
        .sum();
    Ok(sum / (3 * a.pixels.len()) as f64)
}

/// PSNR in dB; infinite for identical images.
pub fn psnr(a: &Image, b: &Image) -> Result<f64, DataError> {
    Ok(10.0 * (1.0 / mse(a, b)?).log10())
}
