//! `mannequin batch` on this machine: bad manifests refused at `plan` with the line and field and
//! nothing written; a failing person not stopping the others, and a second `batch local`
//! finishing only what is left; the index taken from `JOB_COMPLETION_INDEX`; and the Kubernetes
//! Job held to the Job API's schema by `kubernetes-validate` (PyPI), which CI installs.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use common::{copy_dir, mannequin, ok, one_line_error, read_json, s, scratch, tiny_subject};

/// A tiny synthetic dataset (64², 10 frames, the light body), made once for every test here:
/// batch runs only read their inputs, so people may share one.
fn subject() -> &'static Path {
    static DATA: OnceLock<PathBuf> = OnceLock::new();
    DATA.get_or_init(|| {
        let data = scratch("batch_subject").join("subject");
        ok(mannequin(&tiny_subject("1", &data)));
        data
    })
}

fn write(path: &Path, text: &str) -> PathBuf {
    std::fs::write(path, text).unwrap();
    path.to_path_buf()
}

fn plan(manifest: &Path, run: &Path, engine: &str) -> std::process::Output {
    mannequin(&["batch", "plan", "--manifest", s(manifest), "--engine", engine, "--out", s(run)])
}

/// A person's step record.
fn record(run: &Path, id: &str, step: &str) -> serde_json::Value {
    read_json(&run.join("people").join(id).join("steps").join(format!("{step}.json")))
}

#[test]
fn bad_manifests_are_refused_at_plan_with_line_and_field() {
    let dir = scratch("batch_bad_manifests");
    let d = s(subject());
    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            format!("id,input,steps\nanna,{d},train\nbob,{d}/missing,train\n"),
            vec!["line 3", "`input`", "missing"],
        ),
        (format!("id,input,steps\nanna,{d},train\nanna,{d},train\n"), vec!["line 3", "`id`", "line 2"]),
        (
            format!("id,input,steps\nanna,{d},train+dance\n"),
            vec!["line 2", "`steps`", "unknown step `dance`"],
        ),
        (format!("id,input,steps\nanna,{d},eval+train\n"), vec!["line 2", "`steps`", "order"]),
        (
            format!("id,input,steps,train.speed\nanna,{d},train,3\n"),
            vec!["line 1", "`train.speed`", "no --speed"],
        ),
        (
            format!("id,input,steps,dance.iters\nanna,{d},train,3\n"),
            vec!["line 1", "`dance.iters`", "unknown step"],
        ),
        (
            format!("id,input,steps,train.iters\nanna,{d},train,\nbob,{d},train,many\n"),
            vec!["line 3", "`train.iters`", "many"],
        ),
        (
            format!("id,input,steps,train.out\nanna,{d},train,x\n"),
            vec!["line 1", "`train.out`", "set by the batch"],
        ),
        (
            format!("id,input,steps,eval.samples\nanna,{d},train,10\n"),
            vec!["line 2", "`eval.samples`", "do not run"],
        ),
        (format!("id,input,steps\nanna,{d},train,extra\n"), vec!["line 2", "4 fields, expected 3"]),
        (format!("id,input,steps\nan/na,{d},train\n"), vec!["line 2", "`id`", "an/na"]),
        (format!("id,input,steps\nanna,{d}/images,train\n"), vec!["line 2", "`steps`", "capture"]),
        (format!("id,input\nanna,{d}\n"), vec!["line 1", "no `steps` column"]),
    ];
    for (i, (text, needles)) in cases.iter().enumerate() {
        let manifest = write(&dir.join(format!("bad{i}.csv")), text);
        let run = dir.join(format!("run{i}"));
        one_line_error(&plan(&manifest, &run, "slurm"), needles);
        assert!(!run.exists(), "case {i}: a refused manifest wrote {}", run.display());
    }
}

