//! Runs one crafted case as a user's shell would, but under an address-space limit, with a
//! watchdog for hangs, and with the child's peak resident memory read from `wait4`.

use std::collections::BTreeMap;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime};

use super::{Case, Expect, PEAK_RSS_LIMIT};

/// Address space a case may map: well above [`PEAK_RSS_LIMIT`] because allocators and thread
/// stacks reserve more than they touch, but low enough that an allocation sized by a header
/// fails instead of swapping the machine.
const ADDRESS_SPACE_LIMIT: u64 = 6 << 30;

/// Longest a case may run before it counts as a hang.
const TIMEOUT: Duration = Duration::from_secs(90);

/// What a case did.
pub struct Outcome {
    pub code: Option<i32>,
    pub signal: Option<i32>,
    pub stderr: String,
    pub peak_rss: u64,
    pub seconds: f64,
    pub timed_out: bool,
}

/// Every file under `dir` with its size and modification time.
pub fn snapshot(dir: &Path) -> BTreeMap<PathBuf, (u64, SystemTime)> {
    let mut files = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for entry in entries.flatten() {
            let path = entry.path();
            let Ok(meta) = std::fs::symlink_metadata(&path) else { continue };
            if meta.is_dir() {
                files.insert(path.clone(), (0, SystemTime::UNIX_EPOCH));
                stack.push(path);
            } else {
                files.insert(path, (meta.len(), meta.modified().unwrap()));
            }
        }
    }
    files
}

/// Runs `case`'s command; stdout is discarded, stderr kept.
pub fn execute(case: &Case, log: &Path) -> Outcome {
    let stderr_file = std::fs::File::create(log).unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_mannequin"));
    command.args(&case.args).stdin(Stdio::null()).stdout(Stdio::null()).stderr(stderr_file);
    // SAFETY: only async-signal-safe calls (setrlimit) between fork and exec.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit { rlim_cur: ADDRESS_SPACE_LIMIT, rlim_max: ADDRESS_SPACE_LIMIT };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            let none = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
            libc::setrlimit(libc::RLIMIT_CORE, &none);
            Ok(())
        });
    }
    let start = Instant::now();
    let child = command.spawn().unwrap();
    let pid = child.id() as libc::pid_t;
    let done = Arc::new(AtomicBool::new(false));
    let timed_out = Arc::new(AtomicBool::new(false));
    let watchdog = {
        let (done, timed_out) = (done.clone(), timed_out.clone());
        std::thread::spawn(move || {
            while start.elapsed() < TIMEOUT {
                if done.load(Ordering::SeqCst) {
                    return;
                }
                std::thread::sleep(Duration::from_millis(50));
            }
            if !done.load(Ordering::SeqCst) {
                timed_out.store(true, Ordering::SeqCst);
                // SAFETY: the child is not reaped until wait4 below returns, so the pid is ours.
                unsafe { libc::kill(pid, libc::SIGKILL) };
            }
        })
    };
    let mut status = 0;
    // SAFETY: plain C structs filled by the kernel.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let reaped = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    done.store(true, Ordering::SeqCst);
    watchdog.join().unwrap();
    assert_eq!(reaped, pid, "wait4 failed for case {}", case.name);
    drop(child);
    let (code, signal) = if libc::WIFEXITED(status) {
        (Some(libc::WEXITSTATUS(status)), None)
    } else {
        (None, libc::WIFSIGNALED(status).then(|| libc::WTERMSIG(status)))
    };
    Outcome {
        code,
        signal,
        stderr: std::fs::read_to_string(log).unwrap_or_default(),
        peak_rss: usage.ru_maxrss as u64 * 1024,
        seconds: start.elapsed().as_secs_f64(),
        timed_out: timed_out.load(Ordering::SeqCst),
    }
}

/// Why `case` failed, or `None` when it was refused as it must be: the right exit code, one line
/// naming what it must, no panic, no non-finite number in the message, memory within the limit,
/// and its folder exactly as before.
pub fn judge(case: &Case, o: &Outcome, before: &BTreeMap<PathBuf, (u64, SystemTime)>) -> Option<String> {
    let err = o.stderr.trim_end();
    if o.timed_out {
        return Some(format!("hung (killed after {} s)", TIMEOUT.as_secs()));
    }
    if let Some(sig) = o.signal {
        return Some(format!("killed by signal {sig}: {err}"));
    }
    if err.contains("panicked") || err.contains("memory allocation") {
        return Some(format!("panicked or aborted: {err}"));
    }
    if o.peak_rss > PEAK_RSS_LIMIT {
        return Some(format!("peak memory {} MB over the limit", o.peak_rss >> 20));
    }
    let (code, needles) = match &case.expect {
        Expect::Refused(n) => (1, n),
        Expect::Usage(n) => (2, n),
    };
    if o.code != Some(code) {
        return Some(format!("exit code {:?}, expected {code}: {err}", o.code));
    }
    let message = match case.expect {
        Expect::Refused(_) => {
            let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
            if lines.len() != 1 {
                return Some(format!("{} error lines, expected one: {err}", lines.len()));
            }
            lines[0].to_string()
        }
        Expect::Usage(_) => err.to_string(),
    };
    if let Some(n) = needles.iter().find(|n| !message.contains(n.as_str())) {
        return Some(format!("'{n}' not in: {message}"));
    }
    let after = snapshot(&case.dir);
    if let Some((path, _)) = after.iter().find(|(p, m)| before.get(*p) != Some(m)) {
        return Some(format!("left {} behind", path.display()));
    }
    if let Some(path) = before.keys().find(|p| !after.contains_key(*p)) {
        return Some(format!("removed {}", path.display()));
    }
    None
}
