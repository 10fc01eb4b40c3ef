//! A verdict on a calibration's quality report: `good`, `usable` or `poor`, with the reason.
//!
//! It reads two numbers of the report, each in degrees of heading so that one scale judges
//! both:
//! * the bound on the error the calibration itself adds
//!   ([`CompassQuality::heading_error_bound_deg`](crate::CompassQuality::heading_error_bound_deg): 3σ of the parameter uncertainty plus the
//!   method's systematic error), which every later heading carries;
//! * the per-reading heading noise ([`CompassQuality::heading_noise_rms_deg`](crate::CompassQuality::heading_noise_rms_deg)), which is the
//!   residual of the fit in angle: large for a noisy sensor, or when the readings do not lie
//!   on the fitted circle or ellipsoid (a disturbed site, a sensor that moved against its
//!   mount, the wrong model).
//!
//! The two are kept apart, and the verdict says which one decided it ([`Cause`]): a noisy
//! sensor calibrated from many readings has a small bound (the noise averages out of the
//! parameters) and a large per-reading scatter, and is `usable` or `poor` *because it is
//! noisy* — a better recording would not help, averaging its readings would.
//!
//! `good`: both within [`GOOD_DEG`] (bound) and [`GOOD_NOISE_DEG`] (noise); `usable`: within
//! [`USABLE_DEG`]; `poor`: beyond — a heading that can be off by more than that is not worth
//! writing down, and the command line refuses it unless asked. The limits are judgements: 1°
//! is what a good hand bearing compass reads to, 5° the accuracy class of the vehicle
//! compasses in the seed patents.

// `!(x <= limit)` and `!(x > 0.0)` are deliberate: they are true for NaN, so a NaN fails
// every check instead of slipping through one.
#![expect(clippy::neg_cmp_op_on_partial_ord)]

use core::fmt;

use crate::Fixed;
use serde::{Deserialize, Serialize};

/// Largest calibration bound of a `good` calibration, degrees.
pub const GOOD_DEG: f64 = 1.0;

/// Largest per-reading heading noise of a `good` calibration, degrees (readings are
/// usually averaged, so twice [`GOOD_DEG`]).
pub const GOOD_NOISE_DEG: f64 = 2.0;

/// Largest calibration bound and per-reading noise of a `usable` calibration, degrees.
pub const USABLE_DEG: f64 = 5.0;

/// How far to trust a calibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Grade {
    /// Within [`GOOD_DEG`] and [`GOOD_NOISE_DEG`].
    Good,
    /// Within [`USABLE_DEG`].
    Usable,
    /// Beyond [`USABLE_DEG`]: not worth using.
    Poor,
}

impl fmt::Display for Grade {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Good => "good",
            Self::Usable => "usable",
            Self::Poor => "poor",
        })
    }
}

/// Which of the two numbers kept a calibration from a better grade.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Cause {
    /// Nothing: the calibration is `good`.
    None,
    /// The calibration's own bound (3σ plus systematic): too few readings, too little of
    /// the circle or sphere, or a method that cannot model the soft iron. A better
    /// recording fixes it.
    Calibration,
    /// The per-reading noise only: the calibration itself is within the grade's bound, but
    /// each reading scatters more than the grade allows. Recalibrating does not fix it;
    /// averaging readings does (or, when the scatter is not random, removing what causes
    /// it).
    Noise,
}

impl fmt::Display for Cause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::None => "none",
            Self::Calibration => "calibration",
            Self::Noise => "noise",
        })
    }
}

/// A grade, the numbers behind it and which of them decided it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Verdict {
    /// The grade.
    pub grade: Grade,
    /// What kept it from a better grade.
    pub cause: Cause,
    /// The calibration bound, degrees (3σ plus systematic).
    #[serde(with = "crate::extended_float::scalar")]
    pub bound_deg: f64,
    /// The per-reading heading noise, degrees.
    #[serde(with = "crate::extended_float::scalar")]
    pub noise_deg: f64,
}

impl Verdict {
    /// The verdict on a heading-error bound and a per-reading noise, both in degrees (a
    /// report's: [`Verdict::of`]).
    pub fn from_figures(bound_deg: f64, noise_deg: f64) -> Self {
        // Written so that NaN is poor.
        let grade = if bound_deg <= GOOD_DEG && noise_deg <= GOOD_NOISE_DEG {
            Grade::Good
        } else if bound_deg <= USABLE_DEG && noise_deg <= USABLE_DEG {
            Grade::Usable
        } else {
            Grade::Poor
        };
        let (bound_limit, _) = Self::limits_missed(grade);
        let cause = if grade == Grade::Good {
            Cause::None
        } else if !(bound_deg <= bound_limit) {
            Cause::Calibration
        } else {
            Cause::Noise
        };
        Self {
            grade,
            cause,
            bound_deg,
            noise_deg,
        }
    }

    /// The bound and noise limits of the grade above `grade`, which it missed.
    fn limits_missed(grade: Grade) -> (f64, f64) {
        match grade {
            Grade::Good | Grade::Usable => (GOOD_DEG, GOOD_NOISE_DEG),
            Grade::Poor => (USABLE_DEG, USABLE_DEG),
        }
    }
}

