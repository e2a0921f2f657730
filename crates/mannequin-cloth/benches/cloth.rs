//! The cloth solver's speed, with a per-phase breakdown to show where the next speed-up lies.
//!
//! 1. Grids of 64×32 and 100×100 particles (1 cm apart) pinned along one edge, let go
//!    horizontally to swing down: 10 substeps per 1/60 s frame, with and without self-collision.
//!    When NVIDIA Newton is installed (`tools/oracles/cloth_newton.py`, in the venv named by
//!    `MANNEQUIN_NEWTON_PYTHON`, default `$HOME/.cache/mannequin-newton/bin/python`), its XPBD
//!    solver is timed on the same grids in the same run and the ratio printed.
//! 2. The target: a 10k-particle garment (a tube around the hips, its top ring attached
//!    to the body) on the default body walking, with self-collision and body collision, per
//!    1/30 s frame (issue 38's target: ≤ 100 ms on 2 cores), and the process's peak memory.
//!
//! `cargo bench -p mannequin-cloth --bench cloth [-- --frames N]`

use std::time::{Duration, Instant};

use mannequin_body::{BodyModel, Motion, Settling, pose_frames, shape_body};
use mannequin_cloth::{Attachment, Body, Cloth, Material, PhaseTimes, Settings, Simulator};
use mannequin_mesh::TriMesh;
use mannequin_mesh::ring_tube::RingLayout;

#[path = "../tests/common/mod.rs"]
mod common;

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
use bench_args::arg;

/// The walking garment's target per 1/30 s frame on 2 cores (issue 38).
const TARGET_MS: f64 = 100.0;

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn breakdown(times: &PhaseTimes, frames: usize) {
    let phases: Vec<String> =
        times.named().iter().map(|(name, d)| format!("{name} {:.1}", ms(*d) / frames as f64)).collect();
    println!("      per frame (ms): {}", phases.join(", "));
}

