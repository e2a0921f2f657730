//! Wall-clock sampling shared by the benches.

use std::time::Instant;

/// Median and fastest wall time of `f` in milliseconds over `reps` calls, after one warm-up call.
pub fn median_and_min_ms(reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    f();
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    (t[reps / 2], t[0])
}
