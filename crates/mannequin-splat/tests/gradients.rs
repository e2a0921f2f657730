//! The backward pass against f64 central finite differences, for every input kind and every
//! output (image, alpha, expected depth).

mod common;

use common::{ColorForm, RotForm, Scene, camera};
use mannequin_splat::{Camera, OutputGrads, RenderOptions, backward, render};

/// A fixed random linear loss on the three outputs; depth is weighted only where the base
/// render is clearly covered (elsewhere expected depth is a ratio of vanishing sums).
struct Loss {
    image: Vec<f64>,
    alpha: Vec<f64>,
    depth: Vec<f64>,
}

impl Loss {
    fn new(
        scene: &Scene,
        rot: RotForm,
        col: ColorForm,
        cam: &Camera,
        opts: &RenderOptions,
        seed: u64,
    ) -> Self {
        let mut rng = common::Rng::new(seed);
        let t = scene.cast::<f64>();
        let out = render(&t.gaussians(rot, col), cam, opts).unwrap();
        Loss {
            image: out.image.iter().map(|_| rng.uniform(-1.0, 1.0)).collect(),
            alpha: out.alpha.iter().map(|_| rng.uniform(-1.0, 1.0)).collect(),
            depth: out.alpha.iter().map(|&a| if a > 0.05 { rng.uniform(-1.0, 1.0) } else { 0.0 }).collect(),
        }
    }

    fn eval(&self, scene: &Scene, rot: RotForm, col: ColorForm, cam: &Camera, opts: &RenderOptions) -> f64 {
        let t = scene.cast::<f64>();
        let out = render(&t.gaussians(rot, col), cam, opts).unwrap();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        dot(&out.image, &self.image) + dot(&out.alpha, &self.alpha) + dot(&out.depth, &self.depth)
    }
}

/// Which parameter array of a scene to perturb.
#[derive(Clone, Copy, Debug)]
enum Field {
    Means,
    Rotations,
    Scales,
    Opacities,
    Colors,
}

fn field_mut(s: &mut Scene, f: Field, rot: RotForm, col: ColorForm) -> &mut Vec<f64> {
    match f {
        Field::Means => &mut s.means,
        Field::Rotations if rot == RotForm::Quaternion => &mut s.quats,
        Field::Rotations => &mut s.matrices,
        Field::Scales => &mut s.scales,
        Field::Opacities => &mut s.opacities,
        Field::Colors if matches!(col, ColorForm::Sh(_)) => &mut s.sh,
        Field::Colors => &mut s.features,
    }
}

/// Compares the analytic gradient with central differences for every parameter. With hard
/// cutoffs a step may cross a threshold: such parameters (one-sided differences disagree) are
/// skipped, and the function returns how many were.
fn check(
    scene: &Scene,
    rot: RotForm,
    col: ColorForm,
    cam: &Camera,
    opts: &RenderOptions,
    h: f64,
    tol: f64,
) -> usize {
    let loss = Loss::new(scene, rot, col, cam, opts, 99);
    let t = scene.cast::<f64>();
    let g = t.gaussians(rot, col);
    let out = render(&g, cam, opts).unwrap();
    let grads = backward(
        &g,
        cam,
        opts,
        &out,
        &OutputGrads { image: Some(&loss.image), alpha: Some(&loss.alpha), depth: Some(&loss.depth) },
    )
    .unwrap();
    let base = loss.eval(scene, rot, col, cam, opts);
    let mut skipped = 0;
    for (field, analytic) in [
        (Field::Means, &grads.means),
        (Field::Rotations, &grads.rotations),
        (Field::Scales, &grads.scales),
        (Field::Opacities, &grads.opacities),
        (Field::Colors, &grads.colors),
    ] {
        let scale = analytic.iter().fold(1e-3f64, |m, v| m.max(v.abs()));
        let n = field_mut(&mut scene.clone(), field, rot, col).len();
        assert_eq!(n, analytic.len(), "{field:?}");
        for (j, &an) in analytic.iter().enumerate() {
            let at = |delta: f64| {
                let mut s = scene.clone();
                field_mut(&mut s, field, rot, col)[j] += delta;
                loss.eval(&s, rot, col, cam, opts)
            };
            let (plus, minus) = (at(h), at(-h));
            let (right, left) = ((plus - base) / h, (base - minus) / h);
            if (right - left).abs() > 1e-2 * scale + 1e3 * h {
                skipped += 1;
                continue;
            }
            let fd = (plus - minus) / (2.0 * h);
            assert!(
                (fd - an).abs() <= tol * scale,
                "{rot:?} {col:?} {field:?}[{j}]: finite difference {fd:.9} vs analytic {an:.9} (scale {scale:.3})"
            );
        }
    }
    skipped
}

fn smooth() -> RenderOptions {
    RenderOptions { background: vec![0.2, 0.5, 0.9], ..RenderOptions::default() }.without_cutoffs()
}

#[test]
fn quaternions_and_sh_degree_3_match_finite_differences() {
    let scene = Scene::random(6, 1, 3, 3);
    assert_eq!(
        check(&scene, RotForm::Quaternion, ColorForm::Sh(3), &camera(24, 20), &smooth(), 1e-6, 1e-6),
        0
    );
}

#[test]
fn every_lower_sh_degree_matches_finite_differences() {
    for degree in 0..3 {
        let scene = Scene::random(4, 10 + degree as u64, degree, 3);
        let n =
            check(&scene, RotForm::Quaternion, ColorForm::Sh(degree), &camera(20, 18), &smooth(), 1e-6, 1e-6);
        assert_eq!(n, 0);
    }
}

