//! `batch status` and `batch report`: what every person's task has done, read from the records
//! the tasks leave (state, attempts, times, the one-line error of a failure) and the scores
//! `eval` wrote, as a table and as JSON. A step that a record calls running while nobody holds
//! its person's lock was stopped (the task was killed); re-running the array resumes it.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use mannequin_io::atomic::write_atomic;
use serde::Serialize;
use serde_json::Value;

use super::plan::Plan;
use super::state::{PersonLock, State, StepRecord};
use super::step::Step;

/// A step's state as the report tells it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    Pending,
    Running,
    Stopped,
    Done,
    Failed,
}

impl Status {
    fn name(self) -> &'static str {
        match self {
            Status::Pending => "pending",
            Status::Running => "running",
            Status::Stopped => "stopped",
            Status::Done => "done",
            Status::Failed => "failed",
        }
    }
}

#[derive(Serialize)]
pub struct StepReport {
    pub step: Step,
    pub status: Status,
    pub attempts: u32,
    pub seconds: Option<f64>,
    pub started: Option<f64>,
    pub finished: Option<f64>,
    pub host: Option<String>,
    pub error: Option<String>,
}

#[derive(Serialize)]
pub struct PersonReport {
    pub id: String,
    pub index: usize,
    pub line: usize,
    pub input: String,
    /// The person's status: their first step not done, or done.
    pub status: Status,
    pub steps: Vec<StepReport>,
    /// `eval`'s PSNR, SSIM and LPIPS per test set, where it ran.
    pub scores: BTreeMap<String, BTreeMap<String, f64>>,
}

#[derive(Serialize)]
pub struct RunReport {
    pub run: String,
    pub people: Vec<PersonReport>,
    /// How many people are in each status.
    pub counts: BTreeMap<String, usize>,
    /// The indices of the people not done, which an array can be resubmitted with alone.
    pub left: Vec<usize>,
}

/// Reads the run folder's records.
pub fn gather(run: &Path) -> Result<RunReport> {
    let plan = Plan::load(run)?;
    let mut people = Vec::new();
    for (index, person) in plan.people.iter().enumerate() {
        let dir = person.dir(run);
        let held = PersonLock::is_held(&dir);
        let mut steps = Vec::new();
        for planned in &person.steps {
            let record = StepRecord::read(&dir, planned.step)?;
            let status = match record.as_ref().map(|r| r.state) {
                None => Status::Pending,
                Some(State::Done) => Status::Done,
                Some(State::Failed) => Status::Failed,
                Some(State::Running) if held => Status::Running,
                Some(State::Running) => Status::Stopped,
            };
            steps.push(StepReport {
                step: planned.step,
                status,
                attempts: record.as_ref().map_or(0, |r| r.attempts),
                seconds: record.as_ref().and_then(|r| r.seconds),
                started: record.as_ref().map(|r| r.started),
                finished: record.as_ref().and_then(|r| r.finished),
                host: record.as_ref().map(|r| r.host.clone()),
                error: record.and_then(|r| r.error),
            });
        }
        let status = steps.iter().map(|s| s.status).find(|s| *s != Status::Done).unwrap_or(Status::Done);
        let scores = if person.runs(Step::Eval) { scores(&dir.join("eval.json"))? } else { BTreeMap::new() };
        people.push(PersonReport {
            id: person.id.clone(),
            index,
            line: person.line,
            input: person.input.display().to_string(),
            status,
            steps,
            scores,
        });
    }
    let mut counts = BTreeMap::new();
    for p in &people {
        *counts.entry(p.status.name().to_string()).or_insert(0) += 1;
    }
    let left = people.iter().filter(|p| p.status != Status::Done).map(|p| p.index).collect();
    Ok(RunReport { run: run.display().to_string(), people, counts, left })
}

