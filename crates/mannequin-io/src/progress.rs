//! Progress display for long work, shared by every pipeline and the command line: `indicatif`
//! bars (labelled with the stage of a multi-stage job) and a closing line with wall time and
//! peak memory. Bars hide themselves when stderr is not a terminal.

use std::sync::Mutex;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

/// The stage of a multi-stage job (the demo), shown before every bar.
static STAGE: Mutex<String> = Mutex::new(String::new());

/// Labels the bars that follow with `stage` ("" for none).
pub fn set_stage(stage: &str) {
    *STAGE.lock().unwrap_or_else(|e| e.into_inner()) = stage.to_string();
}

/// A progress bar for `len` steps of work, labelled `what` (and the current stage, if any).
pub fn bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    let stage = STAGE.lock().unwrap_or_else(|e| e.into_inner()).clone();
    let prefix = if stage.is_empty() { String::new() } else { format!("[{stage}] ") };
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{prefix}{{msg:>12}} [{{bar:30}}] {{pos}}/{{len}} {{per_sec}} eta {{eta}}"
        ))
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// Peak resident memory of this process in MiB, where the OS reports it.
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Reports the wall time and peak memory of a job when dropped.
pub struct JobTimer {
    what: String,
    start: Instant,
}

impl JobTimer {
    pub fn start(what: &str) -> Self {
        Self { what: what.to_string(), start: Instant::now() }
    }
}

impl Drop for JobTimer {
    fn drop(&mut self) {
        let secs = self.start.elapsed().as_secs_f64();
        match peak_memory_mib() {
            Some(mib) => tracing::info!("{} took {secs:.2} s, peak memory {mib:.0} MiB", self.what),
            None => tracing::info!("{} took {secs:.2} s", self.what),
        }
    }
}
