//! Which errors refuse the data (a result they cannot support) and which report an input or a
//! request that is wrong: a program that runs many recordings counts the first as a verdict on
//! a recording and the second as a failure to fix, without reading the message's words.

use crate::Error;

impl Error {
    /// Whether the error is a refusal of the data: the readings were read and are valid, but
    /// they cannot support the result asked for (too few of them, too little turn, an
    /// uncertain or noisy fit, a locus that is no ellipse, a gap a method cannot bridge, …).
    /// More or better data would give a result; fixing an option or a file would not.
    ///
    /// `false` for an input or a request that is wrong: a non-finite value, timestamps out of
    /// order, a parameter out of range, data that contradict their declared units, a date
    /// outside a model, a snapshot of another version or layout, something the sensor or
    /// method does not support. Those are failures to fix, whatever the data would show.
    ///
    /// ```
    /// use truenorth_core::Error;
    ///
    /// let short = Error::IncompleteTurn { turned_deg: 90.0, need_deg: 360.0 };
    /// assert!(short.is_refusal());
    /// let bad = Error::NonFinite { what: "mag_x", value: f64::NAN };
    /// assert!(!bad.is_refusal());
    /// ```
    pub fn is_refusal(&self) -> bool {
        match self {
            // The data: too few, too few headings, too little of a turn or of the sphere,
            // orientations or noise that leave the calibration undetermined or uncertain,
            // geometry that determines nothing, a gap longer than a method bridges, a locus
            // that is no ellipse, a fit the data do not let converge, a result asked for
            // before the data it needs.
            Error::TooFewPoints { .. }
            | Error::TooFewBins { .. }
            | Error::InsufficientCoverage { .. }
            | Error::InsufficientSphereCoverage { .. }
            | Error::IncompleteTurn { .. }
            | Error::Degenerate { .. }
            | Error::Undetermined { .. }
            | Error::TooNoisyForOrientations { .. }
            | Error::TooUncertain { .. }
            | Error::TimeGap { .. }
            | Error::NotAnEllipse { .. }
            | Error::NoConvergence { .. }
            | Error::NotReady { .. } => true,
            // The input or the request: values that are no numbers, time that does not
            // advance, parameters outside their range, units the data contradict, a date
            // outside the model, a saved state of another version or layout, a request the
            // sensor or method cannot meet; or the readings' store failing beneath the fit.
            Error::NonFinite { .. }
            | Error::NonIncreasingTime { .. }
            | Error::InvalidDt { .. }
            | Error::OutOfRange { .. }
            | Error::Implausible { .. }
            | Error::DateOutOfRange { .. }
            | Error::SnapshotVersion { .. }
            | Error::InvalidSnapshot { .. }
            | Error::Unsupported { .. }
            | Error::ReadingsUnavailable { .. } => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_data_are_refused_and_bad_input_fails() {
        let refusals = [
            Error::TooFewPoints { got: 3, need: 10 },
            Error::TooFewBins {
                filled: 15,
                need: 16,
                bins: 64,
            },
            Error::InsufficientCoverage {
                covered_deg: 90.0,
                noise_deg: 0.0,
                need_deg: 200.0,
            },
            Error::NotAnEllipse { detail: "" },
            Error::TimeGap {
                what: "w",
                t_s: 9.0,
                gap_s: 5.0,
                max_gap_s: 1.0,
            },
        ];
        assert!(refusals.iter().all(Error::is_refusal));
        let failures = [
            Error::NonIncreasingTime {
                prev_s: 2.0,
                t_s: 1.0,
            },
            Error::OutOfRange {
                what: "x",
                value: 5.0,
                min: 0.0,
                max: 1.0,
            },
            Error::Unsupported { reason: "r" },
            Error::ReadingsUnavailable { reason: "r" },
            Error::SnapshotVersion {
                found: 1,
                expected: 2,
            },
        ];
        assert!(!failures.iter().any(Error::is_refusal));
    }
}
