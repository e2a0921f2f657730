//! A real Slurm job array: three tiny synthetic people submitted with `sbatch`, one task killed
//! by `scancel` while it trains, the array submitted again, and the report read. The killed
//! person's training resumes from its checkpoint and nothing that had finished runs again.
//! Needs a running single-node Slurm (`tools/slurm/start-local.sh`, which `.ci/run` runs); it
//! fails without one under CI (`CI` or `MANNEQUIN_REQUIRE_SLURM`) and is skipped with a warning
//! elsewhere.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::{mannequin, ok, read_json, s, scratch, tiny_subject};

/// Whether a Slurm controller answers here.
fn slurm_up() -> bool {
    Command::new("sinfo").arg("-h").output().is_ok_and(|o| o.status.success() && !o.stdout.is_empty())
}

fn run(cmd: &str, args: &[&str]) -> String {
    let o = Command::new(cmd).args(args).output().unwrap_or_else(|e| panic!("{cmd}: {e}"));
    assert!(o.status.success(), "{cmd} {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

/// Waits until `done` holds, checking every 200 ms, for at most `limit`.
fn wait(what: &str, limit: Duration, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < limit, "waited {limit:?} for {what}");
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// Whether job `id` still has tasks in the queue.
fn queued(id: &str) -> bool {
    !run("squeue", &["-h", "-j", id]).trim().is_empty()
}

fn record(run: &Path, id: &str, step: &str) -> Option<serde_json::Value> {
    let path = run.join("people").join(id).join("steps").join(format!("{step}.json"));
    path.is_file().then(|| read_json(&path))
}

#[test]
fn a_killed_array_task_resumes_and_nothing_finished_runs_again() {
    if !slurm_up() {
        let required = ["CI", "MANNEQUIN_REQUIRE_SLURM"].iter().any(|v| std::env::var_os(v).is_some());
        assert!(!required, "no Slurm controller answers (sinfo); run tools/slurm/start-local.sh as root");
        eprintln!(
            "warning: no Slurm here (tools/slurm/start-local.sh starts one); the Slurm test is skipped"
        );
        return;
    }
    let dir = scratch("batch_slurm");
    // One tiny subject serves all three people: a task only reads its input.
    let data = dir.join("subject");
    ok(mannequin(&tiny_subject("2", &data)));
    let rows: Vec<String> = ["ada", "ben", "cy"]
        .iter()
        .map(|id| {
            // Ben trains long enough to be killed in the middle; the others briefly.
            let iters = if *id == "ben" { 3000 } else { 20 };
            format!("{id},{},train+export+eval,{iters},default-lod1,10,1000", s(&data))
        })
        .collect();
    let header = "id,input,steps,train.iters,train.body,train.checkpoint-every,eval.samples";
    let manifest = dir.join("people.csv");
    std::fs::write(&manifest, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
    let run_dir = dir.join("run");
    let plan = ["batch", "plan", "--manifest", s(&manifest), "--engine", "slurm", "--out", s(&run_dir)];
    ok(mannequin(&[&plan[..], &["--cpus", "1", "--memory-gib", "1", "--throttle", "3"]].concat()));
    let script = run_dir.join("slurm.sbatch");
    let text = std::fs::read_to_string(&script).unwrap();
    assert!(text.contains("#SBATCH --array=0-2%3"), "{text}");

    let job = run("sbatch", &["--parsable", s(&script)]).trim().split(';').next().unwrap().to_string();
    // Kill Ben's task once his training has written a checkpoint and goes on.
    let checkpoint = run_dir.join("people/ben/avatar/checkpoint.npz");
    wait("ben's first checkpoint", Duration::from_secs(300), || checkpoint.is_file());
    assert_eq!(record(&run_dir, "ben", "train").unwrap()["state"], "running");
    run("scancel", &[&format!("{job}_1")]);
    wait("the first array to end", Duration::from_secs(300), || !queued(&job));

    let status: serde_json::Value =
        serde_json::from_slice(&ok(mannequin(&["batch", "status", "--run", s(&run_dir), "--json"])).stdout)
            .unwrap();
    let people = status["people"].as_array().unwrap();
    let states: Vec<&str> = people.iter().map(|p| p["status"].as_str().unwrap()).collect();
    assert_eq!(states, ["done", "stopped", "done"], "{status}");
    assert_eq!(people[1]["steps"][0]["status"], "stopped");
    let finished: Vec<Option<serde_json::Value>> = ["ada", "cy"]
        .iter()
        .flat_map(|id| ["train", "export", "eval"].map(|st| record(&run_dir, id, st)))
        .collect();

    // The same script again: only Ben's steps run, his training from its checkpoint.
    let again = run("sbatch", &["--parsable", s(&script)]).trim().split(';').next().unwrap().to_string();
    wait("the second array to end", Duration::from_secs(600), || !queued(&again));
    let after: Vec<Option<serde_json::Value>> = ["ada", "cy"]
        .iter()
        .flat_map(|id| ["train", "export", "eval"].map(|st| record(&run_dir, id, st)))
        .collect();
    assert_eq!(after, finished, "a finished step ran again");
    let ben = record(&run_dir, "ben", "train").unwrap();
    assert_eq!((ben["state"].as_str(), ben["attempts"].as_u64()), (Some("done"), Some(2)), "{ben}");
    let log = std::fs::read_to_string(run_dir.join("logs/task-1.log")).unwrap();
    let resumed =
        log.lines().find(|l| l.contains("resuming from")).unwrap_or_else(|| panic!("no resume in:\n{log}"));
    let at: usize = resumed.rsplit("iteration ").next().unwrap().trim().parse().unwrap();
    assert!((10..3000).contains(&at), "{resumed}");

    let report = ok(mannequin(&["batch", "report", "--run", s(&run_dir)]));
    let table = String::from_utf8(report.stdout).unwrap();
    assert!(table.contains("3 people: 3 done"), "{table}");
    let json = read_json(&run_dir.join("report.json"));
    for p in json["people"].as_array().unwrap() {
        assert!(p["scores"]["novel_view"]["psnr"].as_f64().unwrap() > 5.0, "{p}");
    }
}
