//! The uncertainty of the [`crate::QuaternionFilter`]'s attitude: one standard deviation of
//! the error about the reference (NED) x, y and z axes, propagated alongside the filter from
//! the sensors' error model ([`AttitudeUncertaintyConfig`]) and the filter's own gains.
//!
//! The filter is a complementary filter: per axis the error obeys
//! `e ← (1 − k) e − k v + w`, with `k = dt/τ` the correction's gain, `v` the error of what
//! corrects it (accelerometer or magnetometer) and `w` what the gyro adds. A complementary
//! filter with fixed gains is a steady-state Kalman filter for some noise model (Higgins,
//! *A comparison of complementary and Kalman filtering*, IEEE TAES 11(3), 1975), so its
//! error variance follows the same linear propagation with the gain held fixed instead of
//! optimised. Inclination (about x and y, treated alike) and heading (about z) each carry:
//!
//! - **Gyro** (Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
//!   Systems*, 2nd ed., 2013, §4.4.6 and §14.2.7): white noise adds `N² dt` to the variance of
//!   the angle error `e`; a bias error `β` (a random constant plus a random walk) adds to it
//!   through the pair `(e, β)`, whose 2 × 2 covariance is propagated exactly. Each applied
//!   correction multiplies `e` by `1 − k` (for inclination, whose low-pass sets the
//!   dynamics, `k = dt/τ_i` with `τ_i = √2 τ_acc`, the first-order loop with the
//!   Butterworth low-pass's lag behind a steady drift); in motion the filter's bias estimate integrates
//!   the corrections (`β ← β − (k/τ_b) e`), which is credited only with the in-phase part
//!   of a first-order loop's response to a bias that turns with the body at `|ω|`,
//!   `1/(1 + (|ω| τ)²)`: a fast-turning body shows its bias to the corrections only
//!   briefly along any one reference axis. At rest the bias variance
//!   falls to that of the rest detector's mean of white noise, `N²/(2(τ_mean + τ_rest))`
//!   (two first-order low-passes in cascade). As the body turns, the bias uncertainties of
//!   the three reference axes mix (a body axis that was horizontal becomes vertical).
//! - **Gyro scale and axis errors** `S` (relative, `s` per element): the error rate `R S ω`
//!   accumulates coherently while the body keeps turning the same way and cancels when it
//!   turns back. While a sensor corrects the axis, the drift it causes shows in the
//!   corrections (a loop's error behind a steady drift is the drift over its time
//!   constant, which is what its corrections add up to over that time), and is counted
//!   there (below: what the sensors say). Only heading goes without correction (the field
//!   rejected, or absent): then it is `s |ψ|` with `ψ` the reference-frame rotation since
//!   the field was last trusted, `ψ ← ψ + R ω dt`, decaying as `ψ ← (1 − k) ψ` with the
//!   corrections once the field returns (exact for scale errors and a rotation about one
//!   body axis). Counting the prior `s |ψ|` while the corrections show the drift counted
//!   it twice: on BROAD's 20 trials the inclination σ was 4 times its RMS error.
//! - **Latency**: a gyro's digital low-pass delays it by a few milliseconds (InvenSense
//!   MPU-9250 register map, register 26: 2.9 ms at its widest bandwidth, 5.9 ms at 41 Hz),
//!   so the attitude stands for a slightly earlier instant: an error `|R ω| δ` per axis.
//! - **What the corrections trust**: the accelerometer's bias (`b/g` of tilt, a constant
//!   passed fully) and white noise (through the Butterworth low-pass, whose noise bandwidth
//!   is `1/(2√2 τ_acc)`: variance `N_a²/(2√2 g² τ_acc)`); for heading, the magnetometer's residual calibration
//!   error (a constant), its white noise (`σ_h² k/2`: a first-order low-pass of white
//!   noise) and the inclination error about north, which the dip turns into a heading error
//!   `e_x tan(dip)` (the east component of `e × m`). Of that, the parts that persist (the
//!   biases' and the scale error's) pass the heading loop whole; the accelerations' varies
//!   with the inclination loop's time constant `τ_i` and passes by `τ_i/(τ_i + τ_mag)`, the
//!   variance a first-order low-pass leaves of a first-order Gauss–Markov process (Gelb,
//!   *Applied Optimal Estimation*, 1974, §3.8). Such a variance `C` enters as
//!   `P ← (1 − k)² P + (1 − (1 − k)²) C`, so it is reached with the correction's own time
//!   constant and kept while corrections are suspended.
//! - **What the sensors say the model cannot explain** (covariance matching on the
//!   corrections, Mehra, *Approaches to adaptive filtering*, IEEE TAC 17(5), 1972):
//!   - *accelerations and drift*: the body's accelerations and the gyro's drift show in
//!     the inclination corrections; their recent sum `ε ← (1 − k) ε + correction` is what
//!     the accelerometer has moved the attitude by within the loop's time constant, and the
//!     envelope of its square is added per axis (rising with it at once, decaying over the
//!     low-pass's natural period `2π τ_acc`). Likewise the trusted heading corrections'
//!     recent sum, its envelope decaying with the heading loop's time constant. A *sustained* horizontal acceleration (a vehicle's turn) looks exactly like a
//!     tilt and is not seen: like the filter itself, σ assumes that the body's
//!     accelerations average out over a few seconds.
//!   - *magnetic disturbances*: the field's norm and dip departures from the learned
//!     reference, `r_n` and `r_d` (relative), low-passed with the heading loop's time
//!     constant over the readings that correct heading. A disturbance of random direction
//!     moves the east component (which turns heading and cannot be seen) as much on average
//!     as each of the two it shows, so it adds `(r_n² + r_d²)/(2 cos² dip)` to the heading
//!     variance.
//!   - *a hard-iron offset learned online* is estimated from the attitude itself, so
//!     readings corrected by it cannot also tell the heading's error: while one is
//!     subtracted, heading corrections shrink nothing (the gyro's terms grow as when the
//!     field is rejected), or a heading error adopted as an offset would shrink the σ of
//!     the heading it has spoilt.
//!
//! Without a magnetometer the heading is relative to the start and its σ is the drift
//! since the start. Everything is a few scalars per axis, cheap enough for every sample.

