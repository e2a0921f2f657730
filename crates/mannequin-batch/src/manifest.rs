//! The manifest: a CSV with a row per person (`id`, `input`, `steps`, and optional `<step>.<flag>`
//! settings columns), checked whole before anything is planned or submitted. Every refusal names
//! the manifest's line and field; each step's command line is parsed by the verb's own argument
//! parser, so a setting the verb would refuse is refused here.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use clap::Command;

use super::csv::records;
use super::person::{InputKind, Person, PlannedStep};
use super::step::Step;
use mannequin_garment::ngd::layers as garment_layers;

/// The columns every manifest has.
const REQUIRED: [&str; 3] = ["id", "input", "steps"];

/// A `<step>.<flag>` column: which step, which flag, and whether the flag takes a value.
struct Setting {
    column: usize,
    name: String,
    step: Step,
    flag: String,
    takes_value: bool,
}

/// Reads and checks `path` against the CLI's `cli` definition; `place` refuses inputs a run's
/// engine cannot reach (it says why, or None).
pub fn read(path: &Path, cli: &Command, place: &dyn Fn(&Path) -> Option<String>) -> Result<Vec<Person>> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).with_context(|| format!("{file}: cannot read the manifest"))?;
    let rows = records(&text, &file)?;
    let Some((header, rows)) = rows.split_first() else { bail!("{file}: empty; expected a header line") };
    let at = |line: usize, field: &str| format!("{file} line {line}, field `{field}`");
    let mut column: HashMap<&str, usize> = HashMap::new();
    let mut settings = Vec::new();
    for (i, name) in header.fields.iter().enumerate() {
        if column.insert(name.as_str(), i).is_some() {
            bail!("{}: the column appears twice", at(header.line, name));
        }
        if !REQUIRED.contains(&name.as_str()) {
            settings.push(setting(i, name, cli).map_err(|e| anyhow!("{}: {e}", at(header.line, name)))?);
        }
    }
    for name in REQUIRED {
        if !column.contains_key(name) {
            bail!("{file} line {}: no `{name}` column; expected the columns id, input, steps", header.line);
        }
    }
    if rows.is_empty() {
        bail!("{file}: no people; expected a row per person under the header");
    }
    let base = path.parent().unwrap_or(Path::new("."));
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut people = Vec::new();
    for row in rows {
        let line = row.line;
        if row.fields.len() != header.fields.len() {
            bail!(
                "{file} line {line}: {} fields, expected {} (the header's)",
                row.fields.len(),
                header.fields.len()
            );
        }
        let get = |name: &str| row.fields[column[name]].trim();
        let id = get("id").to_string();
        check_id(&id).map_err(|e| anyhow!("{}: {e}", at(line, "id")))?;
        if let Some(first) = seen.insert(id.clone(), line) {
            bail!("{}: `{id}` is already the id of line {first}; ids must be unique", at(line, "id"));
        }
        let input = get("input");
        if input.is_empty() {
            bail!("{}: empty; expected a video, a frame folder or a dataset", at(line, "input"));
        }
        let input = base.join(input);
        let input =
            input.canonicalize().map_err(|e| anyhow!("{}: {}: {e}", at(line, "input"), input.display()))?;
        if let Some(why) = place(&input) {
            bail!("{}: {}", at(line, "input"), why);
        }
        let kind = InputKind::of(&input);
        let steps = parse_steps(get("steps"), kind).map_err(|e| anyhow!("{}: {e}", at(line, "steps")))?;
        let mut planned: BTreeMap<Step, Vec<String>> = steps.iter().map(|s| (*s, Vec::new())).collect();
        for s in &settings {
            let value = row.fields[s.column].trim();
            if value.is_empty() {
                continue;
            }
            let Some(flags) = planned.get_mut(&s.step) else {
                bail!("{}: set for {}, which this row's steps do not run", at(line, &s.name), s.step.name());
            };
            flags.extend(flag_words(s, value).map_err(|e| anyhow!("{}: {e}", at(line, &s.name)))?);
        }
        let person = Person {
            id,
            line,
            input,
            kind,
            steps: planned.into_iter().map(|(step, flags)| PlannedStep { step, flags }).collect(),
        };
        check_commands(&person, cli, &settings).map_err(|(field, e)| anyhow!("{}: {e}", at(line, &field)))?;
        people.push(person);
    }
    Ok(people)
}

