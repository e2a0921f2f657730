//! The scalar type the CPU renderer is generic over: `f32` for speed, `f64` for the
//! finite-difference checks of the backward pass.

use std::fmt::Debug;
use std::iter::Sum;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A floating-point scalar with the few operations the renderer needs.
pub trait Real:
    Copy
    + Debug
    + Default
    + PartialOrd
    + Send
    + Sync
    + Sum
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + 'static
{
    const ZERO: Self;
    const ONE: Self;
    fn from_f64(v: f64) -> Self;
    fn to_f64(self) -> f64;
    fn sqrt(self) -> Self;
    fn ln(self) -> Self;
    fn abs(self) -> Self;
    fn max(self, other: Self) -> Self;
    fn min(self, other: Self) -> Self;
    fn is_finite(self) -> bool;
    /// `exp(x)` in a form the compiler can vectorise. The input is clamped at −60 so that the
    /// result never becomes a denormal (denormals make the compositing loops 4–7× slower).
    fn exp_clamped(self) -> Self;
    /// The bit pattern as an integer that orders like the value, for sorting positive depths.
    fn order_key(self) -> u64;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        f32::ln(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if self > other { self } else { other }
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        if self < other { self } else { other }
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn exp_clamped(self) -> Self {
        exp_f32(self)
    }
    #[inline(always)]
    fn order_key(self) -> u64 {
        total_order_bits_f32(self) as u64
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        f64::ln(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if self > other { self } else { other }
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        if self < other { self } else { other }
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline(always)]
    fn exp_clamped(self) -> Self {
        f64::exp(self.max(-60.0))
    }
    #[inline(always)]
    fn order_key(self) -> u64 {
        let bits = self.to_bits();
        if bits >> 63 == 1 { !bits } else { bits | (1 << 63) }
    }
}

/// Maps an `f32` to a `u32` with the same order (negative values flipped), so depths sort as
/// integers.
fn total_order_bits_f32(v: f32) -> u32 {
    let bits = v.to_bits();
    if bits >> 31 == 1 { !bits } else { bits | (1 << 31) }
}

/// `exp(x)` for `f32` by range reduction `x = n ln 2 + r` and a degree-6 polynomial on
/// `|r| ≤ ln 2 / 2` (the Cephes `expf` coefficients, about 1 ulp). Branch-free and free of
/// float→int casts (Rust's saturating `as` does not vectorise), so a loop over lanes compiles
/// to vector code: `n` is rounded, and its bits extracted, by adding 1.5·2²³.
#[inline(always)]
fn exp_f32(x: f32) -> f32 {
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    const SHIFTER: f32 = 12_582_912.0;
    let x = x.clamp(-60.0, 80.0);
    let shifted = x * LOG2E + SHIFTER;
    let n = shifted - SHIFTER;
    let r = x - n * LN2_HI - n * LN2_LO;
    // The Cephes polynomial in Estrin's scheme (a shorter dependency chain than Horner's).
    let r2 = r * r;
    let p01 = 0.5 + 1.666_666_5e-1 * r;
    let p23 = 4.166_579_6e-2 + 8.333_452e-3 * r;
    let p45 = 1.398_199_9e-3 + 1.987_569_1e-4 * r;
    let p = p01 + r2 * (p23 + r2 * p45);
    let y = p * r2 + r + 1.0;
    // The low mantissa bits of `shifted` hold n; move n + 127 into the exponent field.
    let n_bits = shifted.to_bits().wrapping_sub(SHIFTER.to_bits());
    y * f32::from_bits(n_bits.wrapping_add(127) << 23)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_f32_matches_std_to_a_few_ulp() {
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let x = -60.0 + 70.0 * i as f64 / 200_000.0;
            let got = exp_f32(x as f32) as f64;
            let want = (x as f32 as f64).exp();
            worst = worst.max(((got - want) / want).abs());
        }
        assert!(worst < 4.0 * f32::EPSILON as f64, "worst relative error {worst}");
    }

    #[test]
    fn exp_is_clamped_above_denormals() {
        assert!(exp_f32(-1000.0) >= f32::MIN_POSITIVE);
        assert!(<f64 as Real>::exp_clamped(-1000.0) >= f64::MIN_POSITIVE);
    }

    #[test]
    fn order_keys_sort_like_values() {
        let vals = [-3.5f32, -0.0, 0.0, 1e-30, 0.5, 2.0, 1e30];
        for w in vals.windows(2) {
            assert!(w[0].order_key() <= w[1].order_key(), "{w:?}");
            assert!((w[0] as f64).order_key() <= (w[1] as f64).order_key(), "{w:?}");
        }
    }
}