use core::f64::consts::SQRT_2;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Real, Result, STANDARD_GRAVITY_MPS2};

use super::attitude_uncertainty_config::AttitudeUncertaintyConfig;
use super::min_max::{at_least, at_most};
use super::real_checks::{check_finite_in, check_finite3_in, check_range_in};

/// The error model's values in the filter's float type `T`, as the per-sample steps use
/// them: converted once by the filter, not per sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct UncertaintyConstants<T> {
    /// The gyro's white-noise density and bias walk, squared: per second of strapdown.
    gyro_noise2: T,
    bias_walk2: T,
    /// A field reading's relative noise and the calibration's heading error, squared.
    mag_noise2: T,
    mag_heading2: T,
    /// The variance the bias estimate at rest settles to (see [`AttitudeUncertainty::at_rest`]).
    rest_bias_floor: T,
    /// The accelerometer's bias and white-noise density over g, squared (rad² of tilt, and
    /// per hertz).
    accel_bias2: T,
    accel_noise2: T,
}

/// The inclination loop as the σ follows it (see [`AttitudeUncertainty::accel_corrected`])
/// for one time constant `τ` of the low-pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InclinationConstants<T> {
    /// `τ_i = √2 τ`, the first-order loop's with the same lag behind a steady drift, s, and
    /// its inverse.
    loop_tau: T,
    inv_loop_tau: T,
    /// `1/(2π τ)`: the envelope's decay (see `accel_corrected`), 1/s.
    inv_period: T,
    /// The variance the accelerometer's bias and noise leave, rad².
    target: T,
}

