//! The renderer against golden fixtures made with gsplat 1.5's own projection and SH code and a
//! dense compositor (`tools/oracles/splat_gsplat.py`).

mod common;

use mannequin_io::Npz;
use mannequin_splat::{Camera, Colors, Gaussians, Real, RenderOptions, Rotations, project_gaussians, render};

const SCENES: [&str; 4] = ["random_cloud", "human_shell", "behind_and_crossing", "tiny_and_huge"];

struct Fixture {
    npz: Npz,
    camera: Camera,
}

impl Fixture {
    fn load(name: &str) -> Self {
        let path = format!("{}/tests/fixtures/splat_{name}.npz", env!("CARGO_MANIFEST_DIR"));
        let npz = Npz::read(&path).unwrap();
        let get = |k: &str| npz.require(k).unwrap().to_f64().unwrap();
        let (k, v) = (get("K"), get("viewmat"));
        let camera = Camera {
            width: get("width")[0] as usize,
            height: get("height")[0] as usize,
            intrinsic: std::array::from_fn(|i| std::array::from_fn(|j| k[3 * i + j])),
            extrinsic: std::array::from_fn(|i| std::array::from_fn(|j| v[4 * i + j])),
            near: get("near")[0],
            far: get("far")[0],
        };
        Fixture { npz, camera }
    }

    fn get(&self, key: &str) -> Vec<f64> {
        self.npz.require(key).unwrap().to_f64().unwrap()
    }

    fn options(&self) -> RenderOptions {
        RenderOptions {
            background: self.get("background"),
            count_contributors: true,
            dilation: self.get("eps2d")[0],
            ..RenderOptions::default()
        }
    }
}

/// The fixture's Gaussians in `T`, with rotations as quaternions or as matrices.
struct Inputs<T> {
    means: Vec<T>,
    rotations: Vec<T>,
    matrices: bool,
    scales: Vec<T>,
    opacities: Vec<T>,
    colors: Vec<T>,
    sh_degree: Option<usize>,
    channels: usize,
}

impl<T: Real> Inputs<T> {
    fn new(f: &Fixture, matrices: bool) -> Self {
        let c = |v: Vec<f64>| v.into_iter().map(T::from_f64).collect::<Vec<T>>();
        let quats = f.get("quats");
        let rotations =
            if matrices { quats.chunks(4).flat_map(common::quat_to_matrix).collect() } else { quats };
        let (colors, sh_degree, channels) = if f.npz.contains("sh") {
            (f.get("sh"), Some(f.get("sh_degree")[0] as usize), 3)
        } else {
            let shape = f.npz.require("features").unwrap().shape.clone();
            (f.get("features"), None, shape[1])
        };
        Inputs {
            means: c(f.get("means")),
            rotations: c(rotations),
            matrices,
            scales: c(f.get("scales")),
            opacities: c(f.get("opacities")),
            colors: c(colors),
            sh_degree,
            channels,
        }
    }

    fn gaussians(&self) -> Gaussians<'_, T> {
        Gaussians {
            means: &self.means,
            rotations: if self.matrices {
                Rotations::Matrices(&self.rotations)
            } else {
                Rotations::Quaternions(&self.rotations)
            },
            scales: &self.scales,
            opacities: &self.opacities,
            colors: match self.sh_degree {
                Some(degree) => Colors::Sh { degree, coeffs: &self.colors },
                None => Colors::Features { channels: self.channels, values: &self.colors },
            },
        }
    }
}

/// The most one Gaussian skipped or kept at the 1/255 alpha threshold can move a pixel: its
/// alpha (< 1/255) times a colour difference (< 2 in these scenes).
const THRESHOLD_FLIP: f64 = 2.0 / 255.0;

