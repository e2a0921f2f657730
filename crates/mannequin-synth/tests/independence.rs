//! The shape of the crate graph, read from `cargo metadata`, so a new crate is covered the day it
//! is added (only workspace crates matter, so the workspace's own manifests, `--no-deps`, are the
//! whole graph):
//!
//! - A method must not share code with the data it is judged on: no workspace crate but the
//!   command line may depend on the synthetic generator, directly or through another workspace
//!   crate (dev-dependencies, which tests and benches use to measure, are allowed).
//! - The crates form floors: every dependency points strictly down, normal ones and
//!   dev-dependencies (tests and benches) alike, except a dev-dependency on the generator, which
//!   a crate's tests may use to measure on synthetic subjects.

use std::collections::BTreeMap;
use std::process::Command;

/// How a crate depends on another: to build (normal and build-dependencies) or only to test and
/// bench.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Normal,
    Dev,
}

/// Each workspace crate's dependencies on other workspace crates.
type Graph = BTreeMap<String, Vec<(String, Kind)>>;

const GENERATOR: &str = "mannequin-synth";

fn workspace() -> Graph {
    let out = Command::new(env!("CARGO"))
        .args(["metadata", "--format-version", "1", "--offline", "--no-deps", "--manifest-path"])
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/../../Cargo.toml"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let packages = meta["packages"].as_array().unwrap();
    let names: Vec<&str> = packages.iter().map(|p| p["name"].as_str().unwrap()).collect();
    packages
        .iter()
        .map(|p| {
            let deps = p["dependencies"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|d| names.contains(&d["name"].as_str().unwrap()))
                .map(|d| {
                    let kind = if d["kind"] == "dev" { Kind::Dev } else { Kind::Normal };
                    (d["name"].as_str().unwrap().to_string(), kind)
                })
                .collect();
            (p["name"].as_str().unwrap().to_string(), deps)
        })
        .collect()
}

/// The edges a floor must sit above: all but a dev-dependency on the generator.
fn counted(deps: &[(String, Kind)]) -> impl Iterator<Item = &(String, Kind)> {
    deps.iter().filter(|(to, kind)| !(*kind == Kind::Dev && to == GENERATOR))
}

/// Each crate's floor: 0 with no workspace dependency, else one above its highest counted
/// dependency, so every counted edge points strictly down. `Err` names the edges of a cycle, one
/// of which would have to point up.
fn floors(graph: &Graph) -> Result<BTreeMap<&str, usize>, String> {
    fn visit<'a>(
        graph: &'a Graph,
        at: &'a str,
        path: &mut Vec<(&'a str, Kind)>,
        floor: &mut BTreeMap<&'a str, usize>,
    ) -> Result<usize, String> {
        if let Some(&f) = floor.get(at) {
            return Ok(f);
        }
        if let Some(start) = path.iter().position(|(name, _)| *name == at) {
            let edges: Vec<String> = path[start..]
                .windows(2)
                .map(|w| w[1].0)
                .chain([at])
                .zip(&path[start..])
                .map(|(to, (from, kind))| match kind {
                    Kind::Normal => format!("{from} → {to}"),
                    Kind::Dev => format!("{from} → {to} (dev)"),
                })
                .collect();
            return Err(format!("no floors for the cycle {}", edges.join(", ")));
        }
        let mut f = 0;
        for (to, kind) in counted(graph.get(at).map_or(&[][..], Vec::as_slice)) {
            path.push((at, *kind));
            f = f.max(visit(graph, to, path, floor)? + 1);
            path.pop();
        }
        floor.insert(at, f);
        Ok(f)
    }
    let mut floor = BTreeMap::new();
    for name in graph.keys() {
        visit(graph, name, &mut Vec::new(), &mut floor)?;
    }
    Ok(floor)
}

#[test]
fn no_reconstruction_crate_depends_on_the_generator() {
    let graph = workspace();
    let normal = |name: &str| -> Vec<&str> {
        graph[name].iter().filter(|(_, k)| *k == Kind::Normal).map(|(d, _)| d.as_str()).collect()
    };
    let mut checked = Vec::new();
    for name in graph.keys().map(String::as_str) {
        if matches!(name, "mannequin" | GENERATOR) {
            continue;
        }
        let mut stack = vec![name];
        let mut seen = vec![name];
        while let Some(at) = stack.pop() {
            for dep in normal(at) {
                assert_ne!(dep, GENERATOR, "{name} depends on the synthetic generator (through {at})");
                if !seen.contains(&dep) {
                    seen.push(dep);
                    stack.push(dep);
                }
            }
        }
        checked.push(name);
    }
    for must in ["mannequin-avatar", "mannequin-garment", "mannequin-data", "mannequin-raster"] {
        assert!(checked.contains(&must), "{must} was not checked: {checked:?}");
    }
    // The check can fail: the command line does depend on the generator, and is found to.
    assert!(normal("mannequin").contains(&GENERATOR));
}

#[test]
fn the_crates_form_floors_and_every_dependency_points_down() {
    let graph = workspace();
    let floor = floors(&graph).unwrap_or_else(|e| panic!("{e}"));
    let mut by_floor: BTreeMap<usize, Vec<&str>> = BTreeMap::new();
    for (name, f) in &floor {
        by_floor.entry(*f).or_default().push(name);
    }
    for (f, names) in &by_floor {
        println!("floor {f}: {}", names.join(", "));
    }
    // Every counted edge points strictly down (so by construction), and so does each crate's
    // place in the house: files, then geometry, then datasets, the rasteriser, reconstruction,
    // the generator and the command line.
    for (name, deps) in &graph {
        for (to, _) in counted(deps) {
            assert!(floor[name.as_str()] > floor[to.as_str()], "{name} → {to} does not point down");
        }
    }
    let order = ["mannequin-io", "mannequin-mesh", "mannequin-data", "mannequin-raster", "mannequin-garment"];
    for pair in
        order.windows(2).chain([["mannequin-garment", GENERATOR].as_slice(), &[GENERATOR, "mannequin"]])
    {
        assert!(floor[pair[0]] < floor[pair[1]], "{} is not below {}: {by_floor:?}", pair[0], pair[1]);
    }
}

/// The floor check can fail: on a made-up house, an upward dev-dependency and an upward normal
/// one are each named, while a dev-dependency on the generator is let through.
#[test]
fn an_upward_edge_is_caught() {
    let house = |edges: &[(&str, &str, Kind)]| -> Graph {
        let mut g = Graph::new();
        for (from, to, kind) in edges {
            g.entry(from.to_string()).or_default().push((to.to_string(), *kind));
            g.entry(to.to_string()).or_default();
        }
        g
    };
    let sound = house(&[
        ("data", "io", Kind::Normal),
        ("garment", "data", Kind::Normal),
        (GENERATOR, "garment", Kind::Normal),
        ("data", GENERATOR, Kind::Dev),
    ]);
    let floor = floors(&sound).unwrap();
    assert_eq!((floor["io"], floor["data"], floor["garment"], floor[GENERATOR]), (0, 1, 2, 3));

    let dev_up = house(&[
        ("data", "io", Kind::Normal),
        ("garment", "data", Kind::Normal),
        ("data", "garment", Kind::Dev),
    ]);
    let e = floors(&dev_up).unwrap_err();
    assert!(e.contains("data → garment (dev)") && e.contains("garment → data"), "{e}");

    let normal_up = house(&[("mesh", "io", Kind::Normal), ("io", "mesh", Kind::Normal)]);
    let e = floors(&normal_up).unwrap_err();
    assert!(e.contains("io → mesh") && e.contains("mesh → io") && !e.contains("(dev)"), "{e}");
}