impl<T: Real> UncertaintyConstants<T> {
    /// For the filter's validated parameters.
    pub(crate) fn of(cfg: &crate::QuaternionFilterConfig) -> Self {
        let u = &cfg.uncertainty;
        let g = STANDARD_GRAVITY_MPS2;
        let n = u.gyro_noise_rps_per_sqrt_hz;
        let walk = u.gyro_bias_walk_rps_per_sqrt_s;
        Self {
            gyro_noise2: T::of(n * n),
            bias_walk2: T::of(walk * walk),
            mag_noise2: T::of(u.mag_noise_rel * u.mag_noise_rel),
            mag_heading2: T::of(u.mag_heading_rad * u.mag_heading_rad),
            // The rest detector's mean (time constant `rest.mean_tau_s`) of the gyro's white
            // noise, followed by the bias estimate's own low-pass (`bias_tau_rest_s`).
            rest_bias_floor: T::of(n * n / (2.0 * (cfg.rest.mean_tau_s + cfg.bias_tau_rest_s))),
            accel_bias2: T::of(u.accel_bias_mps2 * u.accel_bias_mps2 / (g * g)),
            accel_noise2: T::of(
                u.accel_noise_mps2_per_sqrt_hz * u.accel_noise_mps2_per_sqrt_hz / (g * g),
            ),
        }
    }

    /// The inclination loop's constants for the low-pass's time constant `tau_s`.
    pub(crate) fn inclination(&self, tau_s: T) -> InclinationConstants<T> {
        let loop_tau = T::of(SQRT_2) * tau_s;
        InclinationConstants {
            loop_tau,
            inv_loop_tau: T::one() / loop_tau,
            // The envelope of the square (see `accel_corrected`) follows a rise at once
            // (the error an acceleration causes builds as fast as the corrections it
            // causes) and decays over the low-pass's natural period 2π τ (13 s by
            // default), so that it holds through the swings of an acceleration slow enough
            // to pass the low-pass.
            inv_period: T::one() / (T::of(core::f64::consts::TAU) * tau_s),
            // White noise through the Butterworth low-pass: its noise bandwidth is
            // 1/(2√2 τ) (∫|H|² df).
            target: self.accel_bias2 + self.accel_noise2 / (T::of(2.0 * SQRT_2) * tau_s),
        }
    }
}

/// A heading correction, as the σ takes it ([`AttitudeUncertainty::mag_corrected`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HeadingCorrection<T> {
    /// Its gain (covering the time since the last reading) and its loop's time constant, s.
    pub(crate) k: T,
    pub(crate) tau_s: T,
    /// The turn it applied about the vertical, rad.
    pub(crate) dz: T,
    /// The bias estimate's `1/τ_b`, 1/s (0 when it does not learn: at rest or in the
    /// start-up).
    pub(crate) inv_tau_bias: T,
}

/// The variance of the error about one kind of reference axis (inclination or heading).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
// `Real` includes serde's bounds on `T`.
#[serde(bound = "")]
struct AxisVariance<T: Real> {
    /// Angle error driven by the gyro, rad².
    angle: T,
    /// Covariance of that angle error and the bias error, rad²/s.
    angle_bias: T,
    /// Bias error, (rad/s)².
    bias: T,
    /// Angle error left by what the corrections trust, rad².
    measured: T,
}

impl<T: Real> AxisVariance<T> {
    fn new(angle: T, bias: T) -> Self {
        Self {
            angle,
            angle_bias: T::zero(),
            bias,
            measured: T::zero(),
        }
    }

