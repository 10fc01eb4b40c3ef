//! Plain integration of the gyro along the odometry, as the vehicle estimator runs it beside
//! its fused estimate: the raw yaw rate less the bias the gyro read at its last rest, with
//! the uncertainty the physics gives it whatever the data (see [`super::plain_guard`]).

use serde::{Deserialize, Serialize};
use truenorth_core::wrap_pi;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Combined standard deviations of the fused and the plain heading beyond which their
/// difference says the fused estimate's learning went wrong (4: a departure checked at every
/// epoch, each strongly correlated with the last, fires by chance about once in 10⁴ of its
/// correlation times when both uncertainties are honest).
pub(super) const DEPARTURE_SIGMAS: f64 = 4.0;

/// Standard deviation of an uncalibrated yaw-rate sensor's common gain error (5 %): a MEMS
/// gyro's sensitivity tolerance of ±3 % and ±2 % over temperature, up to 3.4 % lost to a
/// mounting tilted by 15°, and a car's CAN yaw rate reading up to 8 % low against its
/// reference. Plain integration does not learn it, so it is what the baseline's heading
/// carries in proportion to the net turn.
const PLAIN_GAIN_SIGMA: f64 = 0.05;

/// Standard deviation of the difference between a yaw-rate sensor's right and left turn
/// gains and of its non-linearity (1 %, twice the ±1 % span of right against left that
/// sensor data sheets and the simulator allow): what the gross turn, both ways, carries.
const PLAIN_GAIN_ASYMMETRY: f64 = 0.01;

/// What the fused and the plain heading integrate differently even when both are right, rad
/// (2°): the fused heading carries the gyro's rate on between readings and steps at each
/// compass or wheel correction, and the baseline holds it at rests the fused estimate may
/// judge otherwise.
const DEPARTURE_FLOOR_RAD: f64 = 2.0 * core::f64::consts::PI / 180.0;

/// Plain integration of the gyro along the odometry, since its last anchor.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub(super) struct PlainBaseline {
    /// A rest has measured the bias, so the baseline has one.
    pub has_bias: bool,
    /// Anchored to the fused estimate and integrating since.
    pub anchored: bool,
    /// Heading, in the fused estimate's frame, rad.
    pub psi_rad: f64,
    /// Track, in the fused estimate's frame, m.
    pub north_m: f64,
    pub east_m: f64,
    /// The heading at the last odometry reading, rad.
    pub psi_at_wheels_rad: f64,
    /// The bias the last rest measured, rad/s, and that measurement's variance, rad²/s².
    pub bias_rps: f64,
    pub bias_var: f64,
    /// Time the bias has been walking since that rest, s.
    pub since_rest_s: f64,
    /// Heading error from the bias's error since the anchor, summed as fully correlated, rad.
    pub bias_spread_rad: f64,
    /// Turn since the anchor, right less left, rad: a common gain error turns the heading
    /// in proportion.
    pub net_turn_rad: f64,
    /// Turn since the anchor, right and left, rad: the gains' asymmetry turns the heading in
    /// proportion.
    pub turned_rad: f64,
    /// Rate noise integrated since the anchor, rad².
    pub noise_rad2: f64,
    /// The fused heading's variance at the anchor, rad².
    pub anchor_var: f64,
    /// Track error from the heading's since the anchor, summed as fully correlated, m.
    pub track_spread_m: f64,
    /// The fused track's variance at the anchor (its larger axis), m².
    pub anchor_track_var: f64,
    /// Times the fused estimate fell back to the baseline.
    pub fallbacks: u32,
}

/// What the baseline's uncertainty is made of that the data cannot tell it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PlainErrors {
    /// Rate noise density, rad²/s.
    pub noise_rad2_per_s: f64,
    /// The bias's random walk, rad²/s³.
    pub bias_walk_rad2_per_s3: f64,
    /// The gyro gain's prior standard deviation (the baseline takes at least
    /// [`PLAIN_GAIN_SIGMA`]).
    pub gain_sigma: f64,
}