impl fmt::Display for Verdict {
    /// The reason, one line: which number decided the grade, and what would help.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (b, n) = (Fixed(self.bound_deg, 2), Fixed(self.noise_deg, 2));
        let (limit, noise_limit) = Self::limits_missed(self.grade);
        match self.cause {
            Cause::None => write!(
                f,
                "the calibration adds at most {b} deg (3 sigma + systematic, limit {GOOD_DEG}) and each reading scatters {n} deg RMS about it (limit {GOOD_NOISE_DEG})"
            ),
            Cause::Calibration => {
                write!(
                    f,
                    "the calibration itself may err by up to {b} deg (3 sigma + systematic), more than {limit} deg: too few readings, too little of the circle or sphere, or a method that cannot model this soft iron"
                )?;
                if !(self.noise_deg <= noise_limit) {
                    write!(
                        f,
                        "; and each reading scatters {n} deg RMS about the fit, more than {noise_limit} deg"
                    )?;
                }
                Ok(())
            }
            Cause::Noise => write!(
                f,
                "the sensor is noisy: each reading scatters {n} deg RMS about the fit ({} % of the field), more than {noise_limit} deg, while the calibration itself is determined to {b} deg (3 sigma + systematic); average readings (their noise falls as 1/sqrt of their number) — a scatter that is not random means the readings do not lie on one circle or ellipsoid (a magnetically disturbed site, a sensor moving against its mount, or a tilted 2-axis compass)",
                Fixed(100.0 * self.noise_deg.to_radians(), 1)
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CompassQuality;
    extern crate alloc;
    use alloc::string::ToString;
    use proptest::prelude::*;

    fn report(bound: f64, noise: f64) -> CompassQuality {
        CompassQuality {
            heading_error_3sigma_deg: bound,
            heading_noise_rms_deg: noise,
            ..CompassQuality::default()
        }
    }

    #[test]
    fn a_useless_merit_circle_fit_is_poor() {
        // A real recording under the merit circle: 73 % residual, 42.9° bound.
        let v = Verdict::of(&report(42.9, 41.8));
        assert_eq!(v.grade, Grade::Poor);
        assert!(v.to_string().contains("42.90 deg"), "{v}");
        let v = Verdict::of(&report(0.5, 8.0));
        assert_eq!((v.grade, v.cause), (Grade::Poor, Cause::Noise));
        assert!(v.to_string().contains("scatters 8.00 deg"), "{v}");
        assert!(v.to_string().contains("the sensor is noisy"), "{v}");
        assert!(v.to_string().contains("determined to 0.50 deg"), "{v}");
        // A sensor with 6 % noise, calibrated from thousands of readings: usable, for noise.
        let v = Verdict::of(&report(0.3, 0.06f64.to_degrees()));
        assert_eq!((v.grade, v.cause), (Grade::Usable, Cause::Noise));
        assert!(v.to_string().contains("(6.0 % of the field)"), "{v}");
        let v = Verdict::of(&report(2.0, 8.0));
        assert_eq!((v.grade, v.cause), (Grade::Poor, Cause::Noise));
        let v = Verdict::of(&report(7.0, 8.0));
        assert_eq!((v.grade, v.cause), (Grade::Poor, Cause::Calibration));
        assert!(
            v.to_string().contains("and each reading scatters 8.00"),
            "{v}"
        );
        assert_eq!(Verdict::of(&report(0.04, 0.26)).grade, Grade::Good);
        assert_eq!(Verdict::of(&report(2.0, 0.3)).grade, Grade::Usable);
        assert_eq!(Verdict::of(&report(f64::NAN, 0.3)).grade, Grade::Poor);
        assert_eq!(Verdict::of(&report(f64::INFINITY, 0.3)).grade, Grade::Poor);
    }

    /// A hostile figure in either place still gives one short line, with no long run of
    /// digits and a NaN named as not finite.
    #[test]
    fn hostile_figures_read_short() {
        let specials = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            -f64::MAX,
            1e200,
            5e-324,
        ];
        for b in specials {
            for n in specials.iter().copied().chain([0.1, 8.0]) {
                let text = Verdict::of(&report(b, n)).to_string();
                assert!(text.len() <= 600, "{text}");
                let run = text
                    .split(|c: char| !c.is_ascii_digit())
                    .map(str::len)
                    .max();
                assert!(run.unwrap_or(0) <= 20, "{text}");
            }
        }
        let v = Verdict::of(&report(f64::NAN, 0.3)).to_string();
        assert!(v.contains("up to not finite (NaN) deg"), "{v}");
    }

    proptest! {
        /// Any pair of figures gives a short line without a long run of digits.
        #[test]
        fn any_figures_read_short(b in any::<f64>(), n in any::<f64>()) {
            let text = Verdict::of(&report(b, n)).to_string();
            prop_assert!(text.len() <= 600, "{}", text);
            let run = text.split(|c: char| !c.is_ascii_digit()).map(str::len).max();
            prop_assert!(run.unwrap_or(0) <= 20, "{}", text);
        }

        /// The grade never improves as either number grows, the reason is one line, and the
        /// cause is the number that misses the better grade's limit: the noise only when the
        /// bound meets it.
        #[test]
        fn grades_are_monotone(b in 0.0f64..20.0, n in 0.0f64..20.0, db in 0.0f64..5.0, dn in 0.0f64..5.0) {
            let a = Verdict::of(&report(b, n));
            let worse = Verdict::of(&report(b + db, n + dn));
            prop_assert!(worse.grade >= a.grade);
            prop_assert!(!a.to_string().contains('\n'));
            let (bound_limit, noise_limit) = match a.grade {
                Grade::Good => (f64::INFINITY, f64::INFINITY),
                Grade::Usable => (GOOD_DEG, GOOD_NOISE_DEG),
                Grade::Poor => (USABLE_DEG, USABLE_DEG),
            };
            let expect = match a.grade {
                Grade::Good => Cause::None,
                _ if b > bound_limit => Cause::Calibration,
                _ => Cause::Noise,
            };
            prop_assert_eq!(a.cause, expect);
            if a.cause == Cause::Noise {
                prop_assert!(n > noise_limit && b <= bound_limit);
            }
        }
    }
}
