//! LPIPS v0.1 with the AlexNet trunk (Zhang et al. 2018), computed by our own network code from
//! weights the user supplies.
//!
//! The weights file is an `.npz` holding the `lpips.LPIPS(net='alex')` state dict, exported with
//! `np.savez(path, **{k: v.numpy() for k, v in model.state_dict().items()})` (see
//! `docs/dataset-format.md`): `net.slice1.0.weight/bias` … `net.slice5.10.weight/bias` (the
//! torchvision AlexNet `features` convolutions 0, 3, 6, 8, 10) and `lin0.model.1.weight` …
//! `lin4.model.1.weight`. Other keys (the scaling layer's buffers) are ignored.
//!
//! The distance follows `lpips.LPIPS.forward(.., normalize=True)`: images in [0, 1] are mapped to
//! [−1, 1], shifted and scaled per channel, passed through the five conv+ReLU stages; each
//! stage's features are normalised to unit length per pixel, their squared difference weighted
//! by the stage's linear layer and averaged over the pixels; the five averages are summed.

use std::path::Path;

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use mannequin_io::Npz;
use rayon::prelude::*;

use crate::error::DataError;
use crate::image::Image;
use mannequin_io::limits::FLOAT32;

/// One AlexNet `features` convolution: key prefix, output and input channels, kernel size,
/// stride, padding, and whether a 3×3/2 max-pool comes before it.
struct ConvSpec {
    key: &'static str,
    out: usize,
    inp: usize,
    k: usize,
    stride: usize,
    pad: usize,
    pool_before: bool,
}

const CONVS: [ConvSpec; 5] = [
    ConvSpec { key: "net.slice1.0", out: 64, inp: 3, k: 11, stride: 4, pad: 2, pool_before: false },
    ConvSpec { key: "net.slice2.3", out: 192, inp: 64, k: 5, stride: 1, pad: 2, pool_before: true },
    ConvSpec { key: "net.slice3.6", out: 384, inp: 192, k: 3, stride: 1, pad: 1, pool_before: true },
    ConvSpec { key: "net.slice4.8", out: 256, inp: 384, k: 3, stride: 1, pad: 1, pool_before: false },
    ConvSpec { key: "net.slice5.10", out: 256, inp: 256, k: 3, stride: 1, pad: 1, pool_before: false },
];

/// `lpips.ScalingLayer`: `(x − shift) / scale` per RGB channel.
const SHIFT: [f32; 3] = [-0.030, -0.088, -0.188];
const SCALE: [f32; 3] = [0.458, 0.448, 0.450];
/// `lpips.normalize_tensor`'s epsilon.
const EPS: f32 = 1e-10;

/// A feature map, channels × height × width, row-major.
struct Features {
    c: usize,
    h: usize,
    w: usize,
    data: Vec<f32>,
}

struct Stage {
    weight: Vec<f32>,
    bias: Vec<f32>,
    lin: Vec<f32>,
}

pub struct Lpips {
    stages: Vec<Stage>,
}

fn max_pool_3x3_s2(x: &Features) -> Features {
    let (h, w) = ((x.h - 3) / 2 + 1, (x.w - 3) / 2 + 1);
    let mut data = vec![0.0; x.c * h * w];
    data.par_chunks_mut(h * w).enumerate().for_each(|(c, out)| {
        let src = &x.data[c * x.h * x.w..(c + 1) * x.h * x.w];
        for oy in 0..h {
            for ox in 0..w {
                let mut m = f32::NEG_INFINITY;
                for dy in 0..3 {
                    for dx in 0..3 {
                        m = m.max(src[(2 * oy + dy) * x.w + 2 * ox + dx]);
                    }
                }
                out[oy * w + ox] = m;
            }
        }
    });
    Features { c: x.c, h, w, data }
}