/// PSNR, SSIM and LPIPS of each test set in an `eval.json`, if it has been written.
fn scores(path: &Path) -> Result<BTreeMap<String, BTreeMap<String, f64>>> {
    let Ok(text) = std::fs::read_to_string(path) else { return Ok(BTreeMap::new()) };
    let json: Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not eval's JSON", path.display()))?;
    let mut out = BTreeMap::new();
    for set in ["test", "novel_view", "novel_pose"] {
        let Some(summary) = json.get(set).filter(|v| v.is_object()) else { continue };
        let metrics: BTreeMap<String, f64> = ["psnr", "ssim", "lpips"]
            .iter()
            .filter_map(|m| summary.get(*m).and_then(Value::as_f64).map(|v| (m.to_string(), v)))
            .collect();
        out.insert(set.to_string(), metrics);
    }
    Ok(out)
}

/// A line of counts, e.g. `3 people: 2 done, 1 failed`, and the indices left, if any.
fn summary(report: &RunReport) -> String {
    let total: usize = report.counts.values().sum();
    let parts: Vec<String> = report.counts.iter().map(|(k, v)| format!("{v} {k}")).collect();
    let mut line = format!("{total} people: {}", parts.join(", "));
    if !report.left.is_empty() {
        let left: Vec<String> = report.left.iter().map(usize::to_string).collect();
        line.push_str(&format!(
            "\nleft: indices {} (an array of these alone: sbatch --array={} slurm.sbatch)",
            left.join(","),
            left.join(",")
        ));
    }
    line
}

/// The status table: a row per person, a column per step.
pub fn status_table(report: &RunReport) -> String {
    let steps: Vec<Step> = Step::ALL
        .into_iter()
        .filter(|s| report.people.iter().any(|p| p.steps.iter().any(|r| r.step == *s)))
        .collect();
    let width = report.people.iter().map(|p| p.id.len()).max().unwrap_or(0).max(6);
    let mut out = format!("{:<width$}", "person");
    for s in &steps {
        out.push_str(&format!("  {:<8}", s.name()));
    }
    out.push('\n');
    for p in &report.people {
        out.push_str(&format!("{:<width$}", p.id));
        for s in &steps {
            let cell = p.steps.iter().find(|r| r.step == *s).map_or("-", |r| r.status.name());
            out.push_str(&format!("  {cell:<8}"));
        }
        out.push('\n');
    }
    out.push_str(&summary(report));
    out
}

/// The report table: a row per person and step with its time and attempts, the error of a
/// failure, and each person's scores.
pub fn report_table(report: &RunReport) -> String {
    let width = report.people.iter().map(|p| p.id.len()).max().unwrap_or(0).max(6);
    let mut out = format!(
        "{:<width$}  {:<8}  {:<7}  {:>9}  {:>8}  detail\n",
        "person", "step", "status", "seconds", "attempts"
    );
    for p in &report.people {
        for s in &p.steps {
            let seconds = s.seconds.map_or("-".to_string(), |t| format!("{t:.1}"));
            let detail = match (&s.error, s.step) {
                (Some(e), _) => e.clone(),
                (None, Step::Eval) => p
                    .scores
                    .iter()
                    .map(|(set, m)| {
                        let parts: Vec<String> = m.iter().map(|(k, v)| format!("{k} {v:.3}")).collect();
                        format!("{set}: {}", parts.join(" "))
                    })
                    .collect::<Vec<_>>()
                    .join("; "),
                _ => String::new(),
            };
            out.push_str(&format!(
                "{:<width$}  {:<8}  {:<7}  {seconds:>9}  {:>8}  {detail}\n",
                p.id,
                s.step.name(),
                s.status.name(),
                s.attempts
            ));
        }
    }
    out.push_str(&summary(report));
    out
}

/// Writes the report as `RUN/report.json`.
pub fn save(report: &RunReport, run: &Path) -> Result<()> {
    let path = run.join("report.json");
    let text = serde_json::to_string_pretty(report).expect("a report serialises");
    write_atomic(&path, text.as_bytes()).with_context(|| format!("{}: cannot write", path.display()))
}
