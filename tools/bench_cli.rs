//! Running the `mannequin` program from a bench of the `mannequin` crate (included with
//! `#[path]`): with the bench's own template cache, failing loudly with the program's log.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Runs `mannequin args…` with `XDG_CACHE_HOME` at `cache`; the seconds it took.
pub fn mannequin<S: AsRef<std::ffi::OsStr> + std::fmt::Debug>(args: &[S], cache: &Path) -> f64 {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_mannequin"))
        .args(args)
        .env("XDG_CACHE_HOME", cache)
        .output()
        .unwrap();
    assert!(out.status.success(), "mannequin {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    start.elapsed().as_secs_f64()
}

/// The synthetic subject of seed `seed` (540², `mannequin synth`'s defaults) under `root`, made
/// once and kept between runs (synth is deterministic).
#[allow(dead_code)] // not every bench that runs the program makes subjects
pub fn subject(seed: u64, root: &Path, cache: &Path) -> PathBuf {
    let dir = root.join(format!("subject-{seed}"));
    if !dir.join("subject.json").exists() {
        let _ = std::fs::remove_dir_all(&dir);
        mannequin(
            &["synth".into(), "--seed".into(), seed.to_string(), "--out".into(), dir.display().to_string()],
            cache,
        );
    }
    dir
}
