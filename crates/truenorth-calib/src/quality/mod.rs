//! Quality measures shared by every compass calibrator: how much of the circle (or sphere)
//! the data cover, how far the calibrated readings stray from a circle (sphere), how well
//! the geometry determines the calibration, and how large a heading error that allows.
//!
//! Every calibrator in this crate fills its [`CompassQuality`](truenorth_core::CompassQuality) through [`assess_2d`] /
//! [`quality_2d`] (or [`assess_3d`]), so the numbers mean the same thing whichever method
//! produced them. The least-squares ellipse fit computes the same 2-D report from the
//! monomial sums of its direct fit instead of a second pass over the readings.
//!
//! The parts live in submodules: coverage (heading bins), sphere_cells (the sphere's direction
//! cells), arc (the locus's turning and the shortest arc accepted), direction_bins (the fast
//! direction of a reading and its bin), direction_sectors (the sector of a direction among n
//! equal ones, as `atan2` places it, found mostly without it), direction_turn (whether a direction
//! turned a given angle from another, as `atan2` decides it, found mostly without it), bounds (information matrices and heading-error bounds),
//! uncertainty (what the readings determine: the dilution of the information matrix, the predicted
//! parameter σ, and the determination test that replaces a share of direction cells), pass_2d (the
//! one pass over 2-D readings the report is built from), report_2d and report_3d (assembly of the
//! [`CompassQuality`](truenorth_core::CompassQuality), its [`CompassUncertainty`] included) and
//! field (the fitted field against an expected one). The report's data types and its verdict (good /
//! usable / poor, [`Verdict`]) live in `truenorth-core`, beside the calibrator trait, and are
//! re-exported here.
//!
//! # The three parts of the heading error
//!
//! * `heading_error_3sigma_deg` — three standard deviations of the heading error caused by
//!   the uncertainty of the fitted parameters, at the worst heading (derived below). It is
//!   the error the calibration adds to every later heading; it shrinks as `1/√N` with more
//!   readings. Per-reading noise is **not** in it.
//! * `heading_error_systematic_deg` — the deterministic heading error the method's model
//!   leaves even with perfect data: 0 for the least-squares ellipse and ellipsoid (their
//!   model represents any symmetric soft iron); for the seed methods that fit a circle or an
//!   axis-aligned ellipse, the peak of the two-cycle error of an unremoved rotated soft iron
//!   (see the `seed_quality` module).
//! * `heading_noise_rms_deg` — the RMS heading noise of one calibrated reading, estimated
//!   from the residuals that remain once the model (and, for the seed methods, the
//!   systematic two-cycle part) is taken out: for isotropic sensor noise of standard
//!   deviation `σ·F` per axis the radial residual and the heading error of one reading both
//!   have standard deviation `σ` (radians). Averaging readings reduces it; recalibrating
//!   does not.
//!
//! [`CompassQuality::heading_error_bound_deg`](truenorth_core::CompassQuality::heading_error_bound_deg) is the first two added: a bound on the error
//! of the calibration itself. A single reading's heading errs by that plus its own noise.
//!
//!
//! The bound's derivation is in the `bounds` module.

mod arc;
mod bounds;
mod coverage;
mod direction_bins;
mod direction_sectors;
mod direction_turn;
mod field;
mod limits;
mod pass_2d;
mod report_2d;
mod report_3d;
mod sphere_cells;
mod support;
mod uncertainty;

#[cfg(test)]
mod tests;

pub use arc::{ARC_END_NOISE_SIGMAS, MIN_ARC_DEG, locus_turning_rad, require_arc};
pub use bounds::BOUND_SIGMAS;
pub(crate) use bounds::{
    anisotropy_2d, anisotropy_3d, direct_fit_bias_rad, regressor_2d, regressor_3d,
};
pub use coverage::{COVERAGE_BINS, Coverage, calibrated_coverage_2d, coverage};
pub(crate) use coverage::{calibrated_directions_2d, coverage_of};
pub(crate) use direction_bins::{turns, turns_in};
pub(crate) use direction_sectors::{SectorHint, sector};
pub(crate) use direction_turn::{Direction, turned_at_least};
pub use field::{
    FIELD_RATIO_TOLERANCE, FieldMismatch, field_mismatch, mean_corrected_norm_2d,
    mean_corrected_norm_3d, with_expected_field,
};
pub use limits::FitLimits;
pub(crate) use pass_2d::ReportSums;
pub use report_2d::{Assessment2d, assess_2d, quality_2d};
pub(crate) use report_2d::{Moments2, SupportFigures, assess_2d_from_moments, direction_harmonics};
pub use report_3d::assess_3d;
pub(crate) use report_3d::{assess_3d_of, assess_3d_with_harmonics_of, support_dilution_3d};
pub use sphere_cells::{
    MIN_SPHERE_COVERAGE, SPHERE_BANDS, SPHERE_CELLS, SPHERE_SECTORS, require_sphere_coverage,
    sphere_coverage,
};
pub(crate) use sphere_cells::{sphere_cell, sphere_cell_of};
pub(crate) use support::GAP_BINS;
pub use truenorth_core::compass_quality::{
    DILUTION_EVEN_CIRCLE, DILUTION_EVEN_SPHERE, MODEL_ERROR_REL,
};
pub use truenorth_core::verdict::{GOOD_DEG, GOOD_NOISE_DEG, USABLE_DEG};
pub use truenorth_core::{Cause, CompassUncertainty, Grade, Verdict};
pub(crate) use uncertainty::uncertainty_from_factor;
pub use uncertainty::{MAX_NOISE_DILUTION, require_certain, require_determined, require_linear};