impl PlainBaseline {
    /// Starts integrating from the fused estimate's heading and track as they stand, with
    /// their variances; what the rests taught about the bias is kept.
    pub fn anchor(
        &mut self,
        psi_rad: f64,
        north_m: f64,
        east_m: f64,
        psi_var: f64,
        track_var: f64,
    ) {
        *self = Self {
            has_bias: self.has_bias,
            anchored: self.has_bias,
            psi_rad,
            north_m,
            east_m,
            psi_at_wheels_rad: psi_rad,
            bias_rps: self.bias_rps,
            bias_var: self.bias_var,
            since_rest_s: self.since_rest_s,
            anchor_var: psi_var,
            anchor_track_var: track_var,
            fallbacks: self.fallbacks,
            ..Self::default()
        };
    }

    /// A rest measured the bias as `bias_rps` with variance `var`.
    pub fn rest_measured(&mut self, bias_rps: f64, var: f64) {
        self.has_bias = true;
        self.bias_rps = bias_rps;
        self.bias_var = var;
        self.since_rest_s = 0.0;
    }

    /// Moves the heading by a raw gyro increment `raw_angle_rad` over `dt_s` of motion.
    pub fn gyro_step(&mut self, raw_angle_rad: f64, dt_s: f64, errors: &PlainErrors) {
        if !self.anchored {
            return;
        }
        self.since_rest_s += dt_s;
        let dpsi = raw_angle_rad - self.bias_rps * dt_s;
        self.psi_rad = wrap_pi(self.psi_rad + dpsi);
        let bias_sigma = (self.bias_var + errors.bias_walk_rad2_per_s3 * self.since_rest_s).sqrt();
        self.bias_spread_rad += bias_sigma * dt_s;
        self.net_turn_rad += dpsi;
        self.turned_rad += dpsi.abs();
        self.noise_rad2 += errors.noise_rad2_per_s * dt_s;
    }

    /// Draws the track `ds_m` along the heading half-way since the last odometry reading.
    pub fn odometry_step(&mut self, ds_m: f64, errors: &PlainErrors) {
        if !self.anchored {
            return;
        }
        let mid = self.psi_at_wheels_rad + 0.5 * wrap_pi(self.psi_rad - self.psi_at_wheels_rad);
        let (s, c) = mid.sin_cos();
        self.north_m += ds_m * c;
        self.east_m += ds_m * s;
        self.psi_at_wheels_rad = self.psi_rad;
        self.track_spread_m += ds_m.abs() * self.heading_var(errors).sqrt();
    }

    /// Variance of the baseline's heading, rad²: the anchor's, the bias's error summed as
    /// fully correlated over the time since (it turns the heading the same way all along),
    /// the common gain error over the net turn and the asymmetry over the gross turn, and
    /// the rate noise.
    pub fn heading_var(&self, errors: &PlainErrors) -> f64 {
        let gain = errors.gain_sigma.max(PLAIN_GAIN_SIGMA) * self.net_turn_rad;
        let asymmetry = PLAIN_GAIN_ASYMMETRY * self.turned_rad;
        self.anchor_var
            + self.bias_spread_rad.powi(2)
            + gain * gain
            + asymmetry * asymmetry
            + self.noise_rad2
    }

    /// Variance of the baseline's track along either axis, m².
    pub fn track_var(&self) -> f64 {
        self.anchor_track_var + self.track_spread_m.powi(2)
    }

    /// Variance of the difference between the fused heading, of variance `psi_var`, and
    /// the baseline's, were the fused estimate's model right, rad².
    ///
    /// Both integrate the same gyro from the same anchor, and the fused estimate uses all
    /// the baseline uses and more: were its model right it would be the efficient estimate,
    /// and the difference of an efficient and a consistent estimate has the difference of
    /// their variances (Hausman, "Specification tests in econometrics", Econometrica 46(6),
    /// 1978, lemma 2.1) — not their sum, which the shared gyro errors would swell to
    /// uselessness within minutes. Where the fused estimate claims less than the baseline
    /// (it has widened its heading for what it could not follow), the sum bounds the
    /// difference instead. [`DEPARTURE_FLOOR_RAD`] covers what the two integrate differently.
    pub fn difference_var(&self, psi_var: f64, errors: &PlainErrors) -> f64 {
        let plain = self.heading_var(errors);
        let spread = if plain > psi_var {
            plain - psi_var
        } else {
            plain + psi_var
        };
        spread + DEPARTURE_FLOOR_RAD * DEPARTURE_FLOOR_RAD
    }

