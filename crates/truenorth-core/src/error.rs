//! The workspace error type. Each variant says what was wrong and what to do about it, so that
//! a calibration that cannot be trusted is refused with a reason instead of returned silently.

use thiserror::Error;

/// Everything that can go wrong in truenorth's library code.
///
/// Library code never panics on bad input; it returns one of these.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A value that must be finite was NaN or infinite.
    #[error("{what} is not finite ({value}); every input value must be a finite number")]
    NonFinite {
        /// Which quantity.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A timestamp did not increase.
    #[error(
        "timestamp {t_s} s does not come after the previous one ({prev_s} s); sort samples by time and drop duplicates"
    )]
    NonIncreasingTime {
        /// Previous accepted timestamp, seconds.
        prev_s: f64,
        /// The rejected timestamp, seconds.
        t_s: f64,
    },
    /// A time step that is zero, negative or not finite.
    #[error("time step dt = {dt_s} s is not a positive finite number")]
    InvalidDt {
        /// The rejected time step, seconds.
        dt_s: f64,
    },
    /// A parameter or input outside its valid range.
    #[error("{what} = {value} is outside its valid range [{min}, {max}]")]
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
    /// Not enough samples to do what was asked.
    #[error("too few points: got {got}, need at least {need}; record more data before solving")]
    TooFewPoints {
        /// Samples available.
        got: usize,
        /// Samples required.
        need: usize,
    },
    /// The samples cover too little of a turn to determine a calibration.
    #[error(
        "the samples cover only {covered_deg:.0}° of heading, need at least {need_deg:.0}°; turn further (a full circle is best) before solving"
    )]
    InsufficientCoverage {
        /// Heading span covered, degrees.
        covered_deg: f64,
        /// Heading span required, degrees.
        need_deg: f64,
    },
    /// The orientations seen cover too little of the sphere to determine a 3-D calibration.
    #[error(
        "the orientations fill only {:.0} % of the sphere's direction cells, need at least {:.0} %; tumble the sensor through more orientations (turns about three axes)",
        100.0 * covered_fraction,
        100.0 * need_fraction
    )]
    InsufficientSphereCoverage {
        /// Share of direction cells with data, in [0, 1].
        covered_fraction: f64,
        /// Share required, in [0, 1].
        need_fraction: f64,
    },
    /// A turn-based method saw less than one full revolution.
    #[error(
        "the turn covered only {turned_deg:.0}°, need at least {need_deg:.0}°; drive a complete circle"
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
        "date {year} is outside the model's validity {valid_from}–{valid_to}; use a model for that epoch or opt in to extrapolation"
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
}
