//! The exact Euclidean distance transform (Felzenszwalb & Huttenlocher): for every pixel, the
//! distance to the nearest pixel of a set, by two passes of the 1-D lower envelope of parabolas.
//! The fit reads it to pull the body's projection inside the person's mask.

/// Distance in pixels from each pixel to the nearest `true` one (0 on the set itself);
/// infinite everywhere when the set is empty.
pub fn distance_to(set: &[bool], width: usize, height: usize) -> Vec<f32> {
    let mut d: Vec<f64> = set.iter().map(|&s| if s { 0.0 } else { f64::INFINITY }).collect();
    let mut line = Vec::new();
    for x in 0..width {
        line.clear();
        line.extend((0..height).map(|y| d[y * width + x]));
        let column = squared_1d(&line);
        (0..height).for_each(|y| d[y * width + x] = column[y]);
    }
    for y in 0..height {
        let row = squared_1d(&d[y * width..(y + 1) * width]);
        d[y * width..(y + 1) * width].copy_from_slice(&row);
    }
    d.into_iter().map(|v| v.sqrt() as f32).collect()
}

/// min over q of (p − q)² + f(q), for every p.
fn squared_1d(f: &[f64]) -> Vec<f64> {
    let n = f.len();
    let mut out = vec![f64::INFINITY; n];
    let mut v = Vec::with_capacity(n);
    let mut z: Vec<f64> = Vec::with_capacity(n + 1);
    for q in (0..n).filter(|&q| f[q].is_finite()) {
        let fq = f[q] + (q * q) as f64;
        // The new parabola hides those whose span starts after it overtakes them.
        let mut start = f64::NEG_INFINITY;
        while let Some(&p) = v.last() {
            start = (fq - (f[p] + (p * p) as f64)) / (2.0 * (q as f64 - p as f64));
            if start > *z.last().unwrap() {
                break;
            }
            v.pop();
            z.pop();
            start = f64::NEG_INFINITY;
        }
        v.push(q);
        z.push(start);
    }
    if v.is_empty() {
        return out;
    }
    let mut k = 0;
    for (p, o) in out.iter_mut().enumerate() {
        while k + 1 < v.len() && z[k + 1] < p as f64 {
            k += 1;
        }
        let q = v[k];
        *o = (p as f64 - q as f64).powi(2) + f[q];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_brute_force() {
        let (w, h) = (23, 17);
        let set: Vec<bool> = (0..w * h).map(|i| (i * 7919 + i / 5) % 37 == 0).collect();
        let d = distance_to(&set, w, h);
        for y in 0..h {
            for x in 0..w {
                let want = (0..w * h)
                    .filter(|&i| set[i])
                    .map(|i| {
                        ((x as f64 - (i % w) as f64).powi(2) + (y as f64 - (i / w) as f64).powi(2)).sqrt()
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!((d[y * w + x] as f64 - want).abs() < 1e-5, "({x}, {y}): {} vs {want}", d[y * w + x]);
            }
        }
    }

    #[test]
    fn an_empty_set_is_infinitely_far() {
        assert!(distance_to(&[false; 6], 3, 2).iter().all(|d| d.is_infinite()));
    }
}
