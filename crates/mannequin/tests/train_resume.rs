//! `train` checkpoints as a user meets them, on a tiny synthetic subject: a run killed mid-way
//! and started again ends bit-identical to an uninterrupted one, a resume with other settings is
//! refused in one line before any training, and so is a checkpoint edited outside the run,
//! `--restart` drops the old checkpoint at once, and a run that fails leaves no model.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::OnceLock;

use mannequin_io::{NpyData, Npz};

mod common;
use common::{ok, s, scratch, tiny_subject};

/// One thread: the claim is about checkpoints, and rayon's adaptive splitting may reorder float
/// reductions between runs on a loaded machine.
fn command(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_mannequin"));
    c.args(args).env("RAYON_NUM_THREADS", "1").env_remove("RUST_LOG");
    c
}

/// One synthetic subject for every test.
fn data() -> &'static Path {
    static DATA: OnceLock<PathBuf> = OnceLock::new();
    DATA.get_or_init(|| {
        let data = scratch("train-resume-data").join("subject");
        ok(command(&tiny_subject("3", &data)).output().unwrap());
        data
    })
}

/// `train` on the shared subject into `out`, with `extra` flags.
fn train(out: &Path, extra: &[&str]) -> Command {
    let base = ["train", "--data", s(data()), "--out", s(out), "--body", "default-lod1"];
    command(&[&base[..], extra].concat())
}

/// The iteration a model folder's checkpoint holds, if it has a readable one.
fn checkpoint_iteration(out: &Path) -> Option<i64> {
    let npz = Npz::read(out.join("checkpoint.npz")).ok()?;
    Some(npz.get("iteration")?.to_i64()?[0])
}

/// A training process, killed if a test fails while it runs.
struct Running(Child);

impl Running {
    fn start(mut c: Command, log: &Path) -> Self {
        let log = std::fs::File::create(log).unwrap();
        Self(c.stdout(Stdio::null()).stderr(log).spawn().unwrap())
    }