/// Every value within `tol`, except up to `flips` values within [`THRESHOLD_FLIP`].
fn assert_close<T: Real>(what: &str, got: &[T], want: &[f64], tol: f64, flips: usize) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let errors: Vec<f64> = got.iter().zip(want).map(|(g, w)| (g.to_f64() - w).abs()).collect();
    let (worst, at) =
        errors.iter().enumerate().fold((0.0f64, 0), |m, (i, &e)| if e > m.0 { (e, i) } else { m });
    let over = errors.iter().filter(|&&e| e > tol).count();
    let bound = if flips > 0 { THRESHOLD_FLIP } else { tol };
    assert!(
        over <= flips && worst <= bound,
        "{what}: {over} values over {tol:.0e} (allowed {flips}); worst error {worst:.3e} at {at} (got {:?}, want {})",
        got[at],
        want[at]
    );
}

#[test]
fn projection_matches_gsplat() {
    for name in SCENES {
        let f = Fixture::load(name);
        let inputs = Inputs::<f64>::new(&f, false);
        let p = project_gaussians(&inputs.gaussians(), &f.camera, &f.options()).unwrap();
        let radii = f.get("radii");
        let got: Vec<f64> = p.radii.iter().map(|&r| r as f64).collect();
        assert_eq!(got, radii, "{name}: radii");
        let (m2, con, dep, col) = (f.get("means2d"), f.get("conics"), f.get("depths"), f.get("colors"));
        let ch = inputs.channels;
        for i in 0..inputs.opacities.len() {
            if radii[2 * i] == 0.0 {
                continue;
            }
            let close = |what: &str, a: f64, b: f64, rel: f64| {
                assert!(
                    (a - b).abs() <= rel * (1.0 + b.abs()),
                    "{name}: {what} of Gaussian {i}: {a} vs gsplat {b}"
                );
            };
            for k in 0..2 {
                close("mean2d", p.means2d[2 * i + k], m2[2 * i + k], 1e-5);
            }
            for k in 0..3 {
                close("conic", p.conics[3 * i + k], con[3 * i + k], 1e-5);
            }
            close("depth", p.depths[i], dep[i], 1e-6);
            for k in 0..ch {
                close("colour", p.colors[ch * i + k], col[ch * i + k], 1e-5);
            }
        }
    }
}

fn check_images<T: Real>(name: &str, matrices: bool) {
    let f = Fixture::load(name);
    let inputs = Inputs::<T>::new(&f, matrices);
    let out = render(&inputs.gaussians(), &f.camera, &f.options()).unwrap();
    let what = format!(
        "{name} ({}, {})",
        std::any::type_name::<T>(),
        if matrices { "matrices" } else { "quaternions" }
    );
    // In f32 a pixel may stop one Gaussian earlier or later where transmittance lands within
    // rounding of 1e-4 (the image moves by at most 1e-4 then), or skip or keep a Gaussian whose
    // alpha lands within rounding of 1/255; in f64 everything must agree.
    let npx = out.alpha.len();
    let allowed = if std::mem::size_of::<T>() == 8 { 0 } else { npx / 500 };
    let channels = out.image.len() / npx;
    assert_close(&format!("{what} image"), &out.image, &f.get("image"), 1e-4, allowed * channels);
    assert_close(&format!("{what} alpha"), &out.alpha, &f.get("alpha"), 1e-4, allowed);
    assert_close(&format!("{what} depth"), &out.depth, &f.get("depth"), 1e-4, allowed);
    let count: Vec<f64> = out.count.unwrap().iter().map(|&c| c as f64).collect();
    let want = f.get("count");
    let differ = count.iter().zip(&want).filter(|(a, b)| a != b).count();
    assert!(differ <= allowed, "{what}: {differ} pixels composited a different number of Gaussians");
}

#[test]
fn images_match_the_dense_oracle_in_f64() {
    for name in SCENES {
        check_images::<f64>(name, false);
    }
}

#[test]
fn images_match_the_dense_oracle_in_f32() {
    for name in SCENES {
        check_images::<f32>(name, false);
    }
}

#[test]
fn rotation_matrices_render_like_their_quaternions() {
    for name in SCENES {
        check_images::<f32>(name, true);
    }
}
