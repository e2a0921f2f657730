//! What a task leaves behind of each step, so that a re-run skips what finished and a report can
//! tell what happened: one small JSON record per person and step, written atomically when the
//! step starts and again when it ends, and a lock per person that the task holds while it runs
//! (released by the system when the task dies, so a record that says "running" without its lock
//! held is a task that was stopped).

use std::fs::{File, TryLockError};
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use anyhow::{Context, Result, bail};
use mannequin_io::atomic::write_atomic;
use serde::{Deserialize, Serialize};

use super::step::Step;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum State {
    Running,
    Done,
    Failed,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StepRecord {
    pub step: Step,
    pub state: State,
    /// How many times a task has started this step.
    pub attempts: u32,
    /// Unix time the latest attempt started.
    pub started: f64,
    /// Unix time it ended, and its wall time in seconds, once it has.
    pub finished: Option<f64>,
    pub seconds: Option<f64>,
    /// The one-line error of a failed attempt.
    pub error: Option<String>,
    pub host: String,
    pub pid: u32,
}

/// Seconds since the Unix epoch.
pub fn now() -> f64 {
    SystemTime::now().duration_since(UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64())
}

/// This machine's name, as a record keeps it.
pub fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .or_else(|_| std::env::var("HOSTNAME"))
        .unwrap_or_else(|_| "unknown".to_string())
}

/// The record of `step` in a person's folder.
pub fn record_path(person_dir: &Path, step: Step) -> PathBuf {
    person_dir.join("steps").join(format!("{}.json", step.name()))
}

impl StepRecord {
    /// The record of `step`, or None before its first attempt.
    pub fn read(person_dir: &Path, step: Step) -> Result<Option<StepRecord>> {
        let path = record_path(person_dir, step);
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => {
                return Err(e).with_context(|| format!("{}: cannot read the step record", path.display()));
            }
        };
        let record: StepRecord =
            serde_json::from_str(&text).with_context(|| format!("{}: not a step record", path.display()))?;
        if record.step != step {
            bail!("{}: field `step`: expected {}, found {}", path.display(), step.name(), record.step.name());
        }
        Ok(Some(record))
    }

    pub fn write(&self, person_dir: &Path) -> Result<()> {
        let path = record_path(person_dir, self.step);
        let text = serde_json::to_string_pretty(self).expect("a record serialises");
        write_atomic(&path, text.as_bytes()).with_context(|| format!("{}: cannot write", path.display()))
    }
}

/// A person's lock: held by the task running them, released when it ends or dies.
pub struct PersonLock {
    _file: File,
}

fn lock_path(person_dir: &Path) -> PathBuf {
    person_dir.join(".lock")
}

impl PersonLock {
    /// Takes the lock of the person in `person_dir`, or says who holds it.
    pub fn take(person_dir: &Path, id: &str) -> Result<PersonLock> {
        std::fs::create_dir_all(person_dir)
            .with_context(|| format!("{}: cannot create", person_dir.display()))?;
        let path = lock_path(person_dir);
        let file =
            File::create(&path).with_context(|| format!("{}: cannot create the lock", path.display()))?;
        match file.try_lock() {
            Ok(()) => Ok(PersonLock { _file: file }),
            Err(TryLockError::WouldBlock) => {
                bail!("person `{id}` is being run by another task ({} is held)", path.display())
            }
            Err(TryLockError::Error(e)) => Err(e).with_context(|| format!("{}: cannot lock", path.display())),
        }
    }

    /// Whether a task holds the lock of the person in `person_dir` now.
    pub fn is_held(person_dir: &Path) -> bool {
        let Ok(file) = File::open(lock_path(person_dir)) else { return false };
        matches!(file.try_lock(), Err(TryLockError::WouldBlock))
    }
}