    /// Waits until `ready` holds, failing if the process ends first; then kills it (SIGKILL).
    fn kill_when(mut self, log: &Path, ready: impl Fn() -> bool) {
        while !ready() {
            if let Some(status) = self.0.try_wait().unwrap() {
                panic!("train ended ({status}) too soon: {}", std::fs::read_to_string(log).unwrap());
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        self.0.kill().unwrap();
        self.0.wait().unwrap();
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Every learned array of a model folder, as raw bits.
fn parameters(out: &Path) -> Vec<(String, Vec<u32>)> {
    let npz = Npz::read(out.join("avatar.npz")).unwrap();
    let params: Vec<_> = npz
        .keys()
        .filter(|k| k.starts_with("param/"))
        .map(|k| match &npz.get(k).unwrap().data {
            NpyData::F32(v) => (k.to_string(), v.iter().map(|x| x.to_bits()).collect()),
            other => panic!("{k}: expected float32, found {other:?}"),
        })
        .collect();
    assert!(!params.is_empty(), "no parameters in {}", out.display());
    params
}

#[test]
fn a_killed_run_resumes_to_the_uninterrupted_result_bit_for_bit() {
    let dir = scratch("train-resume-killed");
    let (straight, killed) = (dir.join("straight"), dir.join("killed"));
    let flags = ["--iters", "20", "--checkpoint-every", "2"];
    ok(train(&straight, &flags).output().unwrap());

    let log = dir.join("killed.log");
    Running::start(train(&killed, &flags), &log)
        .kill_when(&log, || checkpoint_iteration(&killed).is_some_and(|i| i >= 4));
    let stopped_at = checkpoint_iteration(&killed).unwrap();
    assert!((4..20).contains(&stopped_at), "the run was not cut short: checkpoint at {stopped_at}");

    let resumed = ok(train(&killed, &flags).output().unwrap());
    let log = String::from_utf8_lossy(&resumed.stderr);
    assert!(log.contains(&format!("at iteration {stopped_at}")), "did not resume: {log}");
    let (a, b) = (parameters(&straight), parameters(&killed));
    assert_eq!(a.len(), b.len());
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "parameter {name} differs after the killed run resumed");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// The one error line of a failed run.
fn error_line(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    lines[0].to_string()
}

#[test]
fn other_settings_are_refused_and_restart_drops_the_checkpoint_first() {
    let dir = scratch("train-resume-settings");
    let out = dir.join("model");
    let flags = ["--iters", "2", "--checkpoint-every", "1"];
    ok(train(&out, &flags).output().unwrap());
    let files = ["checkpoint.npz", "avatar.npz", "avatar.json"];
    let before: Vec<Vec<u8>> = files.iter().map(|f| std::fs::read(out.join(f)).unwrap()).collect();

    for (extra, named) in [
        (&["--iters", "3"][..], "options.iters was 2, now 3"),
        (&["--iters", "2", "--seed", "5"], "avatar.seed was 0, now 5"),
        (&["--iters", "2", "--no-equilateral"], "options.lambda_equilateral was 0.01, now 0.0"),
        (&["--iters", "2", "--downscale", "2"], "downscale was 1, now 2"),
        (&["--iters", "2", "--skirt", "off"], "skirt was auto, now off"),
        (&["--iters", "2", "--subdivide", "1"], "avatar.subdivisions was 0, now 1"),
    ] {
        let line = error_line(&train(&out, extra).output().unwrap());
        for needle in [named, "checkpoint.npz", "--restart"] {
            assert!(line.contains(needle), "'{needle}' not in: {line}");
        }
    }
    // Nothing was written: the refusal came before any work.
    for (f, bytes) in files.iter().zip(&before) {
        assert!(&std::fs::read(out.join(f)).unwrap() == bytes, "{f} changed");
    }

    // A restart stopped before its first checkpoint has already dropped the old one, so the
    // next plain run starts over instead of resuming the old run; the old model stays until
    // the new one is finished.
    let log = dir.join("restart.log");
    let restart = train(&out, &["--restart", "--iters", "1000", "--checkpoint-every", "1000"]);
    let training = || std::fs::read_to_string(&log).is_ok_and(|l| l.contains("Gaussians on"));
    Running::start(restart, &log).kill_when(&log, training);
    assert!(!out.join("checkpoint.npz").exists(), "--restart left the old checkpoint");
    assert!(std::fs::read(out.join("avatar.npz")).unwrap() == before[1], "the old model was replaced");
    std::fs::remove_dir_all(dir).unwrap();
}

/// `checkpoint` rewritten with `key` replaced by `array`, every other array as it was.
fn edit_checkpoint(checkpoint: &Path, key: &str, array: mannequin_io::NpyArray) {
    let npz = Npz::read(checkpoint).unwrap();
    let mut w = mannequin_io::NpzWriter::uncompressed();
    for k in npz.keys().filter(|&k| k != key) {
        w.add(k, npz.get(k).unwrap().clone());
    }
    w.add(key, array);
    std::fs::write(checkpoint, w.to_bytes()).unwrap();
}

/// A checkpoint edited by hand once resumed into a NaN avatar ("running PSNR NaN dB"): a
/// negative Adam second moment, or an iteration before the run or past its end, is refused in
/// one line naming the file and the field, and the model folder is left as it was.
#[test]
fn a_checkpoint_outside_the_run_is_refused_by_field() {
    use mannequin_io::NpyArray;
    let dir = scratch("train-resume-corrupt");
    let out = dir.join("model");
    let flags = ["--iters", "2", "--checkpoint-every", "1"];
    ok(train(&out, &flags).output().unwrap());
    let checkpoint = out.join("checkpoint.npz");
    let good = std::fs::read(&checkpoint).unwrap();
    let model = std::fs::read(out.join("avatar.npz")).unwrap();
    let v = Npz::read(&checkpoint).unwrap().keys().find(|k| k.starts_with("adam_v/")).unwrap().to_string();
    let moment = Npz::read(&checkpoint).unwrap().get(&v).unwrap().clone();
    let mut negative = moment.to_f32().unwrap();
    negative[1] = -0.25;
    for (key, array, expected) in [
        (v.as_str(), NpyArray::f32(moment.shape.clone(), negative), "element 1 is -0.25: expected 0–"),
        (
            "iteration",
            NpyArray::i64(vec![1], vec![-5]),
            "expected an iteration from 0 to 2 (the run's --iters), found -5",
        ),
        ("iteration", NpyArray::i64(vec![1], vec![1 << 62]), "found 4611686018427387904"),
        ("iteration", NpyArray::i64(vec![1], vec![3]), "found 3"),
    ] {
        std::fs::write(&checkpoint, &good).unwrap();
        edit_checkpoint(&checkpoint, key, array);
        let edited = std::fs::read(&checkpoint).unwrap();
        let line = error_line(&train(&out, &flags).output().unwrap());
        for needle in ["checkpoint.npz", &format!("'{key}'"), expected, "--restart"] {
            assert!(line.contains(needle), "'{needle}' not in: {line}");
        }
        assert!(std::fs::read(&checkpoint).unwrap() == edited, "{key}: the checkpoint changed");
        assert!(std::fs::read(out.join("avatar.npz")).unwrap() == model, "{key}: avatar.npz changed");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A run that fails writes no model: a folder holding `avatar.npz` is a trained avatar, never an
/// untrained one that `render` would go on to use.
#[test]
fn a_failing_run_leaves_no_model() {
    let dir = scratch("train-resume-nan-pose");
    let subject = dir.join("subject");
    ok(Command::new("cp").arg("-r").arg(data()).arg(&subject).output().unwrap());
    let poses = subject.join("poses/anim_nerf_train.npz");
    let npz = Npz::read(&poses).unwrap();
    let mut body = npz.get("body_pose").unwrap().clone();
    if let NpyData::F32(v) = &mut body.data {
        v.iter_mut().step_by(69).for_each(|x| *x = f32::NAN);
    }
    let mut w = mannequin_io::NpzWriter::new();
    for k in npz.keys().filter(|&k| k != "body_pose") {
        w.add(k, npz.get(k).unwrap().clone());
    }
    w.add("body_pose", body);
    // As bytes: the writer refuses the NaN this file is made of.
    std::fs::write(&poses, w.to_bytes()).unwrap();
    let out = dir.join("model");
    let base = ["train", "--data", s(&subject), "--out", s(&out), "--body", "default-lod1"];
    let o = command(&[&base[..], &["--iters", "4", "--checkpoint-every", "4"]].concat()).output().unwrap();
    let line = error_line(&o);
    assert!(line.contains("not finite") || line.contains("NaN"), "{line}");
    assert!(!out.exists(), "a failed run left {:?}", std::fs::read_dir(&out).map(|d| d.count()));
    std::fs::remove_dir_all(dir).unwrap();
}
