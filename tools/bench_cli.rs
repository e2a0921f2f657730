//! Running the `mannequin` program from a bench of the `mannequin` crate (included with
//! `#[path]`): with the bench's own template cache, failing loudly with the program's log.

use std::path::Path;
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
