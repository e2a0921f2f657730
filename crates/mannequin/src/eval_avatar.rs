//! `mannequin eval --model M --data D`: the avatar's scores on the dataset's test sets, printed
//! as a table (the scoring itself is `mannequin_avatar::evaluation`).

use std::cell::RefCell;
use std::path::Path;

use anyhow::Result;
use indicatif::ProgressBar;
use mannequin_avatar::evaluation::{AvatarScores, evaluate_avatar};
use mannequin_data::evaluation::EvalOptions;

use crate::progress::bar;

/// Scores with one progress bar per test set.
pub fn evaluate_with_progress(model: &Path, data: &Path, options: &EvalOptions) -> Result<AvatarScores> {
    let current: RefCell<Option<ProgressBar>> = RefCell::new(None);
    let on_set = |name: &str, frames: usize| {
        if let Some(b) = current.replace(Some(bar(2 * frames as u64, name))) {
            b.finish_and_clear();
        }
    };
    let on_frame = || {
        if let Some(b) = current.borrow().as_ref() {
            b.inc(1);
        }
    };
    let scores = evaluate_avatar(model, data, options, &on_set, &on_frame)?;
    if let Some(b) = current.take() {
        b.finish_and_clear();
    }
    Ok(scores)
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

pub fn print_scores(s: &AvatarScores) {
    println!("{:>11} {:>7} {:>8} {:>7} {:>7}", "test set", "frames", "PSNR", "SSIM", "LPIPS");
    for (name, set) in [("novel view", Some(&s.novel_view)), ("novel pose", s.novel_pose.as_ref())] {
        if let Some(set) = set {
            println!(
                "{name:>11} {:>7} {:>8.2} {:>7.4} {:>7}",
                set.frames,
                set.psnr,
                set.ssim,
                cell(set.lpips, 4)
            );
        }
    }
    let g = &s.geometry;
    println!(
        "geometry: Chamfer {} cm, P2S {} cm, normal consistency {}, normal angle {}°, normal MSE×1e3 {}",
        cell(g.chamfer_cm, 3),
        cell(g.p2s_cm, 3),
        cell(g.normal_consistency, 3),
        cell(g.normal_angle_deg, 2),
        cell(g.normal_mse_x1e3, 2)
    );
}
