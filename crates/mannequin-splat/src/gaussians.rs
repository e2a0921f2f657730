//! The renderer's input: N Gaussians in structure-of-arrays layout, borrowed from the caller so
//! that tensors and files can be rendered without copies.

use crate::SplatError;
use crate::real::Real;
use crate::sh;

/// Orientation of each Gaussian.
#[derive(Clone, Copy, Debug)]
pub enum Rotations<'a, T> {
    /// `[N, 4]` quaternions `(w, x, y, z)`; they are normalised before use, as in 3DGS.
    Quaternions(&'a [T]),
    /// `[N, 3, 3]` row-major matrices whose columns are the Gaussian's axes, used as given
    /// (a mesh-derived frame need not be renormalised).
    Matrices(&'a [T]),
}

/// What each Gaussian contributes to the image.
#[derive(Clone, Copy, Debug)]
pub enum Colors<'a, T> {
    /// `[N, (degree+1)², 3]` spherical-harmonic RGB coefficients, evaluated along the ray from
    /// the camera centre to the mean; colour = max(SH + 0.5, 0) as in 3DGS.
    Sh { degree: usize, coeffs: &'a [T] },
    /// `[N, C]` arbitrary features composited as they are (normals, labels, …).
    Features { channels: usize, values: &'a [T] },
}

/// N Gaussians. All slices are row-major and must agree on N (the length of `opacities`).
#[derive(Clone, Copy, Debug)]
pub struct Gaussians<'a, T> {
    /// `[N, 3]` world-space centres.
    pub means: &'a [T],
    pub rotations: Rotations<'a, T>,
    /// `[N, 3]` standard deviations along the rotation's axes (not log-scales).
    pub scales: &'a [T],
    /// `[N]` opacities in `[0, 1]` (not logits).
    pub opacities: &'a [T],
    pub colors: Colors<'a, T>,
}

impl<T: Real> Gaussians<'_, T> {
    pub fn len(&self) -> usize {
        self.opacities.len()
    }

    pub fn is_empty(&self) -> bool {
        self.opacities.is_empty()
    }

    /// Number of image channels the Gaussians produce.
    pub fn channels(&self) -> usize {
        match self.colors {
            Colors::Sh { .. } => 3,
            Colors::Features { channels, .. } => channels,
        }
    }

    /// Checks array lengths. Per-value domains are checked by [`Gaussians::validate_values`].
    pub fn validate_shapes(&self) -> Result<(), SplatError> {
        let n = self.len();
        let check = |field, found: usize, per: usize| {
            if found == n * per { Ok(()) } else { Err(SplatError::Shape { field, expected: n * per, found }) }
        };
        check("means", self.means.len(), 3)?;
        check("scales", self.scales.len(), 3)?;
        match self.rotations {
            Rotations::Quaternions(q) => check("rotations (quaternions)", q.len(), 4)?,
            Rotations::Matrices(m) => check("rotations (matrices)", m.len(), 9)?,
        }
        match self.colors {
            Colors::Sh { degree, coeffs } => {
                if degree > sh::MAX_DEGREE {
                    return Err(SplatError::Options(format!(
                        "SH degree {degree} is not supported (0 to {})",
                        sh::MAX_DEGREE
                    )));
                }
                check("SH coefficients", coeffs.len(), sh::basis_len(degree) * 3)?
            }
            Colors::Features { channels, values } => {
                if channels == 0 {
                    return Err(SplatError::Options("features need at least one channel".into()));
                }
                check("features", values.len(), channels)?
            }
        }
        Ok(())
    }

    /// Rejects finite values outside their domain: a scale ≤ 0 or an opacity outside `[0, 1]`.
    /// Non-finite values are not errors: the renderer skips those Gaussians and counts them.
    pub fn validate_values(&self) -> Result<(), SplatError> {
        for (i, s) in self.scales.chunks_exact(3).enumerate() {
            if let Some(&v) = s.iter().find(|v| v.is_finite() && **v <= T::ZERO) {
                return Err(SplatError::Domain {
                    field: "scale",
                    index: i,
                    value: v.to_f64(),
                    expected: "scales must be positive standard deviations",
                });
            }
        }
        for (i, &o) in self.opacities.iter().enumerate() {
            if o.is_finite() && !(o >= T::ZERO && o <= T::ONE) {
                return Err(SplatError::Domain {
                    field: "opacity",
                    index: i,
                    value: o.to_f64(),
                    expected: "opacities must lie in [0, 1]",
                });
            }
        }
        Ok(())
    }

    /// Whether every parameter of Gaussian `i` is finite.
    pub(crate) fn is_finite(&self, i: usize) -> bool {
        // v·0 is 0 for finite v and NaN otherwise; one sum checks a whole slice branch-free.
        let all = |s: &[T]| s.iter().fold(T::ZERO, |acc, &v| acc + v * T::ZERO) == T::ZERO;
        let rot = match self.rotations {
            Rotations::Quaternions(q) => &q[4 * i..4 * i + 4],
            Rotations::Matrices(m) => &m[9 * i..9 * i + 9],
        };
        let col = match self.colors {
            Colors::Sh { degree, coeffs } => {
                let k = 3 * sh::basis_len(degree);
                &coeffs[k * i..k * i + k]
            }
            Colors::Features { channels, values } => &values[channels * i..channels * i + channels],
        };
        all(&self.means[3 * i..3 * i + 3])
            && all(&self.scales[3 * i..3 * i + 3])
            && self.opacities[i].is_finite()
            && all(rot)
            && all(col)
    }
}

/// Gradients of a loss with respect to every input of [`Gaussians`], in the same layouts.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GaussianGrads<T> {
    pub means: Vec<T>,
    /// Per quaternion `(w, x, y, z)` or per matrix entry, matching the input form.
    pub rotations: Vec<T>,
    pub scales: Vec<T>,
    pub opacities: Vec<T>,
    /// SH coefficients or features, matching the input form.
    pub colors: Vec<T>,
}