#[test]
fn a_failing_person_does_not_stop_the_others_and_a_rerun_finishes_only_what_is_left() {
    let dir = scratch("batch_local");
    // A dataset that `train` refuses: its camera file is not an archive.
    let broken = dir.join("broken");
    copy_dir(subject(), &broken);
    std::fs::write(broken.join("cameras.npz"), b"not a zip").unwrap();
    let header = "id,input,steps,train.iters,train.body,train.checkpoint-every,eval.samples";
    let rows = [
        format!("anna,{},train+export+eval,3,default-lod1,3,1000", s(subject())),
        format!("bob,{},train+eval,3,default-lod1,3,1000", s(&broken)),
        format!("cleo,{},train,2,default-lod1,1,", s(subject())),
    ];
    let manifest = write(&dir.join("people.csv"), &format!("{header}\n{}\n", rows.join("\n")));
    let run = dir.join("run");
    ok(plan(&manifest, &run, "local"));
    let local = || mannequin(&["batch", "local", "--run", s(&run), "--jobs", "2"]);
    one_line_error(&local(), &["1 of 3 people failed", "bob"]);

    let status = ok(mannequin(&["batch", "status", "--run", s(&run), "--json"]));
    let status: serde_json::Value = serde_json::from_slice(&status.stdout).unwrap();
    let people = status["people"].as_array().unwrap();
    let state = |i: usize| people[i]["status"].as_str().unwrap().to_string();
    assert_eq!([state(0), state(1), state(2)], ["done", "failed", "done"]);
    assert_eq!(status["left"], serde_json::json!([1]));
    let bob_train = &people[1]["steps"][0];
    assert_eq!(bob_train["status"], "failed");
    let error = bob_train["error"].as_str().unwrap();
    assert!(error.contains("cameras.npz") && !error.contains('\n'), "{error}");
    assert_eq!(people[1]["steps"][1]["status"], "pending");
    assert!(people[0]["scores"]["novel_view"]["psnr"].as_f64().unwrap() > 5.0, "{}", people[0]["scores"]);
    assert!(run.join("people/anna/export/avatar.glb").is_file());

    // Bob's input mended, the same array again: only Bob's steps run.
    std::fs::copy(subject().join("cameras.npz"), broken.join("cameras.npz")).unwrap();
    let before: Vec<serde_json::Value> =
        ["train", "export", "eval"].iter().map(|st| record(&run, "anna", st)).collect();
    ok(local());
    for (st, old) in ["train", "export", "eval"].iter().zip(&before) {
        assert_eq!(&record(&run, "anna", st), old, "anna's finished {st} ran again");
    }
    assert_eq!(record(&run, "bob", "train")["attempts"], 2);
    assert_eq!(record(&run, "bob", "eval")["state"], "done");
    let table = String::from_utf8(ok(mannequin(&["batch", "report", "--run", s(&run)])).stdout).unwrap();
    assert!(table.contains("3 people: 3 done"), "{table}");
    assert!(read_json(&run.join("report.json"))["counts"]["done"] == 3);
}

#[test]
fn the_task_index_comes_from_job_completion_index() {
    let dir = scratch("batch_index");
    let d = s(subject());
    let header = "id,input,steps,train.iters,train.body";
    let manifest = write(
        &dir.join("people.csv"),
        &format!("{header}\nanna,{d},train,1,default-lod1\nbob,{d},train,1,default-lod1\n"),
    );
    let run = dir.join("run");
    ok(mannequin(&[
        "batch",
        "plan",
        "--manifest",
        s(&manifest),
        "--engine",
        "kubernetes",
        "--out",
        s(&run),
        "--image",
        "m:1",
        "--mount",
        "/",
    ]));
    let task = |index: Option<&str>| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_mannequin"));
        c.args(["batch", "task", "--run", s(&run)])
            .env_remove("SLURM_ARRAY_TASK_ID")
            .env_remove("JOB_COMPLETION_INDEX");
        if let Some(i) = index {
            c.env("JOB_COMPLETION_INDEX", i);
        }
        c.output().unwrap()
    };
    ok(task(Some("1")));
    assert_eq!(record(&run, "bob", "train")["state"], "done");
    assert!(!run.join("people/anna/steps").exists(), "index 1 ran anna");
    one_line_error(&task(Some("2")), &["task index 2", "2 people"]);
    one_line_error(&task(None), &["JOB_COMPLETION_INDEX"]);
}