    /// `dt` of strapdown: `e ← e + β dt + w`, `β ← β + walk`. The linear propagation holds
    /// while the error is a small angle; at [`UNINFORMED_VARIANCE_RAD2`] the angle is
    /// unknown and stays so (the covariance with the bias kept within Cauchy–Schwarz, so
    /// that the pair stays a covariance).
    #[inline]
    fn propagate(&mut self, dt_s: T, angle_noise: T, bias_noise: T) {
        self.angle += dt_s * (T::of(2.0) * self.angle_bias + dt_s * self.bias) + angle_noise;
        self.angle_bias += dt_s * self.bias;
        self.bias += bias_noise;
        let ceiling = T::of(UNINFORMED_VARIANCE_RAD2);
        if self.angle > ceiling {
            self.angle = ceiling;
            let bound = (self.angle * self.bias).sqrt();
            self.angle_bias = self.angle_bias.clamp(-bound, bound);
        }
    }

    /// One correction with gain `k` whose bias estimate takes `c` (1/s) of the error, and
    /// whose measurement leaves the variance `target` (reached with the correction's own
    /// time constant).
    #[inline]
    fn correct(&mut self, k: T, c: T, target: T) {
        let a = T::one() - k;
        let (pe, pb) = (self.angle, self.angle_bias);
        self.angle = a * a * pe;
        self.angle_bias = a * (pb - c * pe);
        self.bias = at_least(self.bias - c * (T::of(2.0) * pb - c * pe), T::zero());
        let target = at_most(target, T::of(UNINFORMED_VARIANCE_RAD2));
        self.measured += (T::one() - a * a) * (target - self.measured);
    }
}

/// The propagated uncertainty (see the module documentation): part of the
/// [`crate::QuaternionFilterState`], opaque. In the filter's float type `T` (the error
/// model stays `f64`, converted where it is used).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
// `Real` includes serde's bounds on `T`.
#[serde(bound = "")]
pub struct AttitudeUncertainty<T: Real = f64> {
    config: AttitudeUncertaintyConfig,
    inclination: AxisVariance<T>,
    heading: AxisVariance<T>,
    /// Reference-frame rotation since the field was last trusted, decaying with the
    /// heading loop's time constant once it is again.
    turned_heading: Vector3<T>,
    /// The last field reading corrected heading with trust (the turn since it is seen).
    heading_trusted: bool,
    /// Recent sum of the inclination corrections about x and y, and the envelope of its
    /// square per axis.
    accel_moved: [T; 2],
    accel_moved_sq: [T; 2],
    /// Recent sum of the trusted heading corrections, and the envelope of its square.
    mag_moved: T,
    mag_moved_sq: T,
    /// Low-passed relative norm and dip departures of the field, and `1/(2 cos² dip)`.
    norm_departure: T,
    dip_departure: T,
    half_inv_cos2_dip: T,
    /// Reference-frame rate and its norm at the last step.
    rate_ned: Vector3<T>,
    rate_rps: T,
}

/// Inclination σ assumed before the first correction, rad: the tilt the first reading
/// shows under a 2 m/s² horizontal acceleration (a brisk hand movement); the start-up's
/// fast corrections shrink it within a second.
const INITIAL_INCLINATION_RAD: f64 = 0.2;
/// Heading σ of an unknown heading, rad: uniform over the circle, π/√3.
const UNKNOWN_HEADING_RAD: f64 = core::f64::consts::PI / 1.732_050_807_568_877_2;
/// The largest variance of the error about any axis, rad²: that of an uninformed
/// attitude, whose error about the axis is uniform over the circle (−π, π], π²/3. An
/// error angle is defined modulo a turn, so no evidence makes it less known than that,
/// and the linear propagation, which lets a variance grow without bound, is valid only
/// well below it.
pub const UNINFORMED_VARIANCE_RAD2: f64 = UNKNOWN_HEADING_RAD * UNKNOWN_HEADING_RAD;

