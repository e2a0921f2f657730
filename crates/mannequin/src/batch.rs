//! `mannequin batch`: many people, each an independent array task of the CLI that exists, on the
//! engines clusters already run (a Slurm job array, a Kubernetes Indexed Job) or on this machine.
//! `plan` checks a manifest whole and writes a run folder; `task` runs one person's steps,
//! skipping what finished; `local` runs the array here; `status` and `report` read what the
//! tasks left.

mod csv;
mod kubernetes;
mod local;
mod manifest;
mod person;
mod plan;
mod report;
mod resources;
mod slurm;
mod state;
mod step;
mod task;

use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use mannequin_io::atomic::write_atomic;

use plan::{Engine, Plan};
use resources::Needs;

#[derive(Subcommand)]
pub enum BatchCommand {
    /// Check a manifest (CSV: id, input, steps, and <step>.<flag> settings) and write a run
    /// folder: plan.json, and the engine's sbatch script or Kubernetes Job.
    Plan(PlanArgs),
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

#[derive(Args)]
pub struct PlanArgs {
    /// The manifest CSV; relative inputs are taken from its folder.
    #[arg(long)]
    manifest: PathBuf,
    /// Where the array runs: an sbatch script (slurm.sbatch), a Job (job.yaml), or this machine
    /// (`batch local`).
    #[arg(long, value_enum)]
    engine: Engine,
    /// The run folder to write.
    #[arg(long)]
    out: PathBuf,
    /// Tasks running at once (Slurm's `%`, the Job's parallelism; default: no cap on Slurm, 8
    /// on Kubernetes).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    throttle: Option<u32>,
    /// CPUs per task, in place of the steps' own.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    cpus: Option<u32>,
    /// Memory per task in GiB, in place of the steps' own.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    memory_gib: Option<u32>,
    /// Slurm partition.
    #[arg(long)]
    partition: Option<String>,
    /// Slurm's MaxArraySize: a run of more people is split into several scripts.
    #[arg(long, default_value_t = 1001, value_parser = clap::value_parser!(u32).range(2..))]
    array_max: u32,
    /// The mannequin binary the Slurm tasks run (default: this one).
    #[arg(long)]
    mannequin: Option<PathBuf>,
    /// Kubernetes: the container image, with mannequin on its PATH.
    #[arg(long)]
    image: Option<String>,
    /// Kubernetes: the PersistentVolumeClaim of the shared volume.
    #[arg(long, default_value = "mannequin-runs")]
    claim: String,
    /// Kubernetes: where the pods mount the shared volume, the same path as here; the run
    /// folder and every input must lie under it (default: the run folder's parent).
    #[arg(long)]
    mount: Option<PathBuf>,
}

/// Runs one batch verb; `run_verb` runs a verb's command line, `cli` is the whole CLI's definition
/// (which checks each step's command line at plan time).
pub fn run(cmd: BatchCommand, run_verb: &dyn Fn(&[&str]) -> Result<()>, cli: clap::Command) -> Result<()> {
    match cmd {
        BatchCommand::Plan(args) => plan(args, &cli),
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

/// An absolute form of `path`, which need not exist yet.
fn absolute(path: &Path) -> Result<PathBuf> {
    std::path::absolute(path).with_context(|| format!("{}: cannot make the path absolute", path.display()))
}

fn plan(args: PlanArgs, cli: &clap::Command) -> Result<()> {
    let run = absolute(&args.out)?;
    let manifest = absolute(&args.manifest)?;
    let mount = match (&args.mount, args.engine) {
        (Some(m), Engine::Kubernetes) => Some(absolute(m)?),
        (None, Engine::Kubernetes) => Some(run.parent().unwrap_or(Path::new("/")).to_path_buf()),
        (Some(_), _) => bail!("--mount is for --engine kubernetes"),
        (None, _) => None,
    };
    let image = match (&args.image, args.engine) {
        (Some(i), Engine::Kubernetes) => Some(i.as_str()),
        (None, Engine::Kubernetes) => {
            bail!("--engine kubernetes needs --image: a container image with mannequin on its PATH")
        }
        (Some(_), _) => bail!("--image is for --engine kubernetes"),
        (None, _) => None,
    };
    if args.engine == Engine::Slurm && run.to_string_lossy().contains(char::is_whitespace) {
        bail!(
            "--out {}: Slurm's #SBATCH lines cannot hold a path with spaces; choose another run folder",
            run.display()
        );
    }
    if let Some(m) = &mount
        && !run.starts_with(m)
    {
        bail!("--out {}: outside the shared volume mounted at {} in the pods", run.display(), m.display());
    }
    let place = |input: &Path| match &mount {
        Some(m) if !input.starts_with(m) => Some(format!(
            "{} is outside the shared volume mounted at {} in the pods",
            input.display(),
            m.display()
        )),
        _ => None,
    };
    // Everything is checked before the run folder is touched.
    let people = manifest::read(&manifest, cli, &place)?;
    let mut needs = people
        .iter()
        .map(|p| Needs::of_steps(p.steps.iter().map(|s| s.step)))
        .fold(Needs::of_steps([]), Needs::max);
    needs.cpus = args.cpus.unwrap_or(needs.cpus);
    needs.memory_gib = args.memory_gib.unwrap_or(needs.memory_gib);
    let plan = Plan::new(&manifest, args.engine, needs, people);
    plan.save(&run)?;
    std::fs::create_dir_all(run.join("logs"))
        .with_context(|| format!("{}: cannot create", run.join("logs").display()))?;
    let n = plan.people.len();
    match (args.engine, image, mount) {
        (Engine::Slurm, _, _) => {
            let exe = match args.mannequin {
                Some(p) => absolute(&p)?,
                None => std::env::current_exe().context("cannot find this mannequin binary")?,
            };
            let scripts = slurm::scripts(
                &plan,
                &run,
                &exe,
                args.throttle,
                args.partition.as_deref(),
                args.array_max as usize,
            );
            for (path, text) in &scripts {
                write_atomic(path, text.as_bytes())
                    .with_context(|| format!("{}: cannot write", path.display()))?;
            }
            let names: Vec<String> = scripts.iter().map(|(p, _)| format!("sbatch {}", p.display())).collect();
            tracing::info!("planned {n} people; submit with `{}`", names.join("`, `"));
        }
        (Engine::Kubernetes, Some(image), Some(mount)) => {
            let cluster = kubernetes::Cluster {
                image,
                claim: &args.claim,
                mount: &mount,
                parallelism: args.throttle.unwrap_or(8),
            };
            let path = run.join("job.yaml");
            let text = kubernetes::job(&plan, &run, &cluster);
            write_atomic(&path, text.as_bytes())
                .with_context(|| format!("{}: cannot write", path.display()))?;
            tracing::info!("planned {n} people; apply with `kubectl apply -f {}`", path.display());
        }
        _ => tracing::info!(
            "planned {n} people; run them with `mannequin batch local --run {}`",
            run.display()
        ),
    }
    Ok(())
}
