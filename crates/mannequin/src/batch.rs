//! `mannequin batch`: many people, each an independent array task of the CLI that exists, on the
//! engines clusters already run (a Slurm job array, a Kubernetes Indexed Job) or on this machine.
//! `plan` checks a manifest whole and writes a run folder; `task` runs one person's steps,
//! skipping what finished; `local` runs the array here; `status` and `report` read what the
//! tasks left.

use std::num::NonZeroUsize;
use std::path::PathBuf;

use anyhow::Result;
use clap::Subcommand;
use mannequin_batch::{PlanRequest, local, planner, report, task};

#[derive(Subcommand)]
pub enum BatchCommand {
    /// Check a manifest (CSV: id, input, steps, and <step>.<flag> settings) and write a run
    /// folder: plan.json, and the engine's sbatch script or Kubernetes Job.
    Plan(PlanRequest),
    /// Run one person's steps; a finished step is skipped, a stopped one resumes. The index
    /// comes from --index, else SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX.
    Task {
        /// The run folder (`batch plan --out`).
        #[arg(long)]
        run: PathBuf,
        /// The person's index in the manifest, from 0.
        #[arg(long)]
        index: Option<usize>,
        /// Added to the index from the environment: the first person of this array's part of a
        /// run split into several arrays.
        #[arg(long, default_value_t = 0, conflicts_with = "index")]
        offset: usize,
    },
    /// Run every person on this machine, --jobs at a time, each task its own process.
    Local {
        /// The run folder (`batch plan --out`).
        #[arg(long)]
        run: PathBuf,
        /// Tasks at once.
        #[arg(long, default_value = "1")]
        jobs: NonZeroUsize,
        /// Threads per task (default: this machine's cores shared among the jobs).
        #[arg(long)]
        threads: Option<NonZeroUsize>,
    },
    /// Where each person's steps stand: pending, running, stopped, done or failed.
    Status {
        /// The run folder (`batch plan --out`).
        #[arg(long)]
        run: PathBuf,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Per person and step: status, seconds, attempts, the one-line error of a failure, and
    /// eval's scores; also written to RUN/report.json.
    Report {
        /// The run folder (`batch plan --out`).
        #[arg(long)]
        run: PathBuf,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

/// Runs one batch verb; `run_verb` runs a verb's command line, `cli` is the whole CLI's definition
/// (which checks each step's command line at plan time).
pub fn run(cmd: BatchCommand, run_verb: &dyn Fn(&[&str]) -> Result<()>, cli: clap::Command) -> Result<()> {
    match cmd {
        BatchCommand::Plan(args) => planner::plan(args, &cli),
        BatchCommand::Task { run, index, offset } => task::run(&run, task::index(index, offset)?, run_verb),
        BatchCommand::Local { run, jobs, threads } => {
            local::run(&run, jobs.get(), threads.map(NonZeroUsize::get))
        }
        BatchCommand::Status { run, json } => {
            let report = report::gather(&run)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                println!("{}", report::status_table(&report));
            }
            Ok(())
        }
        BatchCommand::Report { run, json } => {
            let report = report::gather(&run)?;
            report::save(&report, &run)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                println!("{}", report::report_table(&report));
            }
            Ok(())
        }
    }
}
