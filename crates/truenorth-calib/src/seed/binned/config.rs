//! The configuration of the [`crate::BinnedEllipseCalibrator`] and its validation.

use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, Validate, check_positive, check_range};

use crate::quality::MIN_ARC_DEG;
use crate::seed::binned::bins::MAX_BINS;

/// Most initial readings averaged for the first origin.
pub const MAX_INIT_SAMPLES: usize = 64;

/// Configuration of the [`crate::BinnedEllipseCalibrator`] (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BinnedEllipseConfig {
    /// Number of direction bins N, even, 8..=[`MAX_BINS`] (128; 64 by default).
    pub bins: usize,
    /// Readings averaged for the initial origin, 1..=[`MAX_INIT_SAMPLES`] (8).
    pub init_samples: usize,
    /// Filled bins needed before interpolating and iterating the origin (N/4 = 16).
    pub min_filled_bins: usize,
    /// Interpolate/re-bin passes before the ellipse parameters are computed (4).
    pub origin_iterations: usize,
    /// How many readings a bin averages; 1 = the newest replaces the stored one (1).
    pub bin_memory: u32,
    /// Readings between the starts of full-set updates (and restart checks) during push
    /// (128). An update runs in slices over the following pushes (at most
    /// `min(update_interval, 128)` of them), so each push does a bounded share of it.
    pub update_interval: usize,
    /// RMS change between successive full sets, relative to `|E_L|`, that restarts (0.1).
    /// On the reference turn noise and re-binning change the set by 0.01–0.03 between
    /// updates, a lorry passing (half the earth's field for 3 s) by no more, and a magnet
    /// shifting the hard iron by 0.6 of the field by about 0.16 within one update. With
    /// noisy readings the threshold rises to four times the per-reading noise (the change
    /// noise alone makes, twice: see the `binned_assess` module), so that noise does not
    /// restart a good calibration; a magnet then has to move the set by that much.
    pub restart_threshold: f64,
    /// Share of bins holding readings before changes are monitored (0.75; re-binning about a
    /// moved origin merges a few readings, so a full turn typically leaves 50–64 of 64 filled).
    pub monitor_from_fraction: f64,
    /// Readings binned before the parameters may be stored (256).
    pub min_samples_to_store: usize,
    /// Shortest arc of headings accepted by solve, degrees ([`MIN_ARC_DEG`]). It is checked
    /// twice: about the fitted origin, and as the locus's own turning
    /// ([`crate::quality::locus_turning_rad`]), which errs short by up to a chord at each
    /// end. In practice a turn of about 250° is needed (1 % noise, 20 seeds: 13 of 20 turns of
    /// 230° accepted, all of 250°; none of 210° or less).
    pub min_arc_deg: f64,
    /// Largest RMS radial residual of the binned readings, relative to `|E_L|`, that solve
    /// accepts (0.1). The ellipse model leaves only noise; more means the readings are not a
    /// rotation in a constant field (a short arc lost in noise, a disturbance).
    pub max_residual_rel: f64,
    /// Largest heading-error bound of the calibration accepted
    /// ([`truenorth_core::CompassQuality::heading_error_bound_deg`] widened to the Student-t
    /// quantile of the bins' residual degrees of freedom), degrees, > 0 (10, as the
    /// least-squares fits'): a noisy arc can spread its binned readings over more headings
    /// than it turned through, and this refuses what its arc tests let through.
    pub max_heading_error_bound_deg: f64,
    /// The expected horizontal field, input unit (e.g. from the World Magnetic Model), > 0,
    /// reported as [`CompassQuality::field_ratio_to_expected`](truenorth_core::CompassQuality::field_ratio_to_expected) (`None`).
    pub expected_field: Option<f64>,
}

impl Default for BinnedEllipseConfig {
    fn default() -> Self {
        Self {
            bins: 64,
            init_samples: 8,
            min_filled_bins: 16,
            origin_iterations: 4,
            bin_memory: 1,
            update_interval: 128,
            restart_threshold: 0.1,
            monitor_from_fraction: 0.75,
            min_samples_to_store: 256,
            min_arc_deg: MIN_ARC_DEG,
            max_residual_rel: 0.1,
            max_heading_error_bound_deg: 10.0,
            expected_field: None,
        }
    }
}

impl Validate for BinnedEllipseConfig {
    fn validate(&self) -> Result<()> {
        check_range(
            "binned ellipse bins",
            self.bins as f64,
            8.0,
            MAX_BINS as f64,
        )?;
        if !self.bins.is_multiple_of(2) {
            return Err(Error::OutOfRange {
                what: "binned ellipse bins (must be even, so opposite directions pair up)",
                value: self.bins as f64,
                min: 8.0,
                max: MAX_BINS as f64,
            });
        }
        check_range(
            "binned ellipse init_samples",
            self.init_samples as f64,
            1.0,
            MAX_INIT_SAMPLES as f64,
        )?;
        check_range(
            "binned ellipse min_filled_bins",
            self.min_filled_bins as f64,
            3.0,
            self.bins as f64,
        )?;
        check_range(
            "binned ellipse origin_iterations",
            self.origin_iterations as f64,
            0.0,
            1000.0,
        )?;
        check_range(
            "binned ellipse bin_memory",
            f64::from(self.bin_memory),
            1.0,
            1e9,
        )?;
        check_range(
            "binned ellipse update_interval",
            self.update_interval as f64,
            1.0,
            1e12,
        )?;
        check_range(
            "binned ellipse restart_threshold",
            self.restart_threshold,
            0.0,
            f64::MAX,
        )?;
        check_range(
            "binned ellipse monitor_from_fraction",
            self.monitor_from_fraction,
            0.0,
            1.0,
        )?;
        check_range("binned ellipse min_arc_deg", self.min_arc_deg, 0.0, 360.0)?;
        check_range(
            "binned ellipse max_residual_rel",
            self.max_residual_rel,
            0.0,
            f64::MAX,
        )?;
        check_positive(
            "binned ellipse max_heading_error_bound_deg",
            self.max_heading_error_bound_deg,
        )?;
        if let Some(f) = self.expected_field {
            check_positive("binned ellipse expected_field", f)?;
        }
        Ok(())
    }
}
