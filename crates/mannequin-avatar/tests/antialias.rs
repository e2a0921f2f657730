//! The antialiasing compensation against the splat renderer's own projection (itself checked
//! against gsplat): the renderer returns the filtered conic `(Σ₂ + 0.3 I)⁻¹`, from which the
//! unfiltered determinant follows on the host in f64.

use burn::tensor::{Device, Tensor, TensorData};
use mannequin_avatar::AVATAR_DILATION;
use mannequin_avatar::antialias::compensation;
use mannequin_avatar::mesh_gaussians::GaussianGeometry;
use mannequin_io::rng::SplitMix64;
use mannequin_splat::{Camera, Colors, Gaussians, RenderOptions, Rotations, project_gaussians};

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / n)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[test]
fn compensation_matches_the_renderers_projection() {
    let camera = Camera::look_at([0.2, 1.0, 3.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], 0.6, 540, 540);
    let mut rng = SplitMix64::new(5);
    let n = 200;
    let (mut means, mut frames, mut scales) = (vec![], vec![], vec![]);
    for i in 0..n {
        means.extend([rng.range(-0.4, 0.4), rng.range(0.2, 1.8), rng.range(-0.3, 0.3)]);
        let normal = unit([rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)]);
        let t1 = unit(cross(normal, unit([rng.range(-1.0, 1.0), 1.0, rng.range(-1.0, 1.0)])));
        let t2 = cross(normal, t1);
        // Row-major with columns (t1, t2, n).
        frames.extend((0..3).flat_map(|r| [t1[r], t2[r], normal[r]]));
        // Disks from sub-pixel to several pixels wide, 1 mm thick; a few round blobs.
        let s = rng.range(0.0005, 0.03);
        scales.extend(if i % 10 == 0 { [s, s, s] } else { [s, 0.6 * s, 0.001] });
    }
    let opacities = vec![1.0; n];
    let colours = vec![0.5; 3 * n];
    let g = Gaussians {
        means: &means,
        rotations: Rotations::Matrices(&frames),
        scales: &scales,
        opacities: &opacities,
        colors: Colors::Features { channels: 3, values: &colours },
    };
    // The avatar's own filter, so the renderer's `dilation` option is exercised too.
    let dilation = AVATAR_DILATION;
    let options = RenderOptions { dilation, ..RenderOptions::default() };
    let projection = project_gaussians(&g, &camera, &options).unwrap();

    let device = Device::flex();
    let f32s = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<_>>();
    let rows = |v: &[f64]| Tensor::<2>::from_data(TensorData::new(f32s(v), [n, 3]), &device);
    let geometry = GaussianGeometry {
        means: rows(&means),
        frames: Tensor::from_data(TensorData::new(f32s(&frames), [n, 3, 3]), &device),
        scales: rows(&scales),
        normals: rows(&vec![0.0; 3 * n]),
    };
    let got: Vec<f32> = compensation(&geometry, &camera, dilation).into_data().try_to_vec().unwrap();
    let (mut checked, mut small, mut large) = (0, 0, 0);
    for (i, &got) in got.iter().enumerate() {
        if projection.radii[2 * i] == 0 {
            continue;
        }
        let [a, b, c] = [0, 1, 2].map(|k| projection.conics[3 * i + k]);
        let det_conic = a * c - b * b;
        let (p, q, r) = (c / det_conic - dilation, -b / det_conic, a / det_conic - dilation);
        let want = ((p * r - q * q) * det_conic).max(0.0).sqrt();
        let err = (f64::from(got) - want).abs();
        assert!(err < 2e-4 * want.max(1e-2), "Gaussian {i}: {got} vs {want}");
        checked += 1;
        small += usize::from(want < 0.5);
        large += usize::from(want > 0.9);
    }
    // Both regimes occur: thin or sub-pixel footprints lose most of their opacity, wide ones keep it.
    assert!(checked > 150 && small > 5 && large > 10, "{checked} checked, {small} small, {large} large");
}
