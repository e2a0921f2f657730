//! The shape of the house (issue 40), read from the sources: the modules of every workspace
//! crate import one another without circles (at most two in all), and the command-line crate
//! stays thin (its `src/` at most 3,500 lines). An import is a `use` or a path through
//! `crate::`, `super::`, `self::` or a child module; a name re-exported by `pub use` counts as
//! the module that defines it, so a crate root that only re-exports joins no circle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Module = Vec<String>;

/// The source with comments and the trailing `#[cfg(test)] mod` removed (tests may import
/// anything they test).
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod").next().unwrap_or(text);
    text.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// `a::{b, c::{d, e}}` as the paths `a::b`, `a::c::d`, `a::c::e` (`self` inside braces is the
/// prefix itself; `x as y` is `x`).
fn expand(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        return vec![tree.split(" as ").next().unwrap_or(tree).trim().to_string()];
    };
    let (prefix, inner) = (&tree[..open], &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())]);
    let (mut parts, mut depth, mut current) = (Vec::new(), 0, String::new());
    for ch in inner.chars() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        if ch == ',' && depth == 0 {
            parts.push(std::mem::take(&mut current));
        } else {
            current.push(ch);
        }
    }
    parts.push(current);
    let mut out = Vec::new();
    for part in parts.iter().map(|p| p.trim()).filter(|p| !p.is_empty()) {
        for e in expand(part) {
            out.push(if e == "self" {
                prefix.trim_end_matches(':').to_string()
            } else {
                format!("{prefix}{e}")
            });
        }
    }
    out
}

/// The trees of the `use` statements in `code`, split into re-exports (`pub use`) and imports,
/// and the code without them.
fn use_trees(code: &str) -> (Vec<String>, Vec<String>, String) {
    let (mut exports, mut imports, mut rest) = (Vec::new(), Vec::new(), String::new());
    let mut kept = 0;
    let mut from = 0;
    while let Some(found) = code[from..].find("use ") {
        let at = from + found;
        from = at + 4;
        let before = code[..at].trim_end();
        let boundary =
            before.is_empty() || before.ends_with([';', '}', '{', ')', ']']) || before.ends_with("pub");
        if !boundary || code[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let Some(end) = code[from..].find(';') else { break };
        let tree = code[from..from + end].to_string();
        // A "use " inside a string or a sentence is not a statement.
        if !tree.chars().all(|c| c.is_alphanumeric() || "_:{},* \n\t".contains(c)) {
            continue;
        }
        rest.push_str(&code[kept..at]);
        kept = from + end + 1;
        if before.ends_with("pub") || before.ends_with("pub(crate)") || before.ends_with("pub(super)") {
            exports.push(tree);
        } else {
            imports.push(tree);
        }
    }
    rest.push_str(&code[kept.min(code.len())..]);
    (exports, imports, rest)
}

/// Every `a::b::c` path written in `code` outside `use` statements.
fn paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut current = String::new();
    let chars: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_alphanumeric() || c == '_' {
            current.push(c);
        } else if c == ':' && chars.get(i + 1) == Some(&':') && !current.is_empty() {
            current.push_str("::");
            i += 1;
        } else {
            if current.contains("::") {
                out.push(current.trim_end_matches(':').to_string());
            }
            current.clear();
        }
        i += 1;
    }
    out
}

struct Crate {
    modules: BTreeMap<Module, String>,
}

