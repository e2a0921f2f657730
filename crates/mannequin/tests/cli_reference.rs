//! `docs/cli.md`, the full command reference, is generated from the binary's own help (the clap
//! definitions) and must match it: a flag added, renamed or re-documented without regenerating
//! the page fails here. `MANNEQUIN_BLESS=1 cargo test --release -p mannequin --test cli_reference`
//! rewrites the page.

mod common;

use std::path::Path;

use common::{mannequin, ok};

/// The help of `mannequin <path…>`.
fn help(path: &[&str]) -> String {
    let args: Vec<&str> = path.iter().copied().chain(["--help"]).collect();
    String::from_utf8(ok(mannequin(&args)).stdout).expect("help is UTF-8")
}

/// The subcommands a help text lists (its `Commands:` section), without clap's own `help`.
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| *l != "Commands:")
        .skip(1)
        .take_while(|l| !l.is_empty())
        .filter(|l| l.starts_with("  ") && !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

/// One section per command, depth first in the order the help lists them.
fn reference(path: &mut Vec<String>, out: &mut String) {
    let borrowed: Vec<&str> = path.iter().map(String::as_str).collect();
    let text = help(&borrowed);
    let title = std::iter::once("mannequin").chain(borrowed.iter().copied()).collect::<Vec<_>>().join(" ");
    out.push_str(&format!("\n## `{title}`\n\n```text\n{}\n```\n", text.trim_end()));
    for sub in subcommands(&text) {
        path.push(sub);
        reference(path, out);
        path.pop();
    }
}

/// The page's opening: how it is made, and what each shared flag means on every verb.
const CONVENTIONS: &str = "# Command reference

Every `mannequin` command and flag, as `--help` prints them. Generated from the clap definitions
by `crates/mannequin/tests/cli_reference.rs`; regenerate with
`MANNEQUIN_BLESS=1 cargo test --release -p mannequin --test cli_reference`.

Each word means one thing on every verb:

- `--body B` is a body model: `default` (the embedded body, about 13k vertices), `default-lod1`
  (about 1k vertices), or a SMPL / SMPL-H / SMPL-X `.npz` or released `.pkl`;
- `--avatar DIR` is a trained avatar folder (what `train --out` writes);
- `--motion FILE --frame N` is frame N of an AMASS or PeopleSnapshot motion, and
  `--named-pose NAME` a built-in SMPL pose; neither is the rest pose;
- enumerated flags list their choices and fail at once on a typo.

Results (tables, JSON) go to stdout; logs and progress bars to stderr. A refusal is one line
naming the file or flag, the field and what was expected (`docs/limits.md`).
";

fn generated() -> String {
    let mut out = String::from(CONVENTIONS);
    reference(&mut Vec::new(), &mut out);
    out
}

#[test]
fn the_command_reference_matches_the_binary() {
    let page = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/cli.md");
    let now = generated();
    assert!(now.contains("## `mannequin cloth simulate`"), "nested commands are listed");
    if std::env::var_os("MANNEQUIN_BLESS").is_some() {
        std::fs::write(&page, &now).unwrap();
        return;
    }
    let written = std::fs::read_to_string(&page).unwrap_or_default();
    let stale = written.lines().zip(now.lines()).position(|(a, b)| a != b).unwrap_or(written.lines().count());
    assert!(
        written == now,
        "docs/cli.md is stale (first difference at line {}: {:?}); regenerate it with \
         MANNEQUIN_BLESS=1 cargo test --release -p mannequin --test cli_reference",
        stale + 1,
        now.lines().nth(stale)
    );
}

#[test]
fn subcommands_are_read_from_the_commands_section() {
    let text = "About\n\nUsage: x\n\nCommands:\n  simulate  Simulate\n            more\n  help      Print\n\nOptions:\n  -h\n";
    assert_eq!(subcommands(text), vec!["simulate".to_string()]);
}
