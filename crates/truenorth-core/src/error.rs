//! The workspace error type. Each variant says what was wrong and what to do about it, so that
//! a calibration that cannot be trusted is refused with a reason instead of returned silently.

use crate::{Fixed, Precise, Readable};
use thiserror::Error;

/// "by up to X°" for an angle that a first-order figure can give, "by any angle" beyond half
/// a turn (where a first-order figure no longer means anything).
struct UpTo(f64);

impl core::fmt::Display for UpTo {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if self.0 <= 180.0 {
            write!(f, "by up to {}°", Fixed(self.0, 1))
        } else {
            f.write_str("by any angle (the first-order figure exceeds 180°)")
        }
    }
}

/// ", X° net of the noise of the readings at its ends (Y°)" for a span `X + Y` of which the
/// noise may account for `Y`; nothing when `Y` is 0.
struct NetOfNoise(f64, f64);

impl core::fmt::Display for NetOfNoise {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if self.1 > 0.0 {
            write!(
                f,
                ", {}° once the noise of the readings at its two ends ({}°) is allowed for",
                Fixed((self.0 - self.1).max(0.0), 0),
                Fixed(self.1, 0)
            )
        } else {
            Ok(())
        }
    }
}

/// Everything that can go wrong in truenorth's library code.
///
/// Library code never panics on bad input; it returns one of these.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A value that must be finite was NaN or infinite.
    #[error("{what} is not finite ({}); every input value must be a finite number", Precise(*value))]
    NonFinite {
        /// Which quantity.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A timestamp did not increase.
    #[error(
        "timestamp {} s does not come after the previous one ({} s); sort samples by time and drop duplicates",
        Precise(*t_s),
        Precise(*prev_s)
    )]
    NonIncreasingTime {
        /// Previous accepted timestamp, seconds.
        prev_s: f64,
        /// The rejected timestamp, seconds.
        t_s: f64,
    },
    /// A time step that is zero, negative or not finite.
    #[error("time step dt = {} s is not a positive finite number", Precise(*dt_s))]
    InvalidDt {
        /// The rejected time step, seconds.
        dt_s: f64,
    },
    /// A parameter or input outside its valid range.
    #[error(
        "{what} = {} is outside its valid range [{}, {}]",
        Readable(*value),
        Readable(*min),
        Readable(*max)
    )]
    OutOfRange {
        /// Which quantity.
        what: &'static str,
        /// The offending value.
        value: f64,
        /// Smallest valid value.
        min: f64,
        /// Largest valid value.
        max: f64,
    },
    /// The data contradict the units they declare (a time base in milliseconds read as
    /// seconds, a field in nT declared as µT, …): what they say cannot come from real motion.
    #[error(
        "the data contradict their declared units: {what} is {}, where real motion gives {}–{}; {hint}",
        Readable(*value),
        Readable(*min),
        Readable(*max)
    )]
    Implausible {
        /// Which quantity, with its declared unit.
        what: &'static str,
        /// The offending value, in the declared unit.
        value: f64,
        /// Smallest value real motion gives.
        min: f64,
        /// Largest value real motion gives.
        max: f64,
        /// What the data probably are and what to do.
        hint: &'static str,
    },
    /// Not enough samples to do what was asked.
    #[error("too few points: got {got}, need at least {need}; record more data before solving")]
    TooFewPoints {
        /// Samples available.
        got: usize,
        /// Samples required.
        need: usize,
    },
    /// The readings fill too few of a binned calibrator's direction bins: a count of the
    /// headings seen, not of the readings, so more readings at the same headings do not help.
    #[error(
        "the readings fill only {filled} of the {bins} direction bins, need at least {need}; turn through more headings (a full circle is best) before solving"
    )]
    TooFewBins {
        /// Direction bins holding a reading.
        filled: usize,
        /// Direction bins required.
        need: usize,
        /// Direction bins in all (each covers `360° / bins` of direction).
        bins: usize,
    },
    /// The samples cover too little of a turn to determine a calibration.
    #[error(
        "the samples cover only {}° of heading{}, need at least {}°; turn further (a full circle is best) before solving",
        Fixed(*covered_deg, 0),
        NetOfNoise(*covered_deg, *noise_deg),
        Fixed(*need_deg, 0)
    )]
    InsufficientCoverage {
        /// Heading span covered, degrees: between the outermost readings.
        covered_deg: f64,
        /// What the readings' noise may add to that span at its two ends, degrees, and is
        /// taken off it before it is compared with `need_deg` (0 where a calibrator does not
        /// know the noise).
        noise_deg: f64,
        /// Heading span required, degrees.
        need_deg: f64,
    },
    /// The orientations seen cover too little of the sphere to determine a 3-D calibration.
    #[error(
        "the orientations fill only {} % of the sphere's direction cells, need at least {} %; tumble the sensor through more orientations (turns about three axes)",
        Fixed(100.0 * covered_fraction, 0),
        Fixed(100.0 * need_fraction, 0)
    )]
    InsufficientSphereCoverage {
        /// Share of direction cells with data, in [0, 1].
        covered_fraction: f64,
        /// Share required, in [0, 1].
        need_fraction: f64,
    },
    /// A turn-based method saw less than one full revolution.
    #[error(
        "the turn covered only {}°, need at least {}°; drive a complete circle",
        Fixed(*turned_deg, 0),
        Fixed(*need_deg, 0)
    )]
    IncompleteTurn {
        /// Heading change seen, degrees.
        turned_deg: f64,
        /// Heading change required, degrees.
        need_deg: f64,
    },
    /// The geometry does not determine the answer (collinear points, all samples equal, a
    /// singular matrix, an extremum at the edge of the record, …).
    #[error("degenerate geometry: {reason}")]
    Degenerate {
        /// What was degenerate and what to do.
        reason: &'static str,
    },
    /// The orientations seen do not determine a calibration, however many readings were
    /// taken in them: a geometric property of the directions, not of their number or noise.
    #[error(
        "the orientations seen do not determine the calibration: their dilution is {} (an evenly covered {even_shape} has {}), so an error of {} % of the field per reading could turn the result {}, more than the {}° accepted; more readings in the same orientations will not help: {hint}",
        Fixed(*dilution, 1),
        Fixed(*even_dilution, 1),
        Fixed(100.0 * model_error_rel, 1),
        UpTo(*error_deg),
        Precise(*max_deg)
    )]
    Undetermined {
        /// The dilution of the directions seen, each direction counted once (infinite when
        /// they do not determine the calibration at all).
        dilution: f64,
        /// The dilution of an evenly covered circle (2-D) or sphere (3-D).
        even_dilution: f64,
        /// `"circle"` or `"sphere"`.
        even_shape: &'static str,
        /// The per-reading error, relative to the field, the test assumes.
        model_error_rel: f64,
        /// `dilution × model_error_rel`, degrees: the error that per-reading error could
        /// cause.
        error_deg: f64,
        /// The largest error accepted, degrees.
        max_deg: f64,
        /// What to record instead.
        hint: &'static str,
    },
    /// The readings are too noisy for the orientations they were taken in: the fit is
    /// outside the range where its own error figures hold.
    #[error(
        "each reading scatters {} % of the field about the fit and the orientations' dilution is {}: their product, {}, exceeds the {} within which a least-squares calibration's error figures hold (beyond it the fit can drift along what the orientations leave loose, and more readings do not stop it); record orientations that determine the calibration better (a fuller tumble: an evenly covered sphere has a dilution of 3.7) or use a quieter sensor",
        Fixed(100.0 * noise_rel, 1),
        Fixed(*dilution, 1),
        Fixed(*product, 2),
        Precise(*max_product)
    )]
    TooNoisyForOrientations {
        /// Per-reading noise, relative to the field.
        noise_rel: f64,
        /// The orientations' dilution.
        dilution: f64,
        /// `noise_rel × dilution`.
        product: f64,
        /// The largest product accepted.
        max_product: f64,
    },
    /// The calibration's own uncertainty is too large for the readings' noise and number.
    #[error(
        "the calibration itself could err by up to {}° (3 sigma{widened}), more than the {}° accepted: {points} readings with a noise of {} % of the field each are too few for the orientations they cover; the error falls as 1/sqrt(readings), so record more readings, or turn (tumble) through more orientations",
        Fixed(*bound_deg, 2),
        Precise(*max_deg),
        Fixed(100.0 * noise_rel, 2)
    )]
    TooUncertain {
        /// The 3σ heading-error bound the refusal judged, degrees.
        bound_deg: f64,
        /// The largest bound accepted, degrees.
        max_deg: f64,
        /// Readings behind the fit.
        points: usize,
        /// Per-reading noise, relative to the field (the fit's residual standard deviation).
        noise_rel: f64,
        /// `""`, or how the bound was widened for a σ estimated from few residuals.
        widened: &'static str,
    },
    /// Two consecutive samples are further apart in time than a method can bridge.
    #[error(
        "the record has a gap of {} s before t = {} s, longer than the {} s that {what} can bridge; split the record at the gap and calibrate each part on its own (or start the calibrator again from this sample)",
        Precise(*gap_s),
        Precise(*t_s),
        Precise(*max_gap_s)
    )]
    TimeGap {
        /// What cannot bridge it (e.g. "the gyro's integrated heading").
        what: &'static str,
        /// Timestamp of the sample after the gap, seconds.
        t_s: f64,
        /// The gap, seconds.
        gap_s: f64,
        /// The longest gap accepted, seconds.
        max_gap_s: f64,
    },
    /// A conic fit returned something that is not an ellipse (or ellipsoid).
    #[error(
        "the best-fitting conic is not an ellipse{detail}; the data are probably not a rotation in a constant field"
    )]
    NotAnEllipse {
        /// Extra detail, may be empty.
        detail: &'static str,
    },
    /// A date outside the validity of a geomagnetic model.
    #[error(
        "date {} is outside the model's validity {}–{}; use a model for that epoch or opt in to extrapolation",
        Precise(*year),
        Precise(*valid_from),
        Precise(*valid_to)
    )]
    DateOutOfRange {
        /// Requested decimal year.
        year: f64,
        /// First valid decimal year.
        valid_from: f64,
        /// Last valid decimal year.
        valid_to: f64,
    },
    /// An iterative solver did not converge.
    #[error("{what} did not converge after {iterations} iterations")]
    NoConvergence {
        /// Which solver.
        what: &'static str,
        /// Iterations run.
        iterations: usize,
    },
    /// An operation needs data that was never supplied (e.g. solving before any push).
    #[error("{what} is not available yet: {hint}")]
    NotReady {
        /// What is missing.
        what: &'static str,
        /// What to do.
        hint: &'static str,
    },
    /// A saved state was written by another layout version.
    #[error(
        "the snapshot has layout version {found}, this build reads version {expected}; recalibrate or restore with the version that wrote it"
    )]
    SnapshotVersion {
        /// Version found in the snapshot.
        found: u32,
        /// Version this build reads.
        expected: u32,
    },
    /// A saved state or stored parameter set is internally inconsistent.
    #[error("invalid saved state: {reason}")]
    InvalidSnapshot {
        /// What was wrong.
        reason: &'static str,
    },
    /// The operation needs something this sensor or method does not have (e.g. tilt
    /// compensation with a two-axis compass).
    #[error("not supported: {reason}")]
    Unsupported {
        /// What is missing and what to use instead.
        reason: &'static str,
    },
    /// The store that keeps a batch fit's readings (one that holds them outside memory, in a
    /// file) could not keep them or give them back: a failure beneath the calibrator, not a
    /// fault of the data.
    #[error("the readings could not be kept or read back: {reason}")]
    ReadingsUnavailable {
        /// Where the readings were kept and what to do.
        reason: &'static str,
    },
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use proptest::prelude::*;
    use std::string::ToString;

    /// Timestamps and gaps keep every digit at everyday magnitudes and go to exponent form
    /// beyond them.
    #[test]
    fn precise_numbers_are_exact_and_short() {
        assert_eq!(
            Precise(17664.399999999998).to_string(),
            "17664.399999999998"
        );
        assert_eq!(Precise(1e308).to_string(), "1e308");
        assert_eq!(Precise(-5e-324).to_string(), "-5e-324");
        assert_eq!(Precise(0.01).to_string(), "0.01");
        let e = Error::NonIncreasingTime {
            prev_s: 1e308,
            t_s: 1.5,
        };
        assert!(e.to_string().len() < 120, "{e}");
        let e = Error::TimeGap {
            what: "w",
            t_s: 1e308,
            gap_s: 1e308,
            max_gap_s: 2.0,
        };
        assert!(e.to_string().len() < 250, "{e}");
    }

    /// The longest run of consecutive digits in `s`.
    fn longest_digit_run(s: &str) -> usize {
        s.split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max()
            .unwrap_or(0)
    }

    /// Every variant that carries a float, built from the figures `v`.
    fn with_figures(v: [f64; 6]) -> std::vec::Vec<Error> {
        std::vec![
            Error::NonFinite {
                what: "x",
                value: v[0]
            },
            Error::NonIncreasingTime {
                prev_s: v[0],
                t_s: v[1]
            },
            Error::InvalidDt { dt_s: v[0] },
            Error::OutOfRange {
                what: "x",
                value: v[0],
                min: v[1],
                max: v[2]
            },
            Error::Implausible {
                what: "x",
                value: v[0],
                min: v[1],
                max: v[2],
                hint: "h"
            },
            Error::InsufficientCoverage {
                covered_deg: v[0],
                noise_deg: v[1],
                need_deg: v[2]
            },
            Error::InsufficientSphereCoverage {
                covered_fraction: v[0],
                need_fraction: v[1]
            },
            Error::IncompleteTurn {
                turned_deg: v[0],
                need_deg: v[1]
            },
            Error::Undetermined {
                dilution: v[0],
                even_dilution: v[1],
                even_shape: "sphere",
                model_error_rel: v[2],
                error_deg: v[3],
                max_deg: v[4],
                hint: "h",
            },
            Error::TooNoisyForOrientations {
                noise_rel: v[0],
                dilution: v[1],
                product: v[2],
                max_product: v[3],
            },
            Error::TooUncertain {
                bound_deg: v[0],
                max_deg: v[1],
                points: usize::MAX,
                noise_rel: v[2],
                widened: "",
            },
            Error::TimeGap {
                what: "w",
                t_s: v[0],
                gap_s: v[1],
                max_gap_s: v[2]
            },
            Error::DateOutOfRange {
                year: v[0],
                valid_from: v[1],
                valid_to: v[2]
            },
        ]
    }

    /// The figures a hostile input can put into a message.
    fn any_figure() -> impl Strategy<Value = f64> {
        prop_oneof![
            any::<f64>(),
            any::<u64>().prop_map(f64::from_bits),
            prop::sample::select(std::vec![
                f64::NAN,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::MAX,
                -f64::MAX,
                f64::MIN_POSITIVE,
                5e-324,
                -5e-324,
                1e200,
                0.0,
            ]),
        ]
    }

    /// Today's text at everyday magnitudes: the figures quoted in the README and tests.
    #[test]
    fn everyday_figures_keep_their_text() {
        let e = Error::InsufficientCoverage {
            covered_deg: 187.2,
            noise_deg: 0.0,
            need_deg: 200.0,
        };
        assert_eq!(
            e.to_string(),
            "the samples cover only 187° of heading, need at least 200°; turn further (a full circle is best) before solving"
        );
        let e = Error::TooFewBins {
            filled: 15,
            need: 16,
            bins: 64,
        };
        assert_eq!(
            e.to_string(),
            "the readings fill only 15 of the 64 direction bins, need at least 16; turn through more headings (a full circle is best) before solving"
        );
        let e = Error::TooNoisyForOrientations {
            noise_rel: 0.012,
            dilution: 21.25,
            product: 0.255,
            max_product: 0.2,
        };
        assert!(
            e.to_string()
                .starts_with("each reading scatters 1.2 % of the field about the fit and the orientations' dilution is 21.2: their product, 0.26, exceeds the 0.2 "),
            "{e}"
        );
        let e = Error::Undetermined {
            dilution: f64::INFINITY,
            even_dilution: 2.0,
            even_shape: "circle",
            model_error_rel: 0.01,
            error_deg: f64::INFINITY,
            max_deg: 5.0,
            hint: "turn",
        };
        assert!(
            e.to_string().contains("their dilution is not finite (inf)"),
            "{e}"
        );
        assert!(e.to_string().contains("by any angle"), "{e}");
        let e = Error::IncompleteTurn {
            turned_deg: 3.2e200,
            need_deg: 360.0,
        };
        assert_eq!(
            e.to_string(),
            "the turn covered only 3.2e200°, need at least 360°; drive a complete circle"
        );
    }

    proptest! {
        /// Whatever figures a variant carries, its message stays a readable sentence: at
        /// most 600 bytes and no run of more than 20 digits.
        #[test]
        fn messages_stay_short_for_any_figure(
            a in any_figure(), b in any_figure(), c in any_figure(),
            d in any_figure(), e in any_figure(), f in any_figure(),
        ) {
            for error in with_figures([a, b, c, d, e, f]) {
                let text = error.to_string();
                prop_assert!(text.len() <= 600, "{} bytes: {}", text.len(), text);
                prop_assert!(longest_digit_run(&text) <= 20, "{}", text);
            }
        }
    }

    /// Ranges and values read at a glance: no 309-digit numbers, no float noise.
    #[test]
    fn numbers_in_messages_are_short() {
        for (v, want) in [
            (100.0, "100"),
            (-0.5, "-0.5"),
            (100.08000000000379, "100.08"),
            (1e308, "1e308"),
            (f64::MAX, "1.798e308"),
            (1.5e-7, "1.5e-7"),
            (0.0, "0"),
            (0.0432, "0.0432"),
            (123456.7, "123457"),
            (f64::NAN, "NaN"),
        ] {
            assert_eq!(Readable(v).to_string(), want, "{v}");
        }
        let e = Error::OutOfRange {
            what: "x",
            value: 1e308,
            min: -f64::MAX,
            max: f64::MAX,
        };
        assert_eq!(
            e.to_string(),
            "x = 1e308 is outside its valid range [-1.798e308, 1.798e308]"
        );
    }
}