/// Mannequin on a pinned grid: ms per frame over `frames` frames.
fn grid_run(nx: usize, ny: usize, self_collision: bool, frames: usize) -> f64 {
    // Horizontal, 1 cm apart, at height 1 m.
    let mesh = common::grid(nx, ny, 0.01, [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    let pins: Vec<u32> = (0..nx as u32).collect();
    let cloth = Cloth::new(&mesh, &Material::named("cotton").expect("cotton"), &pins).expect("cloth");
    let settings = Settings { substeps: Settings::substeps_at(60.0), self_collision, ..Settings::default() };
    let mut sim = Simulator::new(cloth, None, Vec::new(), settings).expect("simulator");
    let start = Instant::now();
    for _ in 0..frames {
        sim.step_frame(&[], &[], 1.0 / 60.0).expect("step");
    }
    let per_frame = ms(start.elapsed()) / frames as f64;
    breakdown(&sim.phase_times(), frames);
    per_frame
}

/// Newton's ms per frame for each grid, plain and with self-collision, from its own script.
fn newton_times(frames: usize) -> Option<serde_json::Value> {
    let python = std::env::var("MANNEQUIN_NEWTON_PYTHON").unwrap_or_else(|_| {
        format!("{}/.cache/mannequin-newton/bin/python", std::env::var("HOME").unwrap_or_default())
    });
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tools/oracles/cloth_newton.py");
    let out =
        std::process::Command::new(&python).args([script, "time", "--frames", &frames.to_string()]).output();
    match out {
        // Warp logs to stdout too: the JSON is the last line.
        Ok(o) if o.status.success() => {
            let stdout = String::from_utf8_lossy(&o.stdout);
            let parsed = stdout.lines().last().and_then(|l| serde_json::from_str(l).ok());
            if parsed.is_none() {
                println!("  Newton printed no JSON on its last line: {stdout}");
            }
            parsed
        }
        Ok(o) => {
            println!("  Newton failed: {}", String::from_utf8_lossy(&o.stderr).lines().last().unwrap_or(""));
            None
        }
        Err(e) => {
            println!("  Newton not run ({python}: {e}); set MANNEQUIN_NEWTON_PYTHON to its venv's python");
            None
        }
    }
}

/// A tube of about `particles` particles around the hips from the waist down 55 cm, 2 cm out from
/// the body's widest point in that span (1 cm rings), and the indices of its top ring.
fn hip_tube(body: &TriMesh, particles: usize) -> (TriMesh, Vec<u32>) {
    let (waist, length) = (-0.12f32, 0.55f32);
    let radius = body
        .positions
        .iter()
        .filter(|p| p[1] <= waist && p[1] >= waist - length && p[0].abs() < 0.3)
        .map(|p| p[0].hypot(p[2]))
        .fold(0.0f32, f32::max)
        + 0.02;
    let rings = (length / 0.01).round() as usize;
    let segments = particles / (rings + 1);
    let layout = RingLayout::uniform(segments, rings);
    let positions = layout
        .ring_of_vertices()
        .enumerate()
        .map(|(v, r)| {
            let a = std::f32::consts::TAU * (v - layout.vertex(r, 0)) as f32 / segments as f32;
            [radius * a.cos(), waist - layout.rings[r] * length, radius * a.sin()]
        })
        .collect();
    let (faces, _) = layout.tube();
    (TriMesh::new(positions, faces), (0..segments as u32).collect())
}

/// Peak resident memory of this process, from /proc (Linux), in MiB.
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    Some(line.split_whitespace().nth(1)?.parse::<f64>().ok()? / 1024.0)
}

fn walking_garment(frames: usize) {
    let model = BodyModel::default_body();
    let shaped = shape_body(&model, &[]).expect("shape");
    let motion = Motion::walk_cycle(frames as f32 / 30.0, 30.0);
    let schedule = Settling::new(&model, &motion, 0.5).expect("schedule");
    let body_at = |k: usize| -> Vec<[f32; 3]> {
        let (pose, trans) = schedule.pose(k);
        let posed = pose_frames(&model, &shaped, pose, trans).expect("pose");
        posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect()
    };
    let faces = model.template_mesh().faces;
    let rest = body_at(0);
    let (garment, band) = hip_tube(&TriMesh::new(rest.clone(), faces.clone()), 10_000);
    let attachments =
        band.iter().map(|&v| Attachment::bind(&rest, &faces, v, garment.positions[v as usize])).collect();
    let cloth = Cloth::new(&garment, &Material::named("cotton").expect("cotton"), &[]).expect("cloth");
    let settings = Settings::default();
    let mut sim =
        Simulator::new(cloth, Some(Body::new(faces.clone())), attachments, settings).expect("simulator");
    let mut previous = rest;
    let mut walking = Duration::ZERO;
    // The walk is timed alone: settling on a still body is cheaper than following a moving one.
    let mut settled = PhaseTimes::default();
    for k in 1..schedule.len() {
        let next = body_at(k);
        if k == schedule.settle {
            settled = sim.phase_times();
        }
        let start = Instant::now();
        sim.step_frame(&previous, &next, 1.0 / 30.0).expect("step");
        if k >= schedule.settle {
            walking += start.elapsed();
        }
        previous = next;
    }
    let walked = schedule.len() - schedule.settle;
    let per_frame = ms(walking) / walked as f64;
    println!(
        "walking body, {} particles, self-collision and body collision, 20 substeps per 1/30 s:",
        garment.vertex_count()
    );
    println!(
        "  {per_frame:.1} ms per frame over {walked} walking frames; target ≤ {TARGET_MS} ms: {} (ratio target / ours {:.2})",
        if per_frame <= TARGET_MS { "met" } else { "NOT met" },
        TARGET_MS / per_frame
    );
    let (all, before) = (sim.phase_times(), settled);
    let walk = PhaseTimes {
        prediction: all.prediction - before.prediction,
        hashing: all.hashing - before.hashing,
        stretch: all.stretch - before.stretch,
        bending: all.bending - before.bending,
        self_contacts: all.self_contacts - before.self_contacts,
        body_contacts: all.body_contacts - before.body_contacts,
    };
    breakdown(&walk, walked);
    if let Some(mib) = peak_memory_mib() {
        println!("  peak memory of the whole bench process: {mib:.0} MiB");
    }
}

fn main() {
    let frames = arg("--frames", 60);
    println!("pinned grids, 1 cm apart, 10 substeps per 1/60 s, {frames} frames (ms per frame):");
    let newton = newton_times(frames);
    for (nx, ny) in [(64, 32), (100, 100)] {
        for self_collision in [false, true] {
            let case = if self_collision { "self_collision" } else { "plain" };
            println!("  {nx}×{ny} {case}:");
            let ours = grid_run(nx, ny, self_collision, frames);
            let theirs = newton.as_ref().and_then(|n| n[format!("{nx}x{ny}")][case].as_f64());
            match theirs {
                Some(t) => {
                    println!("    Mannequin {ours:.1}, Newton {t:.1}: {:.1}× Newton's speed", t / ours)
                }
                None => println!("    Mannequin {ours:.1}"),
            }
        }
    }
    walking_garment(arg("--walk-frames", 30));
}