impl Crate {
    fn read(src: &Path) -> Self {
        let mut modules = BTreeMap::new();
        let mut stack = vec![src.to_path_buf()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let p = entry.unwrap().path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|e| e == "rs") {
                    let rel = p.strip_prefix(src).unwrap().with_extension("");
                    let mut m: Module = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
                    if m.last().is_some_and(|l| l == "mod")
                        || (m.len() == 1 && (m[0] == "lib" || m[0] == "main"))
                    {
                        m.pop();
                    }
                    modules.insert(m, code(&std::fs::read_to_string(&p).unwrap()));
                }
            }
        }
        Self { modules }
    }

    /// `path` as written in module `at`, made absolute; `None` for another crate's path.
    fn absolute(&self, at: &Module, path: &str) -> Option<Module> {
        let segs: Vec<String> =
            path.split("::").map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
        let first = segs.first()?;
        let mut base = match first.as_str() {
            "crate" => Vec::new(),
            "self" => at.clone(),
            "super" => at.clone(),
            _ if self.modules.contains_key(&[at.clone(), vec![first.clone()]].concat()) => {
                return Some([at.clone(), segs].concat());
            }
            _ => return None,
        };
        let mut rest = &segs[1..];
        if first == "super" {
            base.pop();
            while rest.first().is_some_and(|s| s == "super") {
                base.pop();
                rest = &rest[1..];
            }
        }
        Some([base, rest.to_vec()].concat())
    }

    /// The module that defines what `path` names, following re-exports.
    fn owner(
        &self,
        path: &Module,
        exports: &BTreeMap<Module, BTreeMap<String, Module>>,
        hops: usize,
    ) -> Option<Module> {
        let cut = (0..=path.len()).rev().find(|&i| self.modules.contains_key(&path[..i]))?;
        let module = path[..cut].to_vec();
        if let Some(target) = path.get(cut).and_then(|name| exports[&module].get(name))
            && hops < 8
            && target != path
        {
            return self.owner(target, exports, hops + 1);
        }
        Some(module)
    }

    fn imports(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut exports = BTreeMap::new();
        for (m, code) in &self.modules {
            let mut names = BTreeMap::new();
            for tree in use_trees(code).0 {
                for p in expand(&tree) {
                    if let Some(abs) = self.absolute(m, &p) {
                        names.insert(p.rsplit("::").next().unwrap().trim().to_string(), abs);
                    }
                }
            }
            exports.insert(m.clone(), names);
        }
        let mut edges = BTreeMap::new();
        for (m, code) in &self.modules {
            let (_, trees, rest) = use_trees(code);
            let written = trees.iter().flat_map(|t| expand(t)).chain(paths(&rest));
            let to: BTreeSet<Module> = written
                .filter_map(|p| self.absolute(m, &p))
                .filter_map(|abs| self.owner(&abs, &exports, 0))
                .filter(|o| o != m)
                .collect();
            edges.insert(m.clone(), to);
        }
        edges
    }
}

/// The strongly connected groups of two or more modules (Tarjan).
fn circles(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    struct State<'a> {
        edges: &'a BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<&'a Module, usize>,
        low: BTreeMap<&'a Module, usize>,
        stack: Vec<&'a Module>,
        found: Vec<Vec<Module>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a Module) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        for w in s.edges.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                s.low.entry(v).and_modify(|l| *l = (*l).min(lw));
            } else if s.stack.contains(&w) {
                let iw = s.index[w];
                s.low.entry(v).and_modify(|l| *l = (*l).min(iw));
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = Vec::new();
            while let Some(w) = s.stack.pop() {
                group.push(w.clone());
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                s.found.push(group);
            }
        }
    }
    let mut s =
        State { edges, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), found: Vec::new() };
    for v in edges.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.found
}

fn crates_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

#[test]
fn the_house_has_at_most_two_import_circles() {
    let mut all = Vec::new();
    for entry in std::fs::read_dir(crates_dir()).unwrap() {
        let src = entry.unwrap().path().join("src");
        if src.is_dir() {
            let name = src.parent().unwrap().file_name().unwrap().to_string_lossy().into_owned();
            for group in circles(&Crate::read(&src).imports()) {
                let names: Vec<String> =
                    group.iter().map(|m| if m.is_empty() { "<root>".into() } else { m.join("::") }).collect();
                all.push(format!("{name}: {}", names.join(" <-> ")));
            }
        }
    }
    all.sort();
    println!("{} import circles:\n{}", all.len(), all.join("\n"));
    assert!(all.len() <= 2, "{} import circles (at most 2):\n{}", all.len(), all.join("\n"));
}