/// Convolution + bias + ReLU by im2col and a matrix product.
fn conv_relu(x: &Features, spec: &ConvSpec, stage: &Stage) -> Features {
    let (k, s, p) = (spec.k, spec.stride, spec.pad);
    let oh = (x.h + 2 * p - k) / s + 1;
    let ow = (x.w + 2 * p - k) / s + 1;
    let n = oh * ow;
    let rows = x.c * k * k;
    let mut cols = vec![0.0f32; rows * n];
    cols.par_chunks_mut(n).enumerate().for_each(|(r, out)| {
        let (ci, ky, kx) = (r / (k * k), (r / k) % k, r % k);
        let src = &x.data[ci * x.h * x.w..(ci + 1) * x.h * x.w];
        for oy in 0..oh {
            let iy = (oy * s + ky) as isize - p as isize;
            if iy < 0 || iy >= x.h as isize {
                continue;
            }
            for ox in 0..ow {
                let ix = (ox * s + kx) as isize - p as isize;
                if ix >= 0 && ix < x.w as isize {
                    out[oy * ow + ox] = src[iy as usize * x.w + ix as usize];
                }
            }
        }
    });
    let mut data = vec![0.0f32; spec.out * n];
    matmul(
        MatMut::from_row_major_slice_mut(&mut data, spec.out, n),
        Accum::Replace,
        MatRef::from_row_major_slice(&stage.weight, spec.out, rows),
        MatRef::from_row_major_slice(&cols, rows, n),
        1.0f32,
        Par::rayon(0),
    );
    data.par_chunks_mut(n)
        .zip(&stage.bias)
        .for_each(|(ch, &b)| ch.iter_mut().for_each(|v| *v = (*v + b).max(0.0)));
    Features { c: spec.out, h: oh, w: ow, data }
}

/// Per pixel, `x / (‖x‖ + ε)` over channels.
fn unit_normalise(x: &mut Features) {
    let hw = x.h * x.w;
    let mut norm = vec![0.0f32; hw];
    for c in 0..x.c {
        for (n, v) in norm.iter_mut().zip(&x.data[c * hw..(c + 1) * hw]) {
            *n += v * v;
        }
    }
    norm.iter_mut().for_each(|n| *n = 1.0 / (n.sqrt() + EPS));
    x.data.par_chunks_mut(hw).for_each(|ch| ch.iter_mut().zip(&norm).for_each(|(v, n)| *v *= n));
}

/// The weight-file keys and shapes this network reads, stage by stage: the convolution's
/// weight and bias, then the linear layer's weight.
pub fn weight_shapes() -> Vec<(String, Vec<usize>)> {
    CONVS
        .iter()
        .enumerate()
        .flat_map(|(i, c)| {
            [
                (format!("{}.weight", c.key), vec![c.out, c.inp, c.k, c.k]),
                (format!("{}.bias", c.key), vec![c.out]),
                (format!("lin{i}.model.1.weight"), vec![1, c.out, 1, 1]),
            ]
        })
        .collect()
}

impl Lpips {
    /// Reads the weights, refusing a non-finite value anywhere and a negative linear-layer
    /// weight (LPIPS trains them clamped at 0; a negative one makes a distance negative).
    pub fn from_npz(npz: &Npz) -> Result<Self, DataError> {
        let mut arrays = Vec::new();
        for (key, shape) in weight_shapes() {
            let expected: Vec<Option<usize>> = shape.iter().map(|&d| Some(d)).collect();
            let allowed = if key.starts_with("lin") { 0.0..=*FLOAT32.end() } else { FLOAT32 };
            let (_, v) = npz.f64_in_range(&key, &expected, allowed)?;
            arrays.push(v.into_iter().map(|x| x as f32).collect::<Vec<f32>>());
        }
        let mut arrays = arrays.into_iter();
        let mut stages = Vec::new();
        while let (Some(weight), Some(bias), Some(lin)) = (arrays.next(), arrays.next(), arrays.next()) {
            stages.push(Stage { weight, bias, lin });
        }
        Ok(Self { stages })
    }

    pub fn load(path: &Path) -> Result<Self, DataError> {
        Self::from_npz(&Npz::read(path)?)
    }

