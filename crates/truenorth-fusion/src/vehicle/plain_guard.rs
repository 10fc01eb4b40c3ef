//! Plain integration beside the fused estimate, and the fall-back to it when the two part.
//!
//! The fused estimator learns the gyro's bias and gains and the wheels' calibration from
//! how the sensors disagree. Where the motion cannot separate them (a skid-steer's wheels
//! in a turn, a steady circle, equal wheels that say nothing of turning) it can learn them
//! wrongly and then trust its model more than it should. Plain integration needs no such
//! learning: the raw yaw rate less the bias the gyro read at the last rest, drawn along the
//! odometry's distance. Its errors come from what it does not correct — the rest's bias
//! error growing with the bias's walk, the gyro's gain error within its physical prior, the
//! rate noise — so its uncertainty is known without the data.
//!
//! The baseline is anchored to the fused estimate where the fused estimate gains
//! information plain integration does not have (an absolute compass reference, a gap
//! bridged) and at the first rest that measures the bias; between anchors the two run on the
//! same gyro and odometry. Where the fused heading departs from the baseline's by more than
//! [`super::plain_baseline::DEPARTURE_SIGMAS`] of their combined uncertainty, one of the fused estimate's learned
//! states is wrong: the estimator falls back to the baseline's heading and track with the
//! baseline's uncertainty, and every learned gyro and wheel state returns to what the
//! baseline assumes (the rest's bias, the gains and wheel calibration at their priors)
//! instead of carrying on from a model the data contradicted.

use super::estimator::VehicleEstimator;
use super::nav_filter::{
    BIAS, EAST, GAIN_NEG, GAIN_POS, NORTH, PSI, SPEED_COEFF, TRACK_SCALE, WHEEL_DIFF, WHEEL_LAG,
};
use super::plain_baseline::PlainErrors;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

impl VehicleEstimator {
    /// What the plain baseline's uncertainty is made of, from the priors in use.
    fn plain_errors(&self) -> PlainErrors {
        PlainErrors {
            noise_rad2_per_s: self.coeffs.gyro_noise_rad2_per_s,
            bias_walk_rad2_per_s3: self.coeffs.bias_walk_rad2_per_s3,
            gain_sigma: self.coeffs.prior_sigma[GAIN_POS].max(self.coeffs.prior_sigma[GAIN_NEG]),
        }
    }

    /// Anchors the plain baseline to the fused estimate as it stands: the fused estimate
    /// has just gained what plain integration cannot have (a rest's bias for the first
    /// time, a compass reference, a gap crossed on other sensors).
    pub(super) fn anchor_plain(&mut self) {
        let f = &self.filter;
        let psi_var = self.tracking.batch.psi_variance(f).max(0.0);
        let track_var = f.p[NORTH][NORTH].max(f.p[EAST][EAST]).max(0.0);
        self.tracking
            .guard
            .anchor(f.x[PSI], f.x[NORTH], f.x[EAST], psi_var, track_var);
    }

    /// A rest measured the gyro's bias: plain integration takes it, and starts from the
    /// fused estimate if it had no bias before.
    pub(super) fn plain_rest(&mut self, bias_rps: f64, var: f64) {
        let first = !self.tracking.guard.has_bias;
        self.tracking.guard.rest_measured(bias_rps, var);
        if first {
            self.anchor_plain();
        }
    }

    /// Moves the plain heading by a raw gyro increment over `dt_s` of motion.
    pub(super) fn plain_gyro(&mut self, raw_angle_rad: f64, dt_s: f64) {
        let errors = self.plain_errors();
        self.tracking.guard.gyro_step(raw_angle_rad, dt_s, &errors);
    }

    /// Draws the plain track over `ds_m` of odometry.
    pub(super) fn plain_odometry(&mut self, ds_m: f64) {
        let errors = self.plain_errors();
        self.tracking.guard.odometry_step(ds_m, &errors);
    }

    /// At an epoch (the covariance just carried forward): where the fused heading departs
    /// from plain integration beyond both uncertainties, falls back to plain integration.
    ///
    /// The heading and track become the baseline's, with its uncertainty; the gyro's bias
    /// becomes the last rest's and its gains and the wheels' calibration return to their
    /// priors (not to a stored calibration: that may be what was wrong), uncorrelated with
    /// anything: what the fused estimate had learned of them is
    /// what the data contradicted, and which of them was wrong matters less than not
    /// carrying it on. The filter learns them again from there.
    pub(super) fn guard_against_plain(&mut self) {
        let errors = self.plain_errors();
        let g = self.tracking.guard;
        if !self.config.plain_guard
            || !g.departs(self.filter.x[PSI], self.filter.p[PSI][PSI], &errors)
        {
            return;
        }
        let since_rest_var = g.bias_var + errors.bias_walk_rad2_per_s3 * g.since_rest_s;
        let prior = self.coeffs.prior_sigma;
        let initial = self.coeffs.prior_x();
        let f = &mut self.filter;
        f.x[BIAS] = g.bias_rps;
        f.reset_state(BIAS, since_rest_var.sqrt());
        for i in [
            GAIN_POS,
            GAIN_NEG,
            WHEEL_DIFF,
            SPEED_COEFF,
            TRACK_SCALE,
            WHEEL_LAG,
        ] {
            f.x[i] = initial[i];
            f.reset_state(i, prior[i]);
        }
        f.x[PSI] = g.psi_rad;
        f.reset_state(PSI, g.heading_var(&errors).sqrt());
        f.x[NORTH] = g.north_m;
        f.x[EAST] = g.east_m;
        let track_sigma = g.track_var().sqrt();
        f.reset_state(NORTH, track_sigma);
        f.reset_state(EAST, track_sigma);
        self.tracking.motion.psi_at_wheels_rad = g.psi_at_wheels_rad;
        self.tracking.gyro.rate_rps = 0.0;
        self.tracking.gyro.smoothed_rps = 0.0;
        self.restart_wheel_heading();
        self.tracking.guard.fallbacks += 1;
        self.est.status.fell_back = true;
        self.anchor_plain();
    }
}
