//! Training as a user relies on it: a run resumed from a checkpoint ends bit-identical to an
//! uninterrupted one (and a run of another length is refused), a non-finite loss stops the run naming the iteration, the loss falls on a
//! real (small) synthetic subject, a dataset with a missing piece fails before training, and a
//! run goes to its one iteration count, checkpointing on the way, and saves the avatar.

use std::path::{Path, PathBuf};

use burn::tensor::Device;
use mannequin_avatar::{
    Avatar, AvatarConfig, AvatarError, Canonical, Checkpoint, Method, SkirtMode, TrainOptions, Trainer,
    Training, TrainingRun, checkpoint_path, load_views,
};
use mannequin_body::BodyModel;
use mannequin_data::Dataset;
use mannequin_synth::{SynthOptions, generate};

fn subject(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mannequin-training-{name}-{}", std::process::id()));
    let options = SynthOptions {
        seed: 2,
        size: 64,
        supersample: 1,
        capture_frames: 10,
        train_frames: 8,
        view_poses: 1,
        motion_frames: 1,
        // Training, not cloth, is under test: the faster simulation without cloth–cloth contacts.
        self_collision: false,
    };
    generate(&BodyModel::default_body_lod1(), &dir, &options, &|_| {}).expect("synthetic subject");
    dir
}

fn trainer(data: &Path, method: Method, iters: usize) -> Trainer {
    trainer_with(data, method, TrainOptions::new(method, iters, 7))
}

fn trainer_with(data: &Path, method: Method, options: TrainOptions) -> Trainer {
    let dataset = Dataset::open(data, 1).unwrap();
    let split = dataset.split("train").unwrap();
    let views = load_views(&dataset, &split, |_, _| {}).unwrap();
    let canonical = Canonical::from_body(&BodyModel::default_body_lod1(), &split.poses.betas, 0).unwrap();
    let mut config = AvatarConfig::new(method, 7);
    // A small grid keeps the test quick; the code paths are the same.
    config.hash_log2_table = 12;
    let avatar = Avatar::new(config, canonical, &Device::flex().autodiff()).unwrap();
    Trainer::new(avatar, views, options).unwrap()
}

/// What the CLI records for a trainer built by [`trainer_with`].
fn record(t: &Trainer, data: &Path) -> TrainingRun {
    let dataset = Dataset::open(data, 1).unwrap();
    let split = dataset.split("train").unwrap();
    TrainingRun {
        body: "default-lod1".into(),
        downscale: 1,
        skirt: SkirtMode::Off,
        garments: None,
        data: dataset.fingerprint(&split).unwrap(),
        avatar: t.avatar.config.clone(),
        options: t.options.clone(),
    }
}

fn parameters(t: &Trainer) -> Vec<(String, Vec<f32>)> {
    t.avatar
        .params
        .iter()
        .map(|p| (p.name.clone(), p.value.clone().into_data().iter::<f32>().collect()))
        .collect()
}

#[test]
fn resumed_training_matches_an_uninterrupted_run_bit_for_bit() {
    // One thread: rayon's adaptive splitting can change the order of some float reductions when
    // other tests load the machine; the claim here is about the checkpoint, not the scheduler.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(resume_matches);
}

fn resume_matches() {
    let data = subject("resume");
    for method in [Method::Tavatar, Method::Ihuman] {
        let mut straight = trainer(&data, method, 6);
        for _ in 0..6 {
            straight.step().unwrap();
        }
        let mut first = trainer(&data, method, 6);
        for _ in 0..3 {
            first.step().unwrap();
        }
        let checkpoint = data.join(format!("{method:?}.npz"));
        first.save_checkpoint(&checkpoint, &record(&first, &data)).unwrap();
        drop(first);
        // A run of another length is refused: its learning rates would decay differently.
        let longer = trainer(&data, method, 7);
        let e = Checkpoint::open(&checkpoint, &record(&longer, &data), &[]).err().unwrap().to_string();
        assert!(e.contains("options.iters was 6, now 7"), "{e}");
        let mut resumed = trainer(&data, method, 6);
        let run = record(&resumed, &data);
        resumed.resume(&Checkpoint::open(&checkpoint, &run, &[]).unwrap(), &run).unwrap();
        assert_eq!(resumed.iteration, 3);
        for _ in 0..3 {
            resumed.step().unwrap();
        }
        let (a, b) = (parameters(&straight), parameters(&resumed));
        assert_eq!(a.len(), b.len());
        for ((name, x), (_, y)) in a.iter().zip(&b) {
            assert!(x == y, "{method:?}: parameter {name} differs after resuming");
        }
        // And training did move the parameters.
        assert!(parameters(&trainer(&data, method, 6)) != a, "{method:?}: nothing was learned");
    }
    std::fs::remove_dir_all(data).ok();
}

