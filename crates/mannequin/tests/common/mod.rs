//! What every CLI test needs: the binary, its outcome, and scratch folders.
#![allow(dead_code)] // each test binary uses its own part

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `mannequin args…` to completion.
pub fn mannequin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mannequin")).args(args).output().unwrap()
}

/// The output of a run that must succeed (its stderr in the failure message otherwise).
pub fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `mannequin synth` arguments of a tiny subject at `out` (64 px, 10 frames of which 8 train,
/// the decimated body), simulated without cloth–cloth contacts: the tests that take it are not
/// about the cloth.
pub fn tiny_subject<'a>(seed: &'a str, out: &'a Path) -> [&'a str; 16] {
    sized_subject(seed, "64", "1", out)
}

/// [`tiny_subject`] at `size` pixels, rendered at `supersample` times that.
pub fn sized_subject<'a>(seed: &'a str, size: &'a str, supersample: &'a str, out: &'a Path) -> [&'a str; 16] {
    [
        "synth",
        "--no-self-collision",
        "--seed",
        seed,
        "--size",
        size,
        "--supersample",
        supersample,
        "--frames",
        "10",
        "--train",
        "8",
        "--body",
        "default-lod1",
        "--out",
        s(out),
    ]
}

/// Scratch folder `name` under the test target's temporary folder, emptied.
pub fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A failure the way a user sees one: exit code 1, no panic, and one `error:` line naming
/// each of `needles`.
pub fn one_line_error(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let line =
        err.lines().find(|l| l.starts_with("error:")).unwrap_or_else(|| panic!("no error line in {err}"));
    for n in needles {
        assert!(line.contains(n), "'{n}' not in: {line}");
    }
}

/// A usage error from clap: exit code 2, before any work, naming each of `needles`.
pub fn usage_error(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for n in needles {
        assert!(err.contains(n), "'{n}' not in: {err}");
    }
}

/// A tiny synthetic subject (`dir/data`: 96², 10 frames, the light body) and an avatar trained on
/// it for three iterations (`dir/model`): a few seconds.
pub fn tiny_avatar(dir: &Path) -> (PathBuf, PathBuf) {
    let (data, model) = (dir.join("data"), dir.join("model"));
    ok(mannequin(&sized_subject("1", "96", "2", &data)));
    ok(mannequin(&[
        "train",
        "--data",
        s(&data),
        "--out",
        s(&model),
        "--iters",
        "3",
        "--checkpoint-every",
        "3",
        "--body",
        "default-lod1",
    ]));
    (data, model)
}

/// A JSON file the program wrote.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[path = "../../../../tools/copy_dir.rs"]
mod copy_dir_tool;
#[allow(unused_imports)] // not every test binary copies folders
pub use copy_dir_tool::copy_dir;
