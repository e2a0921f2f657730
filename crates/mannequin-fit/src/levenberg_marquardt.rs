//! Levenberg–Marquardt on a residual vector, with central-difference Jacobians over the free
//! parameters (or a Jacobian the problem computes itself). The fits here have ~100 parameters and a few hundred residuals, so dense normal
//! equations solved by Cholesky are the simple and fast choice.

/// How a minimisation went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    pub initial_cost: f64,
    pub final_cost: f64,
    pub iterations: usize,
}

/// ½‖r‖².
fn cost(r: &[f64]) -> f64 {
    0.5 * r.iter().map(|v| v * v).sum::<f64>()
}

/// Minimises ½‖f(x)‖² over the parameters `free` (the others stay as they are), for at most
/// `iterations` accepted or rejected steps. `step` is the finite-difference half-width.
pub fn minimise(
    f: &dyn Fn(&[f64]) -> Vec<f64>,
    x: &mut [f64],
    free: &[usize],
    iterations: usize,
    step: f64,
) -> Summary {
    let central = |x: &[f64]| -> Vec<Vec<f64>> {
        let mut probe = x.to_vec();
        free.iter()
            .map(|&i| {
                probe[i] = x[i] + step;
                let plus = f(&probe);
                probe[i] = x[i] - step;
                let minus = f(&probe);
                probe[i] = x[i];
                plus.iter().zip(&minus).map(|(p, q)| (p - q) / (2.0 * step)).collect()
            })
            .collect()
    };
    minimise_with(f, &central, x, free, iterations)
}

/// [`minimise`] with the Jacobian given: `jacobian(x)` returns ∂r/∂x_i for each free parameter
/// i, in the order of `free` (a problem that knows which residuals a parameter moves can
/// difference far fewer of them).
pub fn minimise_with(
    f: &dyn Fn(&[f64]) -> Vec<f64>,
    jacobian: &dyn Fn(&[f64]) -> Vec<Vec<f64>>,
    x: &mut [f64],
    free: &[usize],
    iterations: usize,
) -> Summary {
    let mut r = f(x);
    let initial_cost = cost(&r);
    let mut current = initial_cost;
    let mut lambda = 1e-3;
    let mut done = 0;
    let n = free.len();
    while done < iterations {
        done += 1;
        let jac = jacobian(x);
        let mut jtj = vec![0.0; n * n];
        let mut jtr = vec![0.0; n];
        for a in 0..n {
            jtr[a] = jac[a].iter().zip(&r).map(|(j, r)| j * r).sum();
            for b in a..n {
                let v: f64 = jac[a].iter().zip(&jac[b]).map(|(p, q)| p * q).sum();
                jtj[a * n + b] = v;
                jtj[b * n + a] = v;
            }
        }
        loop {
            let mut m = jtj.clone();
            for a in 0..n {
                m[a * n + a] += lambda * (jtj[a * n + a] + 1e-9);
            }
            let Some(delta) = cholesky_solve(&mut m, &jtr, n) else {
                lambda *= 10.0;
                continue;
            };
            let trial: Vec<f64> = {
                let mut t = x.to_vec();
                free.iter().zip(&delta).for_each(|(&i, d)| t[i] -= d);
                t
            };
            let rt = f(&trial);
            let c = cost(&rt);
            if c < current {
                let converged = current - c < 1e-10 * current.max(1e-12);
                x.copy_from_slice(&trial);
                r = rt;
                current = c;
                lambda = (lambda / 3.0).max(1e-9);
                if converged {
                    return Summary { initial_cost, final_cost: current, iterations: done };
                }
                break;
            }
            lambda *= 4.0;
            if lambda > 1e10 {
                return Summary { initial_cost, final_cost: current, iterations: done };
            }
        }
    }
    Summary { initial_cost, final_cost: current, iterations: done }
}

/// Solves M d = b for symmetric positive definite M (overwritten by its factor); None when M is
/// not positive definite.
fn cholesky_solve(m: &mut [f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    for j in 0..n {
        let mut d = m[j * n + j];
        for k in 0..j {
            d -= m[j * n + k] * m[j * n + k];
        }
        if d <= 0.0 || !d.is_finite() {
            return None;
        }
        let d = d.sqrt();
        m[j * n + j] = d;
        for i in j + 1..n {
            let mut s = m[i * n + j];
            for k in 0..j {
                s -= m[i * n + k] * m[j * n + k];
            }
            m[i * n + j] = s / d;
        }
    }
    let mut y = b.to_vec();
    for i in 0..n {
        for k in 0..i {
            y[i] -= m[i * n + k] * y[k];
        }
        y[i] /= m[i * n + i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            y[i] -= m[k * n + i] * y[k];
        }
        y[i] /= m[i * n + i];
    }
    Some(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_rosenbrock_minimum() {
        // r = (10 (y − x²), 1 − x): the minimum is (1, 1), reached along a curved valley.
        let f = |p: &[f64]| vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]];
        let mut x = [-1.2, 1.0];
        let s = minimise(&f, &mut x, &[0, 1], 200, 1e-6);
        assert!((x[0] - 1.0).abs() < 1e-5 && (x[1] - 1.0).abs() < 1e-5, "{x:?} {s:?}");
    }

    #[test]
    fn fixed_parameters_stay_put() {
        let f = |p: &[f64]| vec![p[0] - 3.0, p[1] - 5.0];
        let mut x = [0.0, 0.0];
        minimise(&f, &mut x, &[1], 50, 1e-6);
        assert_eq!(x[0], 0.0);
        assert!((x[1] - 5.0).abs() < 1e-8);
    }

    #[test]
    fn cholesky_solves_a_known_system() {
        let mut m = [4.0, 2.0, 2.0, 3.0];
        let d = cholesky_solve(&mut m, &[2.0, 1.0], 2).unwrap();
        // [4 2; 2 3] d = [2 1] → d = (0.5, 0).
        assert!((d[0] - 0.5).abs() < 1e-12 && d[1].abs() < 1e-12);
    }
}