/// An id names a folder: letters, digits, `.`, `_` and `-`, not starting with a dot.
fn check_id(id: &str) -> Result<()> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-');
    if id.is_empty() || id.len() > 64 || id.starts_with('.') || !id.chars().all(allowed) {
        bail!("`{id}`: expected 1 to 64 letters, digits, `.`, `_` or `-`, not starting with `.`");
    }
    Ok(())
}

/// A `+`-joined list of steps, each known, once, in order, and possible on this input.
fn parse_steps(text: &str, kind: InputKind) -> Result<Vec<Step>> {
    let names: Vec<&str> = Step::ALL.iter().map(|s| s.name()).collect();
    let mut steps: Vec<Step> = Vec::new();
    for word in text.split('+').map(str::trim) {
        let step = Step::named(word).ok_or_else(|| {
            anyhow!("unknown step `{word}`; expected some of {} joined by `+`", names.join(", "))
        })?;
        if let Some(last) = steps.last().filter(|last| **last >= step) {
            bail!("`{}` after `{}`; steps run in the order {}", step.name(), last.name(), names.join(", "));
        }
        steps.push(step);
    }
    let has = |s: Step| steps.contains(&s);
    if kind != InputKind::Dataset && !has(Step::Capture) {
        bail!(
            "the input is a {}; its steps must start with capture",
            if kind == InputKind::Video { "video" } else { "frame folder" }
        );
    }
    if let Some(step) = steps.iter().find(|s| s.needs_train() && !has(Step::Train)) {
        bail!("`{}` needs `train` in the same row", step.name());
    }
    Ok(steps)
}

/// Parses a settings column's name against the CLI.
fn setting(column: usize, name: &str, cli: &Command) -> Result<Setting> {
    let Some((step_name, flag)) = name.split_once('.') else {
        bail!("unknown column; expected id, input, steps or <step>.<flag> (e.g. train.iters)");
    };
    let step = Step::named(step_name).ok_or_else(|| anyhow!("unknown step `{step_name}`"))?;
    if step.owned_flags().contains(&flag) {
        bail!("--{flag} is set by the batch run itself (each person's files go under RUN/people/<id>/)");
    }
    let verb =
        step.verb().iter().try_fold(cli, |c, name| c.find_subcommand(name)).expect("each step's verb exists");
    let arg = verb
        .get_arguments()
        .find(|a| a.get_long() == Some(flag))
        .ok_or_else(|| anyhow!("`mannequin {}` has no --{flag} flag", step.verb().join(" ")))?;
    let takes_value = arg.get_action().takes_values();
    Ok(Setting { column, name: name.to_string(), step, flag: flag.to_string(), takes_value })
}

/// The words a setting adds to its verb's command line.
fn flag_words(s: &Setting, value: &str) -> Result<Vec<String>> {
    if s.takes_value {
        return Ok(vec![format!("--{}", s.flag), value.to_string()]);
    }
    match value {
        "true" => Ok(vec![format!("--{}", s.flag)]),
        "false" => Ok(Vec::new()),
        _ => bail!("`{value}`: --{} is a switch; expected true or false", s.flag),
    }
}

/// Parses each step's whole command line with the verb's own parser; a refusal is blamed on the
/// first setting that the verb refuses alone, or on `steps`.
fn check_commands(person: &Person, cli: &Command, settings: &[Setting]) -> Result<(), (String, String)> {
    let run = Path::new("/run");
    let parse = |argv: &[String]| {
        cli.clone()
            .try_get_matches_from(std::iter::once("mannequin".to_string()).chain(argv.iter().cloned()))
            .map(drop)
            .map_err(|e| {
                e.to_string().lines().next().unwrap_or_default().trim_start_matches("error: ").to_string()
            })
    };
    for planned in &person.steps {
        let Err(whole) = parse(&person.argv(run, planned, None)) else { continue };
        for s in settings.iter().filter(|s| s.step == planned.step) {
            let flag = format!("--{}", s.flag);
            let Some(at) = planned.flags.iter().position(|w| *w == flag) else { continue };
            let alone = PlannedStep {
                step: planned.step,
                flags: planned.flags[at..(at + 1 + usize::from(s.takes_value))].to_vec(),
            };
            if let Err(e) = parse(&person.argv(run, &alone, None)) {
                return Err((s.name.clone(), e));
            }
        }
        return Err(("steps".to_string(), whole));
    }
    if person.runs(Step::Garments) {
        garment_layers::resolve("auto", &person.input)
            .map_err(|e| ("input".to_string(), format!("{e:#}")))?;
    }
    Ok(())
}
