//! The quality report of a seed calibration: the shared 2-D report of [`crate::quality`] plus
//! the heading error that a circle-shaped model leaves where the locus is an ellipse.
//!
//! [`crate::quality::assess_2d`] bounds the error of the calibration *parameters* that noise
//! causes. The merit-circle and turn methods cannot represent a rotated soft iron at all, so
//! part of their residual is not noise but a deterministic two-cycle error. To first order a
//! symmetric soft-iron error `E` gives the radial residual `uᵀE u` and the heading error
//! `u⊥ᵀE u`; their two-cycle parts, `½(e₁₁ − e₂₂) cos 2u + e₁₂ sin 2u` and
//! `−½(e₁₁ − e₂₂) sin 2u + e₁₂ cos 2u`, have the same amplitude. So the amplitude of the
//! two-cycle component of the relative radial residual, fitted by least squares, is the peak
//! heading error (radians) that the calibration leaves uncorrected: it is reported as
//! `heading_error_systematic_deg`. For a calibration that models the ellipse it is close to
//! zero (noise only). The per-reading noise is then estimated from what the two-cycle fit
//! leaves, so the systematic part is not counted as noise.

use nalgebra::{Matrix3, Vector2, Vector3};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::Solution;

use crate::quality::{self, Assessment2d, ReportSums, SupportFigures, assess_2d};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// `solution` with its fitted field reported against `expected` (input unit), as the
/// least-squares fits report theirs: the seed methods take the expected field in their
/// configurations too.
pub(crate) fn with_expected_field<P>(solution: Solution<P>, expected: Option<f64>) -> Solution<P> {
    Solution {
        quality: quality::with_expected_field(solution.quality, expected),
        ..solution
    }
}

/// Amplitude of the two-cycle component of `|cal(p)|/field − 1` over the heading of
/// `cal(p)`: the peak heading error (radians) an unmodelled symmetric soft iron leaves.
/// 0 when fewer than 3 usable points.
#[cfg(test)]
pub(crate) fn two_cycle_amplitude(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
) -> f64 {
    two_cycle_fit(points, cal, field).0
}

/// The two-cycle amplitude (see `two_cycle_amplitude`, its tests' form) and the residual standard
/// deviation left by the fit of `1, cos 2u, sin 2u` (relative to the field; `None` when
/// fewer than 4 usable points or a singular fit).
fn two_cycle_fit(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
) -> (f64, Option<f64>) {
    let mut ata = Matrix3::<f64>::zeros();
    let mut atb = Vector3::<f64>::zeros();
    let mut btb = 0.0;
    let mut n = 0usize;
    for p in points {
        let h = cal.correct(p);
        let rho = h.norm();
        if !(rho > 0.0 && rho.is_finite()) {
            continue;
        }
        let (c, s) = (h.x / rho, h.y / rho);
        let row = Vector3::new(1.0, c * c - s * s, 2.0 * c * s);
        let r = rho / field - 1.0;
        ata += row * row.transpose();
        atb += row * r;
        btb += r * r;
        n += 1;
    }
    if n < 3 {
        return (0.0, None);
    }
    match ata.try_inverse() {
        Some(inv) => {
            let x = inv * atb;
            let a = x.y.hypot(x.z);
            // Residual sum of squares of the linear fit: bᵀb − xᵀAᵀb (normal equations).
            let rss = (btb - x.dot(&atb)).max(0.0);
            let sigma = (n > 3).then(|| (rss / (n - 3) as f64).sqrt());
            let sigma = sigma.filter(|s| s.is_finite());
            (if a.is_finite() { a } else { 0.0 }, sigma)
        }
        None => (0.0, None),
    }
}

/// [`assess_2d`] with the two-cycle term (in degrees) as the systematic heading error, the
/// per-reading noise taken from what the two-cycle fit leaves, and `points` set to the
/// number of samples the calibrator used.
pub(crate) fn seed_assessment(
    points: &[Vector2<f64>],
    cal: &CompassCalibration2d,
    field: f64,
    samples_used: usize,
) -> Assessment2d {
    let a = assess_2d(points, cal, field);
    seed_report(a, two_cycle_fit(points, cal, field), samples_used)
}

