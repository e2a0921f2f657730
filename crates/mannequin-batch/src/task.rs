//! `batch task`: one person's steps, in order, each through its verb. A finished step is
//! skipped; a stopped one is run again, and its verb resumes from its own checkpoint (`capture`
//! and `train` keep one); a failed step ends the task, since the later steps read its output.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use mannequin_garment::ngd::layers as garment_layers;
use mannequin_io::progress::set_stage;

use super::person::{Person, PlannedStep};
use super::plan::Plan;
use super::state::{PersonLock, State, StepRecord, host, now};
use super::step::Step;

/// The environment variables the engines hand a task its index in.
pub const INDEX_VARIABLES: [&str; 2] = ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"];

/// The task's index: `given`, else the first of [`INDEX_VARIABLES`] that is set plus `offset`.
pub fn index(given: Option<usize>, offset: usize) -> Result<usize> {
    if let Some(i) = given {
        return Ok(i);
    }
    for name in INDEX_VARIABLES {
        if let Ok(text) = std::env::var(name) {
            let i: usize = text.trim().parse().with_context(|| {
                format!("{name}={text}: expected the task's index, a whole number from 0")
            })?;
            return Ok(i + offset);
        }
    }
    bail!("no --index, and neither {} is set", INDEX_VARIABLES.join(" nor "))
}

/// Runs person `index` of the run folder `run`; `run_verb` runs one verb's command line.
pub fn run(run: &Path, index: usize, run_verb: &dyn Fn(&[&str]) -> Result<()>) -> Result<()> {
    let plan = Plan::load(run)?;
    let Some(person) = plan.people.get(index) else {
        bail!(
            "task index {index}: the run has {} people (indices 0 to {})",
            plan.people.len(),
            plan.people.len() - 1
        );
    };
    let dir = person.dir(run);
    let _lock = PersonLock::take(&dir, &person.id)?;
    tracing::info!("person {} (index {index}, manifest line {})", person.id, person.line);
    for planned in &person.steps {
        let previous = StepRecord::read(&dir, planned.step)?;
        if let Some(done) = previous.as_ref().filter(|r| r.state == State::Done) {
            tracing::info!(
                "{} {}: done already ({:.1} s), skipped",
                person.id,
                planned.step.name(),
                done.seconds.unwrap_or(0.0)
            );
            continue;
        }
        let mut record = StepRecord {
            step: planned.step,
            state: State::Running,
            attempts: previous.map_or(0, |r| r.attempts) + 1,
            started: now(),
            finished: None,
            seconds: None,
            error: None,
            host: host(),
            pid: std::process::id(),
        };
        record.write(&dir)?;
        set_stage(&format!("{} {}", person.id, planned.step.name()));
        let start = Instant::now();
        let outcome = run_step(run, person, planned, run_verb);
        set_stage("");
        record.finished = Some(now());
        record.seconds = Some(start.elapsed().as_secs_f64());
        match outcome {
            Ok(()) => {
                record.state = State::Done;
                record.write(&dir)?;
                tracing::info!(
                    "{} {}: done in {:.1} s",
                    person.id,
                    planned.step.name(),
                    record.seconds.unwrap_or(0.0)
                );
            }
            Err(e) => {
                let line = e.chain().map(|c| c.to_string()).collect::<Vec<_>>().join(": ");
                record.state = State::Failed;
                record.error = Some(line.clone());
                record.write(&dir)?;
                bail!("person {} step {}: {line}", person.id, planned.step.name());
            }
        }
    }
    Ok(())
}

/// One step's verb, or for `garments` one `garment fit` per garment of the dataset's legend.
fn run_step(
    run: &Path,
    person: &Person,
    planned: &PlannedStep,
    run_verb: &dyn Fn(&[&str]) -> Result<()>,
) -> Result<()> {
    let garments: Vec<Option<String>> = if planned.step == Step::Garments {
        let categories = garment_layers::resolve("auto", &person.dataset(run))?;
        categories.into_iter().map(|c| Some(c.name().to_string())).collect()
    } else {
        vec![None]
    };
    for garment in garments {
        let argv = person.argv(run, planned, garment.as_deref());
        tracing::debug!("running mannequin {}", argv.join(" "));
        let words: Vec<&str> = argv.iter().map(String::as_str).collect();
        run_verb(&words)?;
    }
    Ok(())
}