impl<T: Real> AttitudeUncertainty<T> {
    /// Before any correction: inclination from one reading of unknown acceleration, heading
    /// unknown (or, with `relative_heading`, zero: heading counted from the start).
    pub(crate) fn new(config: AttitudeUncertaintyConfig, relative_heading: bool) -> Self {
        let bias = T::of(config.gyro_bias_rps * config.gyro_bias_rps);
        let heading = if relative_heading {
            T::zero()
        } else {
            T::of(UNKNOWN_HEADING_RAD * UNKNOWN_HEADING_RAD)
        };
        Self {
            config,
            inclination: AxisVariance::new(
                T::of(INITIAL_INCLINATION_RAD * INITIAL_INCLINATION_RAD),
                bias,
            ),
            heading: AxisVariance::new(heading, bias),
            turned_heading: Vector3::zeros(),
            heading_trusted: false,
            accel_moved: [T::zero(); 2],
            accel_moved_sq: [T::zero(); 2],
            mag_moved: T::zero(),
            mag_moved_sq: T::zero(),
            norm_departure: T::zero(),
            dip_departure: T::zero(),
            half_inv_cos2_dip: T::of(0.5),
            rate_ned: Vector3::zeros(),
            rate_rps: T::zero(),
        }
    }

    /// Starts again after a gap the gyro could not bridge: the attitude is taken anew from
    /// the sensors, while the bias uncertainty carries over, widened by its walk.
    pub(crate) fn restart(&mut self, relative_heading: bool, gap_s: f64) {
        let mut fresh = Self::new(self.config, relative_heading);
        let walk = self.config.gyro_bias_walk_rps_per_sqrt_s;
        let prior = fresh.inclination.bias;
        let bias = |b: T| (b + T::of(walk * walk * gap_s)).min(prior);
        fresh.inclination.bias = bias(self.inclination.bias);
        fresh.heading.bias = bias(self.heading.bias);
        *self = fresh;
    }

    /// One strapdown step of `dt_s` at the body rate `omega_rps` (bias removed) of norm
    /// `rate_rps`, the body's attitude being `r` (body → NED).
    #[inline]
    pub(crate) fn propagate(
        &mut self,
        c: &UncertaintyConstants<T>,
        dt_s: T,
        omega_rps: &Vector3<T>,
        rate_rps: T,
        r: &Matrix3<T>,
    ) {
        let angle_noise = c.gyro_noise2 * dt_s;
        let bias_noise = c.bias_walk2 * dt_s;
        self.inclination.propagate(dt_s, angle_noise, bias_noise);
        self.heading.propagate(dt_s, angle_noise, bias_noise);
        self.rate_ned = r * omega_rps;
        self.rate_rps = rate_rps;
        let step = self.rate_ned * dt_s;
        if !self.heading_trusted {
            self.turned_heading += step;
        }
        // The body's turn mixes the reference axes' bias uncertainties (two inclination
        // axes and one heading axis), by the fraction of a radian turned.
        let mix = at_most(rate_rps * dt_s, T::one());
        let mean = (T::of(2.0) * self.inclination.bias + self.heading.bias) * T::of(1.0 / 3.0);
        self.inclination.bias += mix * (mean - self.inclination.bias);
        self.heading.bias += mix * (mean - self.heading.bias);
    }

    /// The inclination correction of this step of `dt_s`: the constants of the loop `c`,
    /// the correction applied about x and y (rad) and the bias estimate's `1/τ_b` (0 when it
    /// does not learn: at rest or in the start-up). The error follows the low-pass as it
    /// would a first-order loop with the same lag behind a steady drift, `√2 τ`.
    #[inline]
    pub(crate) fn accel_corrected(
        &mut self,
        c: &InclinationConstants<T>,
        dt_s: T,
        correction: (T, T),
        inv_tau_bias: T,
    ) {
        let k = at_most(dt_s * c.inv_loop_tau, T::one());
        let k_env = at_most(dt_s * c.inv_period, T::one());
        let credit = self.bias_credit(k, c.loop_tau, inv_tau_bias);
        self.inclination.correct(k, credit, c.target);
        let a = T::one() - k;
        for (i, c) in [correction.0, correction.1].into_iter().enumerate() {
            let moved = a * self.accel_moved[i] + c;
            self.accel_moved[i] = moved;
            let sq = moved * moved;
            let env = self.accel_moved_sq[i];
            self.accel_moved_sq[i] = if sq > env {
                sq
            } else {
                env + k_env * (sq - env)
            };
        }
    }