#[test]
fn a_run_refining_its_poses_resumes_bit_for_bit_and_saves_them() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| {
        let data = subject("refine");
        let options = TrainOptions { refine_poses: true, ..TrainOptions::new(Method::Tavatar, 6, 7) };
        let betas = Dataset::open(&data, 1).unwrap().split("train").unwrap().poses.betas;
        let mut straight = trainer_with(&data, Method::Tavatar, options.clone());
        for _ in 0..6 {
            straight.step().unwrap();
        }
        let mut first = trainer_with(&data, Method::Tavatar, options.clone());
        for _ in 0..3 {
            first.step().unwrap();
        }
        let checkpoint = data.join("refine.npz");
        first.save_checkpoint(&checkpoint, &record(&first, &data)).unwrap();
        let mut resumed = trainer_with(&data, Method::Tavatar, options.clone());
        let run = record(&resumed, &data);
        resumed.resume(&Checkpoint::open(&checkpoint, &run, &[]).unwrap(), &run).unwrap();
        for _ in 0..3 {
            resumed.step().unwrap();
        }
        assert!(parameters(&straight) == parameters(&resumed), "the avatar differs after resuming");
        let (a, b) = (straight.refined_poses(&betas).unwrap(), resumed.refined_poses(&betas).unwrap());
        assert!(a == b, "the refined poses differ after resuming");
        let initial = Dataset::open(&data, 1).unwrap().split("train").unwrap().poses;
        assert!(a != initial, "no pose was refined");
        // A run without refinement records none, and so refuses this checkpoint.
        let plain = trainer_with(&data, Method::Tavatar, TrainOptions::new(Method::Tavatar, 6, 7));
        let e = Checkpoint::open(&checkpoint, &record(&plain, &data), &[]).err().unwrap().to_string();
        assert!(e.contains("options.refine_poses"), "{e}");
        // The run saves them beside the avatar, in the pose format.
        let out = data.join("model");
        let run = record(&resumed, &data);
        Training {
            trainer: resumed,
            record: run,
            checkpoint_every: 100,
            out: out.clone(),
            betas: betas.clone(),
        }
        .run()
        .unwrap();
        let saved =
            mannequin_data::Poses::read(&out.join(mannequin_avatar::training::REFINED_POSES)).unwrap();
        assert_eq!(saved.len(), b.len());
        assert_eq!(saved.betas, betas);
        std::fs::remove_dir_all(data).ok();
    });
}

#[test]
fn loss_falls_and_a_nan_stops_the_run_naming_the_iteration() {
    let data = subject("loss");
    // Constant rates: over 40 iterations the default decay would make the later steps tiny.
    let options = TrainOptions { final_lr_factor: 1.0, ..TrainOptions::new(Method::Tavatar, 40, 7) };
    let mut t = trainer_with(&data, Method::Tavatar, options);
    let first: f64 = (0..8).map(|_| t.step().unwrap().loss).sum::<f64>() / 8.0;
    for _ in 0..24 {
        t.step().unwrap();
    }
    let last: f64 = (0..8).map(|_| t.step().unwrap().loss).sum::<f64>() / 8.0;
    assert!(last < 0.8 * first, "mean loss {first} -> {last}");
    // A NaN in the offset field's last bias makes every vertex NaN, and the mesh terms with it.
    let bias = t.avatar.params.iter_mut().find(|p| p.name == "offsets/mlp/b2").unwrap();
    bias.value = (bias.value.clone().inner() * f32::NAN).autodiff().require_grad();
    match t.step() {
        Err(AvatarError::NonFiniteLoss { iteration, .. }) => assert_eq!(iteration, 41),
        other => panic!("expected a non-finite loss error, got {:?}", other.map(|s| s.loss)),
    }
    std::fs::remove_dir_all(data).ok();
}

