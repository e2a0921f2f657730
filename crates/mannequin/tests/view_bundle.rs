//! The page `mannequin view` embeds (viewer/dist/) is what viewer/build.sh makes from viewer/src
//! and the pinned packages: a change to the page's source that was not rebuilt fails here.
//!
//! Needs Node and npm, and the npm registry (or npm's cache) for the pinned packages; where npm
//! is missing or cannot install them (offline) the test fails under CI (`CI` or
//! `MANNEQUIN_REQUIRE_BROWSER` set) and is skipped with a warning elsewhere.

use std::io::Write;
use std::path::Path;
use std::process::Command;

mod common;
use common::scratch;

#[test]
fn the_embedded_page_is_built_from_its_source() {
    let viewer = Path::new(env!("CARGO_MANIFEST_DIR")).join("viewer");
    let required = ["CI", "MANNEQUIN_REQUIRE_BROWSER"]
        .iter()
        .any(|v| std::env::var(v).is_ok_and(|v| !matches!(v.as_str(), "" | "0" | "false")));
    let npm = Command::new("npm").arg("--version").output().is_ok_and(|o| o.status.success());
    if !npm {
        assert!(
            !required,
            "npm not found, so the page's bundle was not checked (apt-get install nodejs npm)"
        );
        let _ = writeln!(std::io::stderr(), "warning: npm not found; the page's bundle was not checked");
        return;
    }
    let dir = scratch("view-bundle");
    for file in ["package.json", "package-lock.json", "build.sh"] {
        std::fs::copy(viewer.join(file), dir.join(file)).unwrap();
    }
    std::fs::create_dir_all(dir.join("src")).unwrap();
    for entry in std::fs::read_dir(viewer.join("src")).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, dir.join("src").join(path.file_name().unwrap())).unwrap();
    }
    let mut build = Command::new("bash");
    build.arg(dir.join("build.sh"));
    if !required {
        // Offline, npm retries every package for about a minute; one try tells.
        build.env("npm_config_fetch_retries", "0");
    }
    let out = build.output().unwrap();
    if !out.status.success() && !dir.join("node_modules/three").is_dir() {
        let why = "npm could not install the page's pinned packages (is the npm registry reachable?)";
        assert!(!required, "{why}:\n{}", String::from_utf8_lossy(&out.stderr));
        let _ = writeln!(std::io::stderr(), "warning: {why}; the page's bundle was not checked");
        return;
    }
    assert!(out.status.success(), "build.sh failed:\n{}", String::from_utf8_lossy(&out.stderr));
    for file in ["viewer.js", "LICENSES.txt"] {
        let built = std::fs::read(dir.join("dist").join(file)).unwrap();
        let committed = std::fs::read(viewer.join("dist").join(file)).unwrap();
        assert!(
            built == committed,
            "viewer/dist/{file} is stale: run crates/mannequin/viewer/build.sh and commit it"
        );
    }
}
