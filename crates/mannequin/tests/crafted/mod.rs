//! Crafted bad input, as a new user's broken files and flags arrive (issue 42): each case is one
//! `mannequin` command that must be refused in one line naming the file or flag and the field,
//! with no panic, no hang, peak memory within [`PEAK_RSS_LIMIT`], and nothing left behind in its
//! folder. Each module makes the cases of one area from shared [`Fixtures`].

pub mod avatar;
pub mod cloth;
pub mod inputs;
pub mod run;

use std::path::{Path, PathBuf};

use crate::common::{mannequin, ok, s};

/// Peak resident memory any case may reach (issue 42: 1 GB for any input under 10 MB and any
/// flag value).
pub const PEAK_RSS_LIMIT: u64 = 1 << 30;

/// What a case must end in.
#[derive(Debug, Clone)]
pub enum Expect {
    /// Exit code 1 and one `error:` line holding every needle (the file or flag, the field).
    Refused(Vec<String>),
    /// A usage error from the argument parser (exit code 2) naming every needle, before any work.
    Usage(Vec<String>),
}

/// One crafted command.
#[derive(Debug, Clone)]
pub struct Case {
    /// `area/what`, unique, shown when the case fails.
    pub name: String,
    /// The case's own folder: its crafted inputs and its outputs live here, and a refused command
    /// must leave it exactly as it was.
    pub dir: PathBuf,
    pub args: Vec<String>,
    pub expect: Expect,
}

impl Case {
    /// A case whose command must be refused naming each of `needles`.
    pub fn refused(name: impl Into<String>, dir: &Path, args: &[&str], needles: &[&str]) -> Case {
        Case::new(name, dir, args, Expect::Refused(needles.iter().map(|n| n.to_string()).collect()))
    }

    /// A case whose flags the argument parser itself must refuse naming each of `needles`.
    pub fn usage(name: impl Into<String>, dir: &Path, args: &[&str], needles: &[&str]) -> Case {
        Case::new(name, dir, args, Expect::Usage(needles.iter().map(|n| n.to_string()).collect()))
    }

    fn new(name: impl Into<String>, dir: &Path, args: &[&str], expect: Expect) -> Case {
        Case {
            name: name.into(),
            dir: dir.to_path_buf(),
            args: args.iter().map(|a| a.to_string()).collect(),
            expect,
        }
    }
}

/// How an area makes its cases: from the fixtures, into its own folder.
pub type MakeCases = fn(&Fixtures, &Path) -> Vec<Case>;

/// Good files every area starts from and mutates copies of. Read-only for cases: a case that
/// writes must point its outputs into its own folder (the harness checks the fixtures are
/// unchanged at the end).
pub struct Fixtures {
    /// The folder holding the fixtures.
    pub root: PathBuf,
    /// A tiny synthetic subject (96², 10 frames, the light body `default-lod1`).
    pub data: PathBuf,
    /// An avatar trained on `data` for three iterations, with its checkpoint.
    pub model: PathBuf,
    /// A one-second procedural walk, AMASS `.npz` at 30 fps.
    pub motion: PathBuf,
}

impl Fixtures {
    /// Makes the fixtures under `root` (a few seconds).
    pub fn make(root: &Path) -> Fixtures {
        let (data, model) = crate::common::tiny_avatar(root);
        let motion = root.join("walk.npz");
        ok(mannequin(&["motion", "walk", "-o", s(&motion), "--seconds", "1", "--fps", "30"]));
        Fixtures { root: root.to_path_buf(), data, model, motion }
    }
}

/// A fresh folder for the case `name` under `dir` (`/` in names become folders).
pub fn case_dir(dir: &Path, name: &str) -> PathBuf {
    let d = dir.join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A good file's bytes broken the ways files break: emptied, cut short at a tenth, a half and
/// nine tenths, and replaced by noise as long.
pub fn broken_bytes(good: &[u8]) -> Vec<(String, Vec<u8>)> {
    let mut out = vec![("empty".to_string(), Vec::new())];
    for share in [10, 50, 90] {
        out.push((format!("cut_{share}"), good[..good.len() * share / 100].to_vec()));
    }
    let mut rng = mannequin_io::rng::SplitMix64::new(42);
    out.push(("random".to_string(), (0..good.len().max(64)).map(|_| rng.next_u64() as u8).collect()));
    out
}

pub use crate::common::copy_dir;

/// The `.npz` at `from` written to `to` with `key` replaced by `array` (or removed when `None`;
/// added when the archive lacks it), every other array as it was.
pub fn npz_with(from: &Path, to: &Path, key: &str, array: Option<mannequin_io::NpyArray>) {
    let npz = mannequin_io::Npz::read(from).unwrap();
    let mut out = mannequin_io::NpzWriter::new();
    for k in npz.keys().filter(|&k| k != key) {
        out.add(k, npz.get(k).unwrap().clone());
    }
    if let Some(a) = array {
        out.add(key, a);
    }
    // The bytes, not `write`: the writer refuses the non-finite numbers a crafted file holds.
    std::fs::write(to, out.to_bytes()).unwrap();
}
