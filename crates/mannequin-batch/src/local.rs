//! `batch local`: the run's array on this machine, N tasks at once, each its own `mannequin batch
//! task` process (so a task that crashes takes no other with it) with the cores shared out among
//! them, and its output appended to `RUN/logs/task-<index>.log` as Slurm's would be.

use std::fs::OpenOptions;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use anyhow::{Context, Result, bail};
use mannequin_io::progress::bar;

use super::plan::Plan;

/// Runs every person of `run` with `jobs` workers and `threads` threads per task (default: the
/// cores shared out). Every person runs whatever the others do; the error lists who failed.
pub fn run(run: &Path, jobs: usize, threads: Option<usize>) -> Result<()> {
    let plan = Plan::load(run)?;
    let n = plan.people.len();
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let threads = threads.unwrap_or((cores / jobs).max(1));
    let exe = std::env::current_exe().context("cannot find the mannequin binary to run the tasks")?;
    let logs = run.join("logs");
    std::fs::create_dir_all(&logs).with_context(|| format!("{}: cannot create", logs.display()))?;
    tracing::info!("{n} people, {jobs} at a time, {threads} threads each; logs in {}", logs.display());
    let progress = bar(n as u64, "people");
    let next = AtomicUsize::new(0);
    let failed: Mutex<Vec<(usize, String)>> = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..jobs.min(n) {
            scope.spawn(|| {
                loop {
                    let index = next.fetch_add(1, Ordering::SeqCst);
                    if index >= n {
                        break;
                    }
                    if let Err(e) = task(&exe, run, index, threads) {
                        failed.lock().unwrap_or_else(|e| e.into_inner()).push((index, format!("{e:#}")));
                    }
                    progress.inc(1);
                }
            });
        }
    });
    progress.finish_and_clear();
    let mut failed = failed.into_inner().unwrap_or_else(|e| e.into_inner());
    if failed.is_empty() {
        tracing::info!(
            "all {n} people done; `mannequin batch report --run {}` has the scores",
            run.display()
        );
        return Ok(());
    }
    failed.sort();
    let who: Vec<String> = failed.iter().map(|(i, e)| format!("{} ({e})", plan.people[*i].id)).collect();
    bail!(
        "{} of {n} people failed: {}; see `mannequin batch status --run {}`",
        failed.len(),
        who.join(", "),
        run.display()
    )
}

/// One task as a child process, to completion.
fn task(exe: &Path, run: &Path, index: usize, threads: usize) -> Result<()> {
    let log_path = run.join("logs").join(format!("task-{index}.log"));
    let log = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&log_path)
        .with_context(|| format!("{}: cannot open", log_path.display()))?;
    let status = Command::new(exe)
        .args(["batch", "task", "--run"])
        .arg(run)
        .args(["--index", &index.to_string()])
        .env("RAYON_NUM_THREADS", threads.to_string())
        .stdin(Stdio::null())
        .stdout(log.try_clone()?)
        .stderr(log)
        .status()
        .with_context(|| format!("cannot start task {index}"))?;
    if !status.success() {
        bail!("task {index} exited with {status}; its log is {}", log_path.display());
    }
    Ok(())
}