    /// Whether the fused heading `psi_rad` of variance `psi_var` departs from the baseline's
    /// beyond [`DEPARTURE_SIGMAS`] standard deviations of their difference.
    pub fn departs(&self, psi_rad: f64, psi_var: f64, errors: &PlainErrors) -> bool {
        if !self.anchored {
            return false;
        }
        let d = wrap_pi(psi_rad - self.psi_rad);
        d * d > DEPARTURE_SIGMAS * DEPARTURE_SIGMAS * self.difference_var(psi_var, errors)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const ERRORS: PlainErrors = PlainErrors {
        noise_rad2_per_s: 1e-6,
        bias_walk_rad2_per_s3: 1e-8,
        gain_sigma: 0.03,
    };

    fn anchored(bias: f64) -> PlainBaseline {
        let mut b = PlainBaseline::default();
        b.rest_measured(bias, 1e-8);
        b.anchor(0.0, 0.0, 0.0, 1e-4, 1.0);
        b
    }

    #[test]
    fn without_a_rest_there_is_no_baseline() {
        let mut b = PlainBaseline::default();
        b.anchor(0.3, 1.0, 2.0, 1e-4, 1.0);
        assert!(!b.anchored);
        b.gyro_step(1.0, 1.0, &ERRORS);
        assert_eq!(b.psi_rad, 0.3);
        assert!(!b.departs(3.0, 0.0, &ERRORS));
    }

    #[test]
    fn a_fused_heading_that_drifts_away_departs() {
        let mut b = anchored(0.01);
        let mut fused = 0.0;
        let mut fired_at = None;
        // Straight ahead for 100 s; the fused estimate learned the bias 0.5°/s off.
        for k in 1..=1000 {
            b.gyro_step(0.01 * 0.1, 0.1, &ERRORS);
            b.odometry_step(1.0, &ERRORS);
            fused += 0.5f64.to_radians() * 0.1;
            if fired_at.is_none() && b.departs(fused, 1e-4, &ERRORS) {
                fired_at = Some(k);
            }
        }
        let k = fired_at.expect("a 0.5°/s error departs within 100 s");
        assert!(k > 10, "not at once: {k}");
        assert!(b.psi_rad.abs() < 1e-12 && (b.north_m - 1000.0).abs() < 1e-9);
    }

    proptest! {
        #[test]
        fn a_heading_within_the_combined_sigma_never_departs(
            turns in proptest::collection::vec(-0.5f64..0.5, 1..200),
            z in -3.9f64..3.9,
            fused_var in 0.0f64..0.1,
        ) {
            let mut b = anchored(0.002);
            for dpsi in &turns {
                b.gyro_step(*dpsi, 0.1, &ERRORS);
                b.odometry_step(0.5, &ERRORS);
            }
            let sigma = b.difference_var(fused_var, &ERRORS).sqrt();
            prop_assert!(!b.departs(b.psi_rad + z * sigma, fused_var, &ERRORS));
            // Never beyond the sum of the two variances, never below the floor.
            let floor = DEPARTURE_FLOOR_RAD * DEPARTURE_FLOOR_RAD;
            prop_assert!(sigma * sigma <= fused_var + b.heading_var(&ERRORS) + floor * (1.0 + 1e-12));
            prop_assert!(sigma * sigma >= floor);
            // Its uncertainty only grows between anchors.
            prop_assert!(b.heading_var(&ERRORS) >= 1e-4 && b.track_var() >= 1.0);
        }

        #[test]
        fn anchoring_keeps_the_bias_and_the_count(bias in -0.1f64..0.1, n in 0u32..5) {
            let mut b = anchored(bias);
            b.fallbacks = n;
            b.gyro_step(0.3, 1.0, &ERRORS);
            b.anchor(1.0, 2.0, 3.0, 0.5, 4.0);
            prop_assert_eq!(b.bias_rps, bias);
            prop_assert_eq!(b.fallbacks, n);
            prop_assert_eq!(b.heading_var(&ERRORS), 0.5);
            prop_assert_eq!(b.turned_rad, 0.0);
        }
    }
}
