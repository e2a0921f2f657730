//! `batch plan`: a manifest checked for an engine, then the run folder written (`plan.json` and
//! what the engine submits). Everything is checked before the folder is touched.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use mannequin_io::atomic::write_atomic;

use crate::plan::{Engine, Plan};
use crate::resources::Needs;
use crate::{kubernetes, manifest, slurm};

/// What `batch plan` is asked: the manifest, the engine, the run folder and the engine's
/// settings.
#[derive(Args)]
pub struct PlanRequest {
    /// The manifest CSV; relative inputs are taken from its folder.
    #[arg(long)]
    pub manifest: PathBuf,
    /// Where the array runs: an sbatch script (slurm.sbatch), a Job (job.yaml), or this machine
    /// (`batch local`).
    #[arg(long, value_enum)]
    pub engine: Engine,
    /// The run folder to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Tasks running at once (Slurm's `%`, the Job's parallelism; default: no cap on Slurm, 8
    /// on Kubernetes).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub throttle: Option<u32>,
    /// CPUs per task, in place of the steps' own.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub cpus: Option<u32>,
    /// Memory per task in GiB, in place of the steps' own.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub memory_gib: Option<u32>,
    /// Slurm partition.
    #[arg(long)]
    pub partition: Option<String>,
    /// Slurm's MaxArraySize: a run of more people is split into several scripts (default: Slurm's
    /// own default, 1001).
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..))]
    pub array_max: Option<u32>,
    /// The mannequin binary the Slurm tasks run (default: this one).
    #[arg(long)]
    pub mannequin: Option<PathBuf>,
    /// Kubernetes: the container image, with mannequin on its PATH.
    #[arg(long)]
    pub image: Option<String>,
    /// Kubernetes: the PersistentVolumeClaim of the shared volume.
    #[arg(long, default_value = "mannequin-runs")]
    pub claim: String,
    /// Kubernetes: where the pods mount the shared volume, the same path as here; the run
    /// folder and every input must lie under it (default: the run folder's parent).
    #[arg(long)]
    pub mount: Option<PathBuf>,
}

/// An absolute form of `path`, which need not exist yet.
fn absolute(path: &Path) -> Result<PathBuf> {
    std::path::absolute(path).with_context(|| format!("{}: cannot make the path absolute", path.display()))
}

/// Checks `args.manifest` whole against the CLI's definition `cli`, then writes the run folder:
/// `plan.json`, the logs folder and the engine's files.
pub fn plan(args: PlanRequest, cli: &clap::Command) -> Result<()> {
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
                args.array_max.map_or(slurm::MAX_ARRAY_SIZE, |m| m as usize),
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
