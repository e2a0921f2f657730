//! Exact orientation predicates for the quality checks: the sign of a 2×2 or 3×3 determinant of
//! coordinate differences, right for any f32 input. A plain f64 evaluation answers when it is
//! farther from zero than its rounding error can reach (Shewchuk's first-stage bounds); otherwise
//! the determinant is evaluated exactly in floating-point expansions (sums of non-overlapping
//! f64s, Shewchuk 1997) and its sign read from the largest component.

use std::cmp::Ordering;

/// A point in f64, where the exact tests work.
pub(crate) type Point = [f64; 3];

/// Shewchuk's ccwerrboundA and o3derrboundA, (3 + 16ε)ε and (7 + 56ε)ε, rounded up.
const ORIENT2D_BOUND: f64 = 3.4e-16;
const ORIENT3D_BOUND: f64 = 7.8e-16;

/// Sign of (a − c)ₓ(b − c)ᵧ − (a − c)ᵧ(b − c)ₓ: positive when a, b, c turn counterclockwise.
pub(crate) fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Ordering {
    let left = (a[0] - c[0]) * (b[1] - c[1]);
    let right = (a[1] - c[1]) * (b[0] - c[0]);
    let det = left - right;
    if det.abs() > ORIENT2D_BOUND * (left.abs() + right.abs()) {
        return det.total_cmp(&0.0);
    }
    let d = |p: [f64; 2], k: usize| Expansion::difference(p[k], c[k]);
    d(a, 0).times(&d(b, 1)).minus(&d(a, 1).times(&d(b, 0))).sign()
}

/// Sign of det[a − d; b − d; c − d]: positive when d lies below the plane of a, b, c seen turning
/// counterclockwise from above.
pub(crate) fn orient3d(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Ordering {
    let [adx, ady, adz] = [0, 1, 2].map(|k| a[k] - d[k]);
    let [bdx, bdy, bdz] = [0, 1, 2].map(|k| b[k] - d[k]);
    let [cdx, cdy, cdz] = [0, 1, 2].map(|k| c[k] - d[k]);
    let det = adz * (bdx * cdy - cdx * bdy) + bdz * (cdx * ady - adx * cdy) + cdz * (adx * bdy - bdx * ady);
    let permanent = ((bdx * cdy).abs() + (cdx * bdy).abs()) * adz.abs()
        + ((cdx * ady).abs() + (adx * cdy).abs()) * bdz.abs()
        + ((adx * bdy).abs() + (bdx * ady).abs()) * cdz.abs();
    if det.abs() > ORIENT3D_BOUND * permanent {
        return det.total_cmp(&0.0);
    }
    let e = |p: [f64; 3], k: usize| Expansion::difference(p[k], d[k]);
    let minor = |p: [f64; 3], q: [f64; 3]| e(p, 0).times(&e(q, 1)).minus(&e(q, 0).times(&e(p, 1)));
    let terms = [e(a, 2).times(&minor(b, c)), e(b, 2).times(&minor(c, a)), e(c, 2).times(&minor(a, b))];
    terms[0].plus(&terms[1]).plus(&terms[2]).sign()
}

/// A number held exactly as a sum of f64 components of increasing magnitude that do not overlap.
#[derive(Debug, Clone, PartialEq)]
struct Expansion(Vec<f64>);

/// a + b = s + e exactly (Knuth's TwoSum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bv = s - a;
    let av = s - bv;
    (s, (a - av) + (b - bv))
}

/// a·b = p + e exactly: the fused multiply–add rounds only once.
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl Expansion {
    fn difference(a: f64, b: f64) -> Self {
        let (s, e) = two_sum(a, -b);
        Expansion(vec![e, s])
    }

    /// Adds one f64 (Shewchuk's Grow-Expansion).
    fn grow(mut self, b: f64) -> Self {
        let mut q = b;
        for h in &mut self.0 {
            let (sum, error) = two_sum(q, *h);
            *h = error;
            q = sum;
        }
        self.0.push(q);
        self
    }

    fn plus(&self, other: &Expansion) -> Expansion {
        other.0.iter().fold(self.clone(), |sum, &x| sum.grow(x))
    }

    fn minus(&self, other: &Expansion) -> Expansion {
        other.0.iter().fold(self.clone(), |sum, &x| sum.grow(-x))
    }

    fn times(&self, other: &Expansion) -> Expansion {
        let mut product = Expansion(Vec::new());
        for &x in &self.0 {
            for &y in &other.0 {
                let (p, e) = two_product(x, y);
                product = product.grow(e).grow(p);
            }
        }
        product
    }

    fn sign(&self) -> Ordering {
        self.0.iter().rev().find(|&&x| x != 0.0).map_or(Ordering::Equal, |x| x.total_cmp(&0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Ordering::{Equal, Greater, Less};

    #[test]
    fn clear_cases() {
        assert_eq!(orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), Greater);
        assert_eq!(orient2d([0.0, 0.0], [0.0, 1.0], [1.0, 0.0]), Less);
        assert_eq!(orient2d([0.0, 0.0], [1.0, 1.0], [3.0, 3.0]), Equal);
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(orient3d(a, b, c, [0.2, 0.2, -1.0]), Greater);
        assert_eq!(orient3d(a, b, c, [0.2, 0.2, 1.0]), Less);
        assert_eq!(orient3d(a, b, c, [5.0, -3.0, 0.0]), Equal);
    }

    /// Points a hair off a line, where the plain f64 determinant drowns in rounding: the exact
    /// sign follows from which side the offset is on, and exactly collinear points give zero.
    #[test]
    fn near_degenerate_cases_are_exact() {
        let on = |t: f64| [0.5 + t * 12.0, 0.5 + t * 12.0];
        for k in 1..50 {
            let t = k as f64 * 0.0137;
            let c = on(t);
            assert_eq!(orient2d([0.5, 0.5], [12.5, 12.5], c), Equal, "t = {t}");
            let tiny = f64::EPSILON * c[1].abs();
            assert_eq!(orient2d([0.5, 0.5], [12.5, 12.5], [c[0], c[1] + tiny]), Greater);
            assert_eq!(orient2d([0.5, 0.5], [12.5, 12.5], [c[0], c[1] - tiny]), Less);
        }
        // f32 points exactly on the plane z = x + y, and a hair above and below it.
        for k in 1..50 {
            let (x, y) = ((k as f32 * 0.173).sin(), (k as f32 * 0.291).cos());
            let z = x as f64 + y as f64;
            let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]);
            let d = [x as f64, y as f64, z];
            assert_eq!(orient3d(a, b, c, d), Equal);
            let hair = f64::EPSILON * z.abs();
            let (above, below) =
                (orient3d(a, b, c, [d[0], d[1], z + hair]), orient3d(a, b, c, [d[0], d[1], z - hair]));
            assert!(above != Equal && below != Equal && above != below, "{above:?} {below:?}");
        }
    }
}