#[test]
fn matrices_and_features_match_finite_differences() {
    let scene = Scene::random(6, 2, 0, 4);
    let opts =
        RenderOptions { background: vec![0.1, -0.3, 0.0, 1.0], ..RenderOptions::default() }.without_cutoffs();
    assert_eq!(check(&scene, RotForm::Matrix, ColorForm::Features(4), &camera(24, 20), &opts, 1e-6, 1e-6), 0);
}

/// With the real cutoffs, including pixels that saturate (alpha capped at 0.99) and stop early
/// (transmittance under 1e-4), the gradient is still exact wherever the loss is differentiable.
#[test]
fn hard_cutoffs_match_finite_differences_where_differentiable() {
    let mut scene = Scene::random(14, 3, 1, 3);
    // Stack half of them, nearly opaque and larger, near the centre so pixels saturate and stop.
    for i in 0..7 {
        scene.opacities[i] = 0.995;
        for k in 0..3 {
            scene.scales[3 * i + k] *= 2.0;
            scene.means[3 * i + k] *= 0.2;
        }
    }
    let cam = camera(32, 24);
    let opts = RenderOptions {
        background: vec![1.0, 1.0, 1.0],
        count_contributors: true,
        ..RenderOptions::default()
    };
    let s64 = scene.cast::<f64>();
    let g = s64.gaussians(RotForm::Quaternion, ColorForm::Sh(1));
    let out = render(&g, &cam, &opts).unwrap();
    let capped = out.alpha.iter().filter(|&&a| a >= 0.99 - 1e-12).count();
    assert!(capped > 20, "the scene should saturate some pixels, got {capped}");
    let no_stop = render(&g, &cam, &RenderOptions { min_transmittance: 0.0, ..opts.clone() }).unwrap();
    let stopped = out.image.iter().zip(&no_stop.image).filter(|(a, b)| a != b).count();
    assert!(stopped > 20, "the transmittance stop should change some pixels, got {stopped}");
    let total = 14 * (3 + 4 + 3 + 1 + 12);
    let skipped = check(&scene, RotForm::Quaternion, ColorForm::Sh(1), &cam, &opts, 1e-7, 1e-5);
    assert!(skipped * 10 < total, "{skipped} of {total} parameters sat on a cutoff");
}

/// The f32 renderer computes the same gradients as the f64 one.
#[test]
fn f32_gradients_agree_with_f64() {
    let scene = Scene::random(40, 4, 2, 3);
    let cam = camera(48, 40);
    let opts = RenderOptions { background: vec![0.0, 0.0, 0.0], ..RenderOptions::default() };
    let mut rng = common::Rng::new(5);
    let npx = 48 * 40;
    let wi: Vec<f64> = (0..3 * npx).map(|_| rng.uniform(-1.0, 1.0)).collect();
    let wa: Vec<f64> = (0..npx).map(|_| rng.uniform(-1.0, 1.0)).collect();
    let s64 = scene.cast::<f64>();
    let g64 = s64.gaussians(RotForm::Quaternion, ColorForm::Sh(2));
    let o64 = render(&g64, &cam, &opts).unwrap();
    let d64 =
        backward(&g64, &cam, &opts, &o64, &OutputGrads { image: Some(&wi), alpha: Some(&wa), depth: None })
            .unwrap();
    let s32 = scene.cast::<f32>();
    let g32 = s32.gaussians(RotForm::Quaternion, ColorForm::Sh(2));
    let o32 = render(&g32, &cam, &opts).unwrap();
    let (wi32, wa32): (Vec<f32>, Vec<f32>) =
        (wi.iter().map(|&v| v as f32).collect(), wa.iter().map(|&v| v as f32).collect());
    let d32 = backward(
        &g32,
        &cam,
        &opts,
        &o32,
        &OutputGrads { image: Some(&wi32), alpha: Some(&wa32), depth: None },
    )
    .unwrap();
    for (name, a, b) in [
        ("means", &d64.means, &d32.means),
        ("rotations", &d64.rotations, &d32.rotations),
        ("scales", &d64.scales, &d32.scales),
        ("opacities", &d64.opacities, &d32.opacities),
        ("colors", &d64.colors, &d32.colors),
    ] {
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (j, (x, y)) in a.iter().zip(b).enumerate() {
            assert!((x - *y as f64).abs() <= 2e-3 * scale, "{name}[{j}]: f64 {x} vs f32 {y} (scale {scale})");
        }
    }
}

/// Gradients are summed per Gaussian in tile order, not per worker thread, so the backward pass
/// gives bit-identical results on one thread and on several (in f32, where a different order of
/// additions would show).
#[test]
fn backward_is_bit_identical_whatever_the_thread_count() {
    let scene = Scene::random(3000, 21, 1, 0).cast::<f32>();
    let cam = camera(160, 120);
    let opts = RenderOptions { background: vec![1.0; 3], ..RenderOptions::default() };
    let g = scene.gaussians(RotForm::Matrix, ColorForm::Sh(1));
    let mut rng = common::Rng::new(4);
    let d_image: Vec<f32> = (0..3 * 160 * 120).map(|_| rng.uniform(-1.0, 1.0) as f32).collect();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let out = render(&g, &cam, &opts).unwrap();
            let grads = OutputGrads { image: Some(&d_image), alpha: None, depth: None };
            let d = backward(&g, &cam, &opts, &out, &grads).unwrap();
            [d.means, d.rotations, d.scales, d.opacities, d.colors]
                .map(|v| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>())
        })
    };
    let one = run(1);
    assert!(one[0].iter().any(|&b| b != 0), "some mean gradient is non-zero");
    for threads in [2, 3, 8] {
        assert!(run(threads) == one, "{threads} threads differ from one");
    }
}