#[test]
fn a_run_larger_than_slurms_array_limit_is_split_and_each_part_finds_its_people() {
    let dir = scratch("batch_split");
    let d = s(subject());
    let rows: Vec<String> =
        ["a", "b", "c"].iter().map(|id| format!("{id},{d},train,1,default-lod1")).collect();
    let manifest = write(
        &dir.join("people.csv"),
        &format!("id,input,steps,train.iters,train.body\n{}\n", rows.join("\n")),
    );
    let run = dir.join("run");
    let plan = ["batch", "plan", "--manifest", s(&manifest), "--engine", "slurm", "--out", s(&run)];
    ok(mannequin(&[&plan[..], &["--array-max", "2"]].concat()));
    assert!(!run.join("slurm.sbatch").exists());
    let first = std::fs::read_to_string(run.join("slurm-0.sbatch")).unwrap();
    let second = std::fs::read_to_string(run.join("slurm-1.sbatch")).unwrap();
    assert!(first.contains("--array=0-1\n") && first.contains("--offset 0\n"), "{first}");
    assert!(second.contains("--array=0-0\n") && second.contains("--offset 2\n"), "{second}");
    // The second script's only task, as Slurm starts it.
    let o = Command::new(env!("CARGO_BIN_EXE_mannequin"))
        .args(["batch", "task", "--run", s(&run), "--offset", "2"])
        .env("SLURM_ARRAY_TASK_ID", "0")
        .env_remove("JOB_COMPLETION_INDEX")
        .output()
        .unwrap();
    ok(o);
    assert_eq!(record(&run, "c", "train")["state"], "done");
    assert!(!run.join("people/a/steps").exists() && !run.join("people/b/steps").exists());
}

/// `kubernetes-validate`: on the PATH, or where `.ci/run` installs it.
fn kubernetes_validate() -> Option<PathBuf> {
    let home = std::env::var_os("HOME").map(PathBuf::from).unwrap_or_default();
    let installed = home.join(".cache/kubernetes-validate/bin/kubernetes-validate");
    if installed.is_file() {
        return Some(installed);
    }
    let found =
        Command::new("kubernetes-validate").arg("--version").output().is_ok_and(|o| o.status.success());
    found.then(|| PathBuf::from("kubernetes-validate"))
}

#[test]
fn the_kubernetes_job_meets_the_job_api_schema() {
    let dir = scratch("batch_kubernetes");
    let d = s(subject());
    let manifest = write(
        &dir.join("people.csv"),
        &format!("id,input,steps\nanna,{d},train+eval\nbob,{d},train+export\n"),
    );
    let run = dir.join("runs/shop day 1");
    let cmd = ["batch", "plan", "--manifest", s(&manifest), "--engine", "kubernetes", "--out", s(&run)];
    one_line_error(&mannequin(&cmd), &["--image"]);
    one_line_error(
        &mannequin(&[&cmd[..], &["--image", "mannequin:1", "--mount", s(&dir.join("runs"))]].concat()),
        &["line 2", "`input`", "outside the shared volume"],
    );
    // The pods mount the volume that holds the inputs and the run folder alike.
    let volume = subject().parent().unwrap().parent().unwrap();
    let more = ["--image", "registry.example/mannequin:1", "--throttle", "4", "--mount", s(volume)];
    ok(mannequin(&[&cmd[..], &more[..]].concat()));
    let job = std::fs::read_to_string(run.join("job.yaml")).unwrap();
    for needle in
        ["completionMode: Indexed", "completions: 2", "parallelism: 2", "claimName: \"mannequin-runs\""]
    {
        assert!(job.contains(needle), "{needle} not in:\n{job}");
    }
    let Some(validate) = kubernetes_validate() else {
        let required =
            ["CI", "MANNEQUIN_REQUIRE_KUBERNETES_VALIDATE"].iter().any(|v| std::env::var_os(v).is_some());
        assert!(!required, "kubernetes-validate is not installed (pip install kubernetes-validate)");
        eprintln!("warning: kubernetes-validate is not installed; the Job is not checked against the schema");
        return;
    };
    let check = |path: &Path| Command::new(&validate).arg("--strict").arg(path).output().unwrap();
    let o = check(&run.join("job.yaml"));
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    // The check can fail: a Job with a count as text is refused.
    let bad = write(&dir.join("bad.yaml"), &job.replace("completions: 2", "completions: \"two\""));
    assert!(!check(&bad).status.success(), "kubernetes-validate took a malformed Job");
}