/// The analysis finds a circle where there is one: a crate of three modules written here.
#[test]
fn a_circle_is_found_and_a_re_export_is_not_one() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("house-circle");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("b")).unwrap();
    let files = [
        ("lib.rs", "mod a;\nmod b;\npub use a::Thing;\n"),
        ("a.rs", "use crate::b::c::helper;\npub struct Thing;\n"),
        ("b/mod.rs", "pub mod c;\n"),
        ("b/c.rs", "pub fn helper() -> crate::Thing { super::super::a::Thing }\n"),
    ];
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let edges = Crate::read(&dir).imports();
    let found = circles(&edges);
    assert_eq!(found.len(), 1, "{edges:?}");
    let mut group: Vec<String> = found[0].iter().map(|m| m.join("::")).collect();
    group.sort();
    assert_eq!(group, ["a", "b::c"]);
    std::fs::write(dir.join("b/c.rs"), "pub fn helper() {}\n").unwrap();
    assert!(circles(&Crate::read(&dir).imports()).is_empty());
}

/// Every `.rs` file under `dir`, with its text.
fn sources(dir: &Path) -> Vec<(PathBuf, String)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(d).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&p).unwrap();
                out.push((p, text));
            }
        }
    }
    out
}

/// The library crates' sources without their unit tests.
fn library_sources() -> Vec<(PathBuf, String)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(crates_dir()).unwrap() {
        let src = entry.unwrap().path().join("src");
        if src.is_dir()
            && !src.starts_with(crates_dir().join("mannequin/"))
            && !src.ends_with("mannequin/src")
        {
            out.extend(sources(&src).into_iter().map(|(p, text)| (p, code(&text))));
        }
    }
    out
}

/// Each setting's default is written once: a pipeline's settings live in its library crate, and
/// a flag's default there reads the settings' `Default` (`Settings::default().field`) instead of
/// repeating the value; the values issue 40 found written several times are each written once.
#[test]
fn every_default_is_written_once() {
    let all = library_sources();
    let cli = sources(&crates_dir().join("mannequin/src"));
    let mut repeated = Vec::new();
    for (path, code) in &all {
        for (at, _) in code.match_indices("default_value_t = ") {
            let value = code[at + 18..].split([',', '\n']).next().unwrap_or("");
            if !value.contains("::default().") {
                repeated.push(format!("{}: default_value_t = {value}", path.display()));
            }
        }
    }
    assert!(
        repeated.is_empty(),
        "flag defaults that do not read their settings' Default:\n{}",
        repeated.join("\n")
    );
    // Substeps: one constant, never a number written into a substeps setting (0 and 1 start a
    // counter; they are not a choice of substeps).
    let everywhere: Vec<&(PathBuf, String)> = all.iter().chain(cli.iter()).collect();
    let defined: Vec<_> = everywhere.iter().filter(|(_, c)| c.contains("pub const SUBSTEPS: ")).collect();
    assert_eq!(defined.len(), 1, "the default substeps are defined in exactly one place");
    for (path, code) in &everywhere {
        for line in code.lines().filter(|l| l.contains("substeps")) {
            let literal = line.split_once(['=', ':']).map(|(_, v)| v.trim()).is_some_and(|v| {
                let digits: String = v.chars().take_while(char::is_ascii_digit).collect();
                digits.parse::<u64>().is_ok_and(|n| n > 1)
            });
            assert!(!literal, "{}: a substeps count written as a number: {line}", path.display());
        }
    }
    // A material is parsed once, where the type is.
    for (path, code) in &everywhere {
        if code.contains("Material::named(") {
            assert!(
                path.ends_with("mannequin-cloth/src/material.rs"),
                "{}: parses a material by name",
                path.display()
            );
        }
    }
    // One run-record writer: only mannequin_io::run_record names the checkpoint's record member.
    for (path, code) in &everywhere {
        let writes_run =
            code.contains("NpyArray::text(") && (code.contains("\"run\"") || code.contains("RUN_MEMBER"));
        assert!(
            !writes_run || path.ends_with("run_record.rs"),
            "{}: writes a run record itself",
            path.display()
        );
    }
}

#[test]
fn the_command_line_crate_is_thin() {
    let lines: usize =
        sources(&crates_dir().join("mannequin/src")).iter().map(|(_, text)| text.lines().count()).sum();
    println!("the command line's src/ holds {lines} lines");
    assert!(lines <= 3500, "crates/mannequin/src holds {lines} lines (at most 3,500)");
}
