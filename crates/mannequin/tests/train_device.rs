//! `train --device gpu` (lavapipe where the machine has no GPU) against the CPU on a tiny
//! synthetic subject: the first iteration's loss is the whole forward pass, the second's follows
//! one backward pass and Adam step, so the two devices must agree on both.

mod common;
use common::{mannequin, ok, s, scratch, tiny_subject};

/// The loss logged at each checkpoint of a run.
fn losses(stderr: &[u8]) -> Vec<f64> {
    let log = String::from_utf8_lossy(stderr);
    let losses: Vec<f64> = log
        .lines()
        .filter_map(|l| l.split("loss ").nth(1))
        .filter_map(|rest| rest.split(',').next()?.trim().parse().ok())
        .collect();
    assert_eq!(losses.len(), 2, "expected a loss per checkpoint in: {log}");
    losses
}

#[test]
fn gpu_training_follows_the_cpu() {
    let dir = scratch("train-device");
    let data = dir.join("subject");
    ok(mannequin(&tiny_subject("3", &data)));
    let run = |device: &str| {
        let out = dir.join(device);
        let args = ["train", "--data", s(&data), "--out", s(&out), "--body", "default-lod1"];
        let more = ["--iters", "2", "--checkpoint-every", "1", "--device", device];
        losses(&ok(mannequin(&[&args[..], &more[..]].concat())).stderr)
    };
    let (cpu, gpu) = (run("cpu"), run("gpu"));
    // Forward only: float rounding apart, plus the log's 6 decimals.
    assert!((cpu[0] - gpu[0]).abs() <= 2e-6 + 1e-4 * cpu[0], "first loss: cpu {} gpu {}", cpu[0], gpu[0]);
    // After one update: Adam's first step is about lr × sign(gradient), so a gradient that
    // differs more than rounding would move the second loss visibly.
    assert!((cpu[1] - gpu[1]).abs() <= 2e-6 + 1e-3 * cpu[1], "second loss: cpu {} gpu {}", cpu[1], gpu[1]);
    assert!(cpu[1] < cpu[0], "one step did not lower the loss: {cpu:?}");
    std::fs::remove_dir_all(dir).unwrap();
}
