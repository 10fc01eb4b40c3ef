//! Data normalisation before a fit: move the centroid to the origin and scale so that the
//! RMS distance from it is 1.
//!
//! Why: an algebraic conic fit minimises a sum of polynomial values whose terms have
//! different degrees, so its answer depends on where the origin is and on the unit. Fitting
//! in coordinates fixed by the data themselves (centroid, RMS radius — both commute with
//! rotations, translations and scalings of the input) makes the whole fit equivariant under
//! those transformations, and keeps the scatter matrix well conditioned whatever unit the
//! magnetometer reports in (Hartley 1997, "In defense of the eight-point algorithm", makes
//! the same argument for the fundamental matrix).

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

use nalgebra::SVector;
use truenorth_core::{Error, Result, check_finite};

use crate::numerics::readings::{Readings, replay_points};
use crate::numerics::segments::{RunFold, fold};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// `q = (p − centre) / scale`, with the centroid as centre and the RMS distance as scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Normaliser<const D: usize> {
    pub centre: SVector<f64, D>,
    pub scale: f64,
}

impl<const D: usize> Normaliser<D> {
    /// The normaliser of `points` (all finite, non-empty). Refuses points that are all equal
    /// and coordinates too large to square in `f64`.
    #[cfg(test)]
    pub fn of(points: &[SVector<f64, D>]) -> Result<Self> {
        Self::of_finite(points, "point")
    }

    /// The normaliser of `points` (non-empty), refusing with [`Error::NonFinite`] naming
    /// `what` the first non-finite coordinate, exactly as checking every point with
    /// `check_finite` before `Self::of` (its tests' form) would. The check rides on the centroid's sum, which
    /// is finite when every point is: only a non-finite sum needs the points looked at one
    /// by one (they are then either not all finite, or so large that the sum overflowed).
    /// An error replaying `points` is returned as it is.
    pub fn of_finite<R: Readings<D> + ?Sized>(points: &R, what: &'static str) -> Result<Self> {
        Self::of_readings(points, what)?
    }

    /// [`Self::of_finite`] with the two kinds of error apart: the outer one replaying
    /// `points`, the inner one the refusal of the points themselves.
    pub fn of_readings<R: Readings<D> + ?Sized>(
        points: &R,
        what: &'static str,
    ) -> Result<Result<Self>> {
        if points.is_empty() {
            return Ok(Err(Error::TooFewPoints { got: 0, need: 1 }));
        }
        let n = points.len() as f64;
        let sum = lane_sum(points, |p| *p)?;
        if !sum.iter().all(|x| x.is_finite()) {
            let mut bad: Result<f64> = Ok(0.0);
            replay_points(points, |p| {
                for &x in p.iter() {
                    if bad.is_ok() {
                        bad = check_finite(what, x);
                    }
                }
            })?;
            if let Err(e) = bad {
                return Ok(Err(e));
            }
        }
        let mut centre = sum / n;
        if !centre.iter().all(|x| x.is_finite()) {
            // The plain sum overflowed; the running mean does not.
            centre = SVector::zeros();
            let mut k = 0.0;
            replay_points(points, |p| {
                k += 1.0;
                centre += (p - centre) / k;
            })?;
        }
        let ss = lane_sum(points, |p| {
            SVector::<f64, 1>::new((p - centre).norm_squared())
        })?[0];
        let scale = (ss / n).sqrt();
        if !(scale.is_finite() && centre.iter().all(|x| x.is_finite())) {
            return Ok(Err(Error::Degenerate {
                reason: "the readings are too large to fit in double precision; rescale them (e.g. to µT or gauss) first",
            }));
        }
        if !(scale > 0.0) || scale <= f64::EPSILON * centre.amax() {
            return Ok(Err(Error::Degenerate {
                reason: "all readings are equal; the sensor must turn so the field direction changes",
            }));
        }
        Ok(Ok(Self { centre, scale }))
    }

    /// A point in normalised coordinates.
    #[inline]
    pub fn apply(&self, p: &SVector<f64, D>) -> SVector<f64, D> {
        (p - self.centre) / self.scale
    }
}

/// `Σ f(p)` over `points` in four interleaved partial sums added pairwise at the end: one
/// running sum is a chain of dependent additions (several cycles each), four are not, and
/// the result differs by rounding error only (Higham 2002, *Accuracy and Stability of
/// Numerical Algorithms*, §4.2). The partial sums carry over from one run of the replay to
/// the next, whose lengths are multiples of four (see [`Readings::replay`]), so a point goes
/// to the same partial sum however the readings are cut into runs; segment by segment (see
/// `fold`), whose partial sums merge lane by lane.
#[inline]
fn lane_sum<const D: usize, const E: usize, R: Readings<D> + ?Sized>(
    points: &R,
    f: impl Fn(&SVector<f64, D>) -> SVector<f64, E> + Sync,
) -> Result<SVector<f64, E>> {
    let s = fold(
        points,
        &RunFold {
            start: || [SVector::<f64, E>::zeros(); 4],
            add: |s: &mut [SVector<f64, E>; 4], run: &[SVector<f64, D>]| {
                let mut chunks = run.chunks_exact(4);
                for c in &mut chunks {
                    for (sl, p) in s.iter_mut().zip(c) {
                        *sl += f(p);
                    }
                }
                for (sl, p) in s.iter_mut().zip(chunks.remainder()) {
                    *sl += f(p);
                }
            },
            merge: |s: &mut [SVector<f64, E>; 4], later: [SVector<f64, E>; 4]| {
                for (a, b) in s.iter_mut().zip(later) {
                    *a += b;
                }
            },
        },
    )?;
    Ok((s[0] + s[2]) + (s[1] + s[3]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn unit_rms_and_zero_mean() {
        let pts = [
            Vector2::new(1.0, 2.0),
            Vector2::new(3.0, 2.0),
            Vector2::new(2.0, 5.0),
        ];
        let n = Normaliser::of(&pts).unwrap();
        let q: Vec<_> = pts.iter().map(|p| n.apply(p)).collect();
        let mean = q.iter().sum::<Vector2<f64>>() / 3.0;
        let rms = (q.iter().map(|v| v.norm_squared()).sum::<f64>() / 3.0).sqrt();
        assert!(mean.norm() < 1e-15);
        assert!((rms - 1.0).abs() < 1e-15);
    }

    #[test]
    fn refuses_equal_and_huge() {
        let eq = [Vector2::new(7.0, 7.0); 5];
        assert!(matches!(Normaliser::of(&eq), Err(Error::Degenerate { .. })));
        let huge = [Vector2::new(1e300, 0.0), Vector2::new(-1e300, 0.0)];
        assert!(matches!(
            Normaliser::of(&huge),
            Err(Error::Degenerate { .. })
        ));
    }
}