/// Most readings a [`SeedJob`] holds (the binned ellipse's most bins).
pub(crate) const SEED_POINTS: usize = 128;

/// Where a [`SeedJob`] stands: each variant holds what the steps before it computed.
#[derive(Debug, Clone, Copy, PartialEq)]
enum SeedStage {
    /// Next: the pass of [`assess_2d`] over the readings.
    Sums,
    /// Next: the two-cycle fit.
    TwoCycle(ReportSums),
    /// Next: the condition number and the dilution of the support's information matrix.
    Condition(ReportSums, (f64, Option<f64>)),
    /// Next: the error bound and the report.
    Report(ReportSums, (f64, Option<f64>), SupportFigures),
    /// Finished.
    Done(Assessment2d),
}

/// [`seed_assessment`] split into [`SeedJob::STEPS`] bounded steps that can run on
/// consecutive pushes: the pass of the shared report over the readings, the two-cycle fit,
/// the support's condition number and dilution, then the error bound and the report. The job holds a copy of its
/// readings, so the caller's may change meanwhile (double buffering); the steps do exactly
/// the arithmetic of the call in one go, in the same order, so the result is the same bit
/// for bit, and replaying a count of steps from [`SeedJob::start`] rebuilds a job exactly.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SeedJob {
    points: [Vector2<f64>; SEED_POINTS],
    len: usize,
    cal: CompassCalibration2d,
    field: f64,
    samples_used: usize,
    steps: usize,
    stage: SeedStage,
}

impl SeedJob {
    /// Steps from [`Self::start`] to the result.
    pub(crate) const STEPS: usize = 4;

    /// The assessment of `cal` on `points` (at most [`SEED_POINTS`]; any beyond are not
    /// used), as [`seed_assessment`] with the same arguments.
    pub(crate) fn start(
        points: &[Vector2<f64>],
        cal: &CompassCalibration2d,
        field: f64,
        samples_used: usize,
    ) -> Self {
        let len = points.len().min(SEED_POINTS);
        let mut buf = [Vector2::zeros(); SEED_POINTS];
        buf[..len].copy_from_slice(&points[..len]);
        Self {
            points: buf,
            len,
            cal: *cal,
            field,
            samples_used,
            steps: 0,
            stage: SeedStage::Sums,
        }
    }

    /// The readings assessed.
    pub(crate) fn points(&self) -> &[Vector2<f64>] {
        &self.points[..self.len]
    }

    /// The calibration assessed.
    pub(crate) fn calibration(&self) -> &CompassCalibration2d {
        &self.cal
    }

    /// The field the residuals are relative to.
    pub(crate) fn field(&self) -> f64 {
        self.field
    }

    /// The sample count the report gives as `points`.
    pub(crate) fn samples_used(&self) -> usize {
        self.samples_used
    }

    /// Steps done so far.
    pub(crate) fn steps(&self) -> usize {
        self.steps
    }

    /// Does the next step; returns the assessment once the job is over (and on every call
    /// after).
    pub(crate) fn step(&mut self) -> Option<Assessment2d> {
        let pts = &self.points[..self.len];
        let next = match self.stage {
            SeedStage::Sums => SeedStage::TwoCycle(Assessment2d::sums(pts, &self.cal, self.field)),
            SeedStage::TwoCycle(s) => {
                SeedStage::Condition(s, two_cycle_fit(pts, &self.cal, self.field))
            }
            SeedStage::Condition(s, fit) => {
                SeedStage::Report(s, fit, Assessment2d::support_figures(&s))
            }
            SeedStage::Report(s, fit, support) => SeedStage::Done(seed_report(
                Assessment2d::from_sums(&s, support, self.field),
                fit,
                self.samples_used,
            )),
            SeedStage::Done(a) => return Some(a),
        };
        self.steps += 1;
        self.stage = next;
        match next {
            SeedStage::Done(a) => Some(a),
            _ => None,
        }
    }
}