    /// A heading correction `correction` that the field may be trusted for (not rejected,
    /// no offset learned from the attitude subtracted), by a reading whose horizontal and
    /// vertical components in the level frame are `reading`, the reference's `reference`;
    /// the inclination loop in effect is `inclination`.
    #[inline]
    pub(crate) fn mag_corrected(
        &mut self,
        constants: &UncertaintyConstants<T>,
        inclination: &InclinationConstants<T>,
        correction: &HeadingCorrection<T>,
        reading: (T, T),
        reference: (T, T),
    ) {
        let HeadingCorrection {
            k,
            tau_s,
            dz,
            inv_tau_bias,
        } = *correction;
        let (h, v) = reading;
        let (h0, v0) = reference;
        let n02 = h0 * h0 + v0 * v0;
        // A reference with no field (never learned) says nothing about the heading.
        if n02.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
            return;
        }
        let inv_n02 = T::one() / n02;
        // Departures without a square root: (|m|² − |m₀|²)/(2|m₀|²) and the sine of the dip
        // difference, both within a few per cent of exact for the fields that pass the test.
        let rn = T::of(0.5) * (h * h + v * v - n02) * inv_n02;
        let rd = (v * h0 - h * v0) * inv_n02;
        self.norm_departure += k * (rn - self.norm_departure);
        self.dip_departure += k * (rd - self.dip_departure);
        // 1/cos² dip = |m₀|²/h₀², the horizontal field kept above 10⁻³ of the whole.
        let inv_cos2_dip = n02 / at_least(h0 * h0, T::of(1e-6) * n02);
        self.half_inv_cos2_dip = T::of(0.5) * inv_cos2_dip;
        let tan2_dip = inv_cos2_dip - T::one();
        // A reading's heading noise, σ/cos dip, through the loop: k/2 of its variance.
        let white = constants.mag_noise2 * inv_cos2_dip * T::of(0.5) * k;
        // The inclination error about north is the one the dip turns into heading. The parts
        // of it that persist (the biases' and the scale error's) pass the heading loop
        // whole; the accelerations' varies with the inclination loop's time constant and
        // passes by τ_acc/(τ_acc + τ_mag).
        let passed = inclination.loop_tau / (inclination.loop_tau + tau_s);
        let i = &self.inclination;
        let tilt = tan2_dip
            * at_most(
                i.angle + i.measured + passed * self.accel_moved_sq[0],
                T::of(UNINFORMED_VARIANCE_RAD2),
            );
        let target = constants.mag_heading2 + white + tilt;
        let c = self.bias_credit(k, tau_s, inv_tau_bias);
        self.heading.correct(k, c, target);
        self.turned_heading *= T::one() - k;
        self.heading_trusted = true;
        let moved = (T::one() - k) * self.mag_moved + dz;
        self.mag_moved = moved;
        let sq = moved * moved;
        self.mag_moved_sq = if sq > self.mag_moved_sq {
            sq
        } else {
            self.mag_moved_sq + k * (sq - self.mag_moved_sq)
        };
    }

    /// A field reading that did not correct heading with trust (disturbed, or corrected by
    /// an offset learned from the attitude): the turn from now on is unseen by it.
    #[inline]
    pub(crate) fn heading_untrusted(&mut self) {
        self.heading_trusted = false;
    }

    /// A heading correction with gain `k` by a field less an offset learned from the
    /// attitude: it tells nothing of the heading's error (the offset took in whatever error
    /// the attitude had when it was learned), so no variance shrinks, but it holds the
    /// heading against the gyro's scale error as a trusted field would.
    #[inline]
    pub(crate) fn heading_held(&mut self, k: T) {
        self.turned_heading *= T::one() - k;
        self.heading_trusted = true;
    }

    /// The share `c` (1/s) of a correction with gain `k` and time constant `tau_s` that the
    /// bias estimate takes, credited by the in-phase response to a bias turning at |ω|.
    #[inline]
    fn bias_credit(&self, k: T, tau_s: T, inv_tau_bias: T) -> T {
        if inv_tau_bias == T::zero() {
            return T::zero();
        }
        let wt = self.rate_rps * tau_s;
        k * inv_tau_bias / (T::one() + wt * wt)
    }

    /// A step at rest: the bias follows the rest detector's mean with gain `k`.
    #[inline]
    pub(crate) fn at_rest(&mut self, constants: &UncertaintyConstants<T>, k: T) {
        let floor = constants.rest_bias_floor;
        let a = (T::one() - k) * (T::one() - k);
        for axis in [&mut self.inclination, &mut self.heading] {
            axis.bias = a * axis.bias + (T::one() - a) * floor;
            axis.angle_bias *= T::one() - k;
        }
    }

    /// The inclination error's variance about reference axis `i` (0: x, 1: y), without the
    /// latency term.
    #[inline]
    fn inclination_variance(&self, i: usize) -> T {
        (self.inclination.angle + self.inclination.measured + self.accel_moved_sq[i])
            .min(T::of(UNINFORMED_VARIANCE_RAD2))
    }

    /// Checks a restored uncertainty against the error model `config` of its filter: the
    /// same model, finite numbers, variances ≥ 0.
    pub(crate) fn check(&self, config: &AttitudeUncertaintyConfig) -> Result<()> {
        if self.config != *config {
            return Err(Error::InvalidSnapshot {
                reason: "the σ's error model differs from the filter's",
            });
        }
        for axis in [&self.inclination, &self.heading] {
            check_range_in("uncertainty angle variance", axis.angle, 0.0, f64::MAX)?;
            check_range_in("uncertainty bias variance", axis.bias, 0.0, f64::MAX)?;
            check_range_in(
                "uncertainty measured variance",
                axis.measured,
                0.0,
                f64::MAX,
            )?;
            check_finite_in("uncertainty angle-bias covariance", axis.angle_bias)?;
        }
        for v in [&self.turned_heading, &self.rate_ned] {
            check_finite3_in("uncertainty turn", v)?;
        }
        for v in self
            .accel_moved
            .iter()
            .chain(&self.accel_moved_sq)
            .chain(&[self.mag_moved, self.mag_moved_sq])
        {
            check_finite_in("uncertainty acceleration term", *v)?;
        }
        for v in [
            self.norm_departure,
            self.dip_departure,
            self.half_inv_cos2_dip,
            self.rate_rps,
        ] {
            check_finite_in("uncertainty field term", v)?;
        }
        Ok(())
    }

    /// One σ of the error about the reference x, y and z axes, rad.
    #[inline]
    pub(crate) fn sigma_rad(&self) -> Vector3<T> {
        let lag = self.rate_ned * T::of(self.config.gyro_latency_s);
        let s = self.config.gyro_scale_rel;
        let disturbance = (self.norm_departure * self.norm_departure
            + self.dip_departure * self.dip_departure)
            * self.half_inv_cos2_dip;
        let heading = self.heading.angle
            + self.heading.measured
            + T::of(s * s) * self.turned_heading.norm_squared()
            + self.mag_moved_sq
            + disturbance;
        // Each term is a variance of the same error; their sum, like each, is at most that
        // of an uninformed attitude (a NaN from an inf − inf cannot arise below it).
        let ceiling = T::of(UNINFORMED_VARIANCE_RAD2);
        let sigma = |v: T| v.min(ceiling).sqrt();
        Vector3::new(
            sigma(self.inclination_variance(0) + lag.x * lag.x),
            sigma(self.inclination_variance(1) + lag.y * lag.y),
            sigma(heading + lag.z * lag.z),
        )
    }
}
