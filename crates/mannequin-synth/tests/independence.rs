//! A method must not share code with the data it is judged on: no workspace crate but the
//! command line may depend on the synthetic generator, directly or through another workspace
//! crate (dev-dependencies, which tests and benches use to measure, are allowed). Read from
//! `cargo metadata`, so a new crate is covered the day it is added. Only workspace crates can
//! lead to the generator, so the workspace's own manifests (`--no-deps`) are the whole graph.

use std::collections::HashMap;
use std::process::Command;

#[test]
fn no_reconstruction_crate_depends_on_the_generator() {
    let out = Command::new(env!("CARGO"))
        .args(["metadata", "--format-version", "1", "--offline", "--no-deps", "--manifest-path"])
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/../../Cargo.toml"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Each workspace package's normal (not dev, not build) dependencies, by name.
    let normal: HashMap<&str, Vec<&str>> = meta["packages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let deps = p["dependencies"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|d| d["kind"].is_null())
                .map(|d| d["name"].as_str().unwrap())
                .collect();
            (p["name"].as_str().unwrap(), deps)
        })
        .collect();
    let mut checked = Vec::new();
    for &name in normal.keys() {
        if matches!(name, "mannequin" | "mannequin-synth") {
            continue;
        }
        let mut stack = vec![name];
        let mut seen = vec![name];
        while let Some(at) = stack.pop() {
            for &dep in normal.get(at).into_iter().flatten() {
                assert_ne!(
                    dep, "mannequin-synth",
                    "{name} depends on the synthetic generator (through {at})"
                );
                if normal.contains_key(dep) && !seen.contains(&dep) {
                    seen.push(dep);
                    stack.push(dep);
                }
            }
        }
        checked.push(name);
    }
    for must in ["mannequin-avatar", "mannequin-garment", "mannequin-data"] {
        assert!(checked.contains(&must), "{must} was not checked: {checked:?}");
    }
    // The check can fail: the command line does depend on the generator, and is found to.
    assert!(normal["mannequin"].contains(&"mannequin-synth"));
}
