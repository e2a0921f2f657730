//! The Node checks in tools/ for the tests that write glTF files (included with `#[path]`): the
//! Khronos glTF-Validator (gltf_validate.mjs) and three.js's loader (gltf_three_check.mjs).
//!
//! Where Node or a check's npm package is missing, the test fails under CI (`CI` or
//! `MANNEQUIN_REQUIRE_GLTF_VALIDATOR` set), so CI cannot pass without running the checks; elsewhere
//! it warns on the terminal (past the harness's capture) and skips the check.
#![allow(dead_code)] // Each test file uses the checks it needs.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A script in tools/, the npm package it loads, where `.ci/run` installs that, and the variable
/// that overrides the package's folder.
pub struct NodeCheck {
    script: &'static str,
    package: &'static str,
    prefix: &'static str,
    dir_var: &'static str,
}

pub const KHRONOS_VALIDATOR: NodeCheck = NodeCheck {
    script: "gltf_validate.mjs",
    package: "gltf-validator",
    prefix: ".cache/gltf-validator",
    dir_var: "GLTF_VALIDATOR_DIR",
};

pub const THREE_JS: NodeCheck = NodeCheck {
    script: "gltf_three_check.mjs",
    package: "three",
    prefix: ".cache/three-check",
    dir_var: "THREE_DIR",
};

/// Whether a missing check fails the test rather than skipping it.
fn required() -> bool {
    let set = |var| std::env::var(var).is_ok_and(|v| !matches!(v.as_str(), "" | "0" | "false"));
    set("CI") || set("MANNEQUIN_REQUIRE_GLTF_VALIDATOR")
}

impl NodeCheck {
    /// The check's report (stdout) on `file`, after asserting that it passed; `None` when the
    /// check is not installed and not required.
    pub fn run(&self, file: &Path) -> Option<String> {
        let home = PathBuf::from(std::env::var_os("HOME").unwrap_or_default());
        let prefix = home.join(self.prefix);
        let dir = std::env::var_os(self.dir_var)
            .map_or_else(|| prefix.join("node_modules").join(self.package), PathBuf::from);
        let node = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
        if !(node && dir.join("package.json").exists()) {
            let npm = format!("npm install --prefix \"{}\" {}", prefix.display(), self.package);
            let (missing, install) = match node {
                true => (format!("{} not found at {}", self.package, dir.display()), npm),
                false => ("node not found".into(), format!("apt-get install nodejs npm && {npm}")),
            };
            let message = format!("{missing}, so tools/{} did not run; install with: {install}", self.script);
            assert!(!required(), "{message} (required under CI or MANNEQUIN_REQUIRE_GLTF_VALIDATOR)");
            // The harness captures print macros, not writes to the handle: this one shows.
            let _ = writeln!(std::io::stderr(), "warning: {message}");
            return None;
        }
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools").join(self.script);
        let out = Command::new("node").arg(&script).arg(file).env(self.dir_var, &dir).output().unwrap();
        let report = String::from_utf8_lossy(&out.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "tools/{} failed on {}:\n{report}{stderr}",
            self.script,
            file.display()
        );
        Some(report)
    }
}