    /// The five stages' ReLU outputs for an image in [0, 1].
    fn features(&self, img: &Image) -> Vec<Features> {
        let hw = img.width * img.height;
        let mut data = vec![0.0f32; 3 * hw];
        for (i, p) in img.pixels.iter().enumerate() {
            for c in 0..3 {
                data[c * hw + i] = ((2.0 * p[c] - 1.0) - SHIFT[c]) / SCALE[c];
            }
        }
        let mut x = Features { c: 3, h: img.height, w: img.width, data };
        let mut out = Vec::new();
        for (spec, stage) in CONVS.iter().zip(&self.stages) {
            let input = if spec.pool_before { max_pool_3x3_s2(&x) } else { x };
            x = conv_relu(&input, spec, stage);
            let mut f = Features { c: x.c, h: x.h, w: x.w, data: x.data.clone() };
            unit_normalise(&mut f);
            out.push(f);
        }
        out
    }

    /// Each stage's contribution; their sum is the LPIPS distance.
    pub fn per_layer(&self, a: &Image, b: &Image) -> Result<Vec<f64>, DataError> {
        if (a.width, a.height) != (b.width, b.height) {
            return Err(DataError::Invalid(format!(
                "LPIPS of images of different sizes: {}×{} and {}×{}",
                a.width, a.height, b.width, b.height
            )));
        }
        // The first convolution and two pools need at least 31 pixels for a non-empty output.
        if a.width.min(a.height) < 31 {
            return Err(DataError::Invalid(format!(
                "LPIPS needs images of at least 31×31, got {}×{}",
                a.width, a.height
            )));
        }
        let (fa, fb) = rayon::join(|| self.features(a), || self.features(b));
        Ok(fa
            .iter()
            .zip(&fb)
            .zip(&self.stages)
            .map(|((x, y), stage)| {
                let hw = x.h * x.w;
                let mut acc = vec![0.0f64; hw];
                for (c, &wc) in stage.lin.iter().enumerate() {
                    let (xs, ys) = (&x.data[c * hw..(c + 1) * hw], &y.data[c * hw..(c + 1) * hw]);
                    for ((s, u), v) in acc.iter_mut().zip(xs).zip(ys) {
                        *s += wc as f64 * ((u - v) as f64).powi(2);
                    }
                }
                acc.iter().sum::<f64>() / hw as f64
            })
            .collect())
    }

    pub fn distance(&self, a: &Image, b: &Image) -> Result<f64, DataError> {
        Ok(self.per_layer(a, b)?.iter().sum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mannequin_io::{NpyArray, NpzWriter};

    /// Weights of every expected shape, all 0.01, with `key`'s element 0 set to `bad`.
    fn weights_with(key: &str, bad: f32) -> Npz {
        let mut w = NpzWriter::new();
        for (k, shape) in weight_shapes() {
            let mut values = vec![0.01f32; shape.iter().product()];
            if k == key {
                values[0] = bad;
            }
            w.add(&k, NpyArray::f32(shape, values));
        }
        Npz::from_bytes("alex.npz".into(), &w.to_bytes()).unwrap()
    }

    #[test]
    fn a_non_finite_weight_is_refused_naming_the_file_and_array() {
        for key in ["net.slice3.6.weight", "net.slice1.0.bias", "lin2.model.1.weight"] {
            for bad in [f32::NAN, f32::INFINITY] {
                let e = Lpips::from_npz(&weights_with(key, bad)).err().expect(key).to_string();
                assert!(e.starts_with(&format!("alex.npz: field '{key}': element 0 is ")), "{e}");
            }
        }
        assert!(Lpips::from_npz(&weights_with("lin0.model.1.weight", 0.0)).is_ok());
    }

    #[test]
    fn a_negative_linear_weight_is_refused() {
        let e = Lpips::from_npz(&weights_with("lin4.model.1.weight", -0.5)).err().unwrap().to_string();
        assert!(
            e.contains("field 'lin4.model.1.weight': element 0 is -0.5: expected 0–3.4028234663852886e38"),
            "{e}"
        );
        // Convolutions may be negative.
        assert!(Lpips::from_npz(&weights_with("net.slice5.10.weight", -0.5)).is_ok());
    }
}
