//! Issue 42's crafted bad input, every case run under a memory limit: no panic, abort, hang or
//! non-finite output, peak memory within 1 GB, one line naming the file or flag and the field,
//! and nothing left behind (the cases themselves are made in `crafted/`).

mod common;
mod crafted;

use std::sync::Mutex;

use crafted::{Case, Fixtures, run};

/// At least this many cases (issue 42).
const MIN_CASES: usize = 500;

#[test]
fn crafted_inputs_are_refused_cleanly() {
    let root = common::scratch("crafted_inputs");
    let fixtures = Fixtures::make(&root.join("fixtures"));
    let cases_dir = root.join("cases");
    // MANNEQUIN_CRAFTED=inputs|cloth|avatar runs one area's cases alone, while working on it.
    let only = std::env::var("MANNEQUIN_CRAFTED").ok();
    let areas: [(&str, crafted::MakeCases); 3] = [
        ("inputs", crafted::inputs::cases),
        ("cloth", crafted::cloth::cases),
        ("avatar", crafted::avatar::cases),
    ];
    let mut cases: Vec<Case> = Vec::new();
    for (area, make) in areas {
        if only.as_deref().is_none_or(|o| o == area) {
            cases.extend(make(&fixtures, &cases_dir.join(area)));
        }
    }
    let mut names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        panic!("case name {} used twice", w[0]);
    }

    let fixtures_before = run::snapshot(&fixtures.root);
    let logs = root.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    let queue = Mutex::new(cases.iter().enumerate());
    let failures = Mutex::new(Vec::new());
    let peak = Mutex::new((0u64, String::new()));
    let times = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| {
                loop {
                    let Some((i, case)) = queue.lock().unwrap().next() else { return };
                    let before = run::snapshot(&case.dir);
                    let outcome = run::execute(case, &logs.join(format!("{i}.stderr")));
                    {
                        let mut p = peak.lock().unwrap();
                        if outcome.peak_rss > p.0 {
                            *p = (outcome.peak_rss, case.name.clone());
                        }
                        times.lock().unwrap().push((outcome.seconds, case.name.as_str()));
                    }
                    if let Some(why) = run::judge(case, &outcome, &before) {
                        failures.lock().unwrap().push(format!("{} ({:?}): {why}", case.name, case.args));
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    let (peak_rss, peak_case) = peak.into_inner().unwrap();
    let mut times = times.into_inner().unwrap();
    times.sort_by(|a, b| b.0.total_cmp(&a.0));
    let slowest: Vec<String> = times.iter().take(5).map(|(t, name)| format!("{name} {t:.1} s")).collect();
    println!(
        "{} crafted cases, {} refused cleanly; peak memory {} MB ({peak_case}); {:.0} s in all; slowest: {}",
        cases.len(),
        cases.len() - failures.len(),
        peak_rss >> 20,
        times.iter().map(|t| t.0).sum::<f64>(),
        slowest.join(", ")
    );
    for f in &failures {
        println!("FAIL {f}");
    }
    if only.is_none() {
        assert!(cases.len() >= MIN_CASES, "{} cases, expected at least {MIN_CASES}", cases.len());
    }
    assert!(failures.is_empty(), "{} of {} cases failed (listed above)", failures.len(), cases.len());
    assert_eq!(run::snapshot(&fixtures.root), fixtures_before, "a case changed the shared fixtures");
}