/// The shared report `a` with the two-cycle fit's amplitude and noise, and `points` the
/// samples used (the end of [`seed_assessment`]).
fn seed_report(
    mut a: Assessment2d,
    (amplitude, sigma): (f64, Option<f64>),
    samples_used: usize,
) -> Assessment2d {
    a.quality.heading_error_systematic_deg = amplitude.to_degrees();
    if let Some(sigma) = sigma {
        a.quality.heading_noise_rms_deg = sigma.to_degrees();
    }
    a.quality.fit.points = samples_used;
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The staged job gives exactly the assessment of the call in one go, for any
        /// readings and calibration, and a job rebuilt by replaying its steps equals it
        /// at every step.
        #[test]
        fn staged_assessment_equals_the_one_shot(
            pts in proptest::collection::vec((-30.0f64..30.0, -30.0f64..30.0), 0..140),
            hx in -5.0f64..5.0, hy in -5.0f64..5.0,
            s00 in 0.5f64..1.5, s01 in -0.3f64..0.3, s11 in 0.5f64..1.5,
            field in 0.1f64..40.0, samples in 0usize..10_000,
        ) {
            let pts: Vec<_> = pts.iter().map(|&(x, y)| Vector2::new(x, y)).collect();
            let cal = CompassCalibration2d {
                hard_iron: Vector2::new(hx, hy),
                soft_iron: nalgebra::Matrix2::new(s00, s01, s01, s11),
            };
            let used = &pts[..pts.len().min(SEED_POINTS)];
            let expect = seed_assessment(used, &cal, field, samples);
            let mut job = SeedJob::start(&pts, &cal, field, samples);
            let mut got = None;
            for k in 0..SeedJob::STEPS {
                prop_assert!(got.is_none(), "finished early at step {}", k);
                let mut replay = SeedJob::start(&pts, &cal, field, samples);
                for _ in 0..job.steps() {
                    replay.step();
                }
                prop_assert_eq!(format!("{replay:?}"), format!("{job:?}"));
                got = job.step();
            }
            prop_assert_eq!(format!("{:?}", got), format!("{:?}", Some(expect)));
            prop_assert_eq!(format!("{:?}", job.step()), format!("{:?}", Some(expect)));
        }
    }
    use truenorth_compass::{HeadingTruth, MagnetometerModel2d, soft_iron_from_axes};
    use truenorth_core::{SensorModel, angle_diff};

    #[test]
    fn two_cycle_amplitude_is_the_peak_heading_error_of_an_ignored_soft_iron() {
        let m = MagnetometerModel2d::new(
            Vector2::new(4.0, 1.0),
            soft_iron_from_axes(1.1, 1.0, 0.5),
            0.0,
        )
        .unwrap();
        let pts: Vec<_> = (0..360)
            .map(|d| {
                m.ideal(&HeadingTruth {
                    heading_rad: f64::from(d).to_radians(),
                    horizontal_field: 10.0,
                })
                .unwrap()
            })
            .collect();
        // Hard iron right, soft iron ignored.
        let cal = CompassCalibration2d {
            hard_iron: Vector2::new(4.0, 1.0),
            ..CompassCalibration2d::identity()
        };
        let field = crate::quality::mean_corrected_norm_2d(&pts, &cal);
        let amp = two_cycle_amplitude(&pts, &cal, field);
        let peak = (0..360)
            .map(|d| angle_diff(cal.heading_rad(&pts[d]), f64::from(d as u32).to_radians()).abs())
            .fold(0.0, f64::max);
        assert!((amp - peak).abs() < 0.1 * peak, "amp {amp} peak {peak}");
        // With the true calibration there is nothing left.
        let good = m.true_calibration();
        assert!(two_cycle_amplitude(&pts, &good, 10.0) < 1e-9);
    }
}