#[test]
fn a_run_trains_to_its_iterations_and_saves_the_avatar() {
    let data = subject("run");
    let out = data.join("model");
    let trainer = trainer(&data, Method::Tavatar, 3);
    let run = record(&trainer, &data);
    Training { trainer, record: run.clone(), checkpoint_every: 2, out: out.clone(), betas: Vec::new() }
        .run()
        .unwrap();
    assert_eq!(Checkpoint::open(&checkpoint_path(&out), &run, &[]).unwrap().iteration, 3);
    assert!(Avatar::load(&out, &Device::flex()).is_ok(), "no avatar in {}", out.display());
    std::fs::remove_dir_all(data).ok();
}

#[test]
fn a_missing_mask_is_an_error_before_training() {
    let data = subject("mask");
    std::fs::remove_file(data.join("masks/mask_0003.npy")).unwrap();
    let e = Dataset::open(&data, 1).unwrap_err().to_string();
    assert!(e.contains("mask_0003.npy") && e.contains("missing mask"), "{e}");
    std::fs::remove_dir_all(data).ok();
}

/// `checkpoint` written to `to` with `key` replaced by `array`.
fn with_array(checkpoint: &Path, to: &Path, key: &str, array: mannequin_io::NpyArray) {
    let npz = mannequin_io::Npz::read(checkpoint).unwrap();
    let mut w = mannequin_io::NpzWriter::uncompressed();
    for k in npz.keys().filter(|&k| k != key) {
        w.add(k, npz.get(k).unwrap().clone());
    }
    w.add(key, array);
    // As bytes: the writer refuses the NaN these files are made of.
    std::fs::write(to, w.to_bytes()).unwrap();
}

/// A checkpoint edited by hand or cut short resumes into NaN unless refused: every counter,
/// moment and parameter is checked, naming the file and the field.
#[test]
fn a_corrupt_checkpoint_is_refused_naming_its_field() {
    use mannequin_io::NpyArray;
    let data = subject("corrupt");
    let mut t = trainer(&data, Method::Tavatar, 6);
    for _ in 0..2 {
        t.step().unwrap();
    }
    let good = data.join("good.npz");
    let run = record(&t, &data);
    t.save_checkpoint(&good, &run).unwrap();
    let first = &t.avatar.params[0];
    let [r, c] = first.value.dims();
    let corrupt = |i: usize, value: f32| {
        let mut v = vec![0.001f32; r * c];
        v[i] = value;
        NpyArray::f32(vec![r, c], v)
    };
    let (v, m, p) =
        (format!("adam_v/{}", first.name), format!("adam_m/{}", first.name), format!("param/{}", first.name));
    let cases = [
        (
            "iteration",
            NpyArray::i64(vec![1], vec![-5]),
            "expected an iteration from 0 to 6 (the run's --iters), found -5",
        ),
        ("iteration", NpyArray::i64(vec![1], vec![1 << 62]), "found 4611686018427387904"),
        ("iteration", NpyArray::i64(vec![1], vec![7]), "from 0 to 6"),
        ("iteration", NpyArray::f64(vec![1], vec![2.5]), "expected one integer"),
        (
            "adam_step",
            NpyArray::i64(vec![1], vec![0]),
            "expected 2 (one optimiser step per iteration), found 0",
        ),
        (v.as_str(), corrupt(3, -1.0), "element 3 is -1: expected 0–3.4028234663852886e38"),
        (v.as_str(), corrupt(0, f32::INFINITY), "is inf"),
        (m.as_str(), corrupt(1, f32::NAN), "is NaN: expected a finite number"),
        (p.as_str(), corrupt(0, f32::NAN), "is NaN"),
        (p.as_str(), NpyArray::f32(vec![r + 1, c], vec![0.0; (r + 1) * c]), "expected shape"),
    ];
    for (key, array, expected) in cases {
        let path = data.join("bad.npz");
        with_array(&good, &path, key, array);
        let mut fresh = trainer(&data, Method::Tavatar, 6);
        let e = match Checkpoint::open(&path, &run, &[]) {
            Err(e) => e,
            Ok(c) => fresh.resume(&c, &run).expect_err(key),
        }
        .to_string();
        assert!(
            e.contains("bad.npz") && e.contains(&format!("'{key}'")) && e.contains(expected),
            "{key}: {e}"
        );
    }
    let mut fresh = trainer(&data, Method::Tavatar, 6);
    fresh.resume(&Checkpoint::open(&good, &run, &[]).unwrap(), &run).unwrap();
    assert_eq!(fresh.iteration, 2);
    std::fs::remove_dir_all(data).ok();
}
