//! A quaternion orientation filter for 6-D (gyro + accelerometer) and 9-D (+ magnetometer)
//! IMUs, with gyro-bias estimation at rest and in motion, magnetic-disturbance rejection and
//! online hard-iron re-estimation.
//!
//! Per sample (body → NED quaternion `q`, Hamilton, scalar first):
//! 1. **Strapdown**: `q ← q ⊗ exp((ω − b̂) dt / 2)`, with the rate the gyro's timing calls
//!    for ([`GyroTiming`]).
//! 2. **Inclination**: the specific force rotated into NED is low-passed there by a
//!    second-order Butterworth filter of time constant `τ_acc`, and `q` is turned about the
//!    horizontal axis so that the low-passed force points up, `(0, 0, −1)`: its horizontal
//!    part over g, wholly, every sample. This is VQF's inclination correction (Laidig &
//!    Seel, *VQF*, Information Fusion 91, 2023, §IV-B): low-passed in the frame the gyro
//!    alone keeps (almost inertial), the body's accelerations average out before they tilt
//!    anything, while a gyro error moves that frame only slowly; the low-passed vector and
//!    its rate are turned with every correction so that they stay in that frame. A
//!    Butterworth low-pass rejects a swing's acceleration three times better than a
//!    first-order low-pass followed by a first-order correction with the same lag behind a
//!    steady drift (`1/(τ²ω²)` against `1/(3τ²ω²)` at high frequency for a lag of `√2 τ`).
//!    The correction is linear in the specific force (its horizontal part over g), so the
//!    body's own accelerations, which average to zero over any swing, cancel; weighting
//!    readings by how far |a| is from g, or using the angle, biases the average.
//! 3. **Heading**: the magnetometer, less any hard-iron offset learned online
//!    ([`crate::HardIronEstimator`]), rotated into NED should point north; `q` is turned
//!    about the vertical only, by `dt/τ_mag` of the horizontal angle, so a disturbed field
//!    can never tilt the inclination (the decoupling of Madgwick's and VQF's heading
//!    updates). Readings judged disturbed by [`crate::MagReference`] (norm or dip off) are
//!    skipped. Samples without a reading (a magnetometer slower than the gyro) are skipped
//!    and the next reading's correction covers the time since the last one.
//! 4. **Gyro bias**: at rest ([`crate::RestDetector`]) the bias follows the mean of the raw
//!    rate; in motion, each correction's implied rate is integrated into the bias (the
//!    integral term of Mahony et al.), along the axes the corrections observe.
//!
//! The 6-D attitude is the same rotation with every heading correction undone:
//! `q₆ = Rz(−H) ⊗ q` with `H` the sum of the heading corrections, exact because each
//! correction acts on the left (in the reference frame) and the inclination correction
//! commutes with a rotation about the vertical.
//!
//! The per-sample path computes no trigonometric function: the strapdown step and the
//! corrections use series that are exact to 10⁻¹⁰ rad at their step sizes
//! ([`super::rotation`]), the dip test compares sines, and the heading error is taken as
//! `sin ε = y/|h|` of the horizontal field `h = (x, y)` (±1 beyond ±90°).
//!
//! **Float type.** The filter, its parts and its state are generic over the float type
//! `T` ([`truenorth_core::Real`], `f64` by default): `QuaternionFilter<f32>` runs the same
//! per-sample path in single precision, for a microcontroller whose FPU has no `f64`. Every
//! constant is written in `f64` and converted with `T::of`, so that for `f64` each
//! operation is the one written. The parameters, the timestamps and the estimate record
//! stay `f64`; how readings in `T` enter is in `quaternion_input`.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use truenorth_core::{
    AttitudeEstimate, AttitudeStatus, Real, Result, STANDARD_GRAVITY_MPS2, Validate,
};

use super::attitude_uncertainty::HeadingCorrection;
use super::quaternion_config::{GyroTiming, QuaternionFilterConfig};
use super::quaternion_gains::{Coefficients, Gains};
use super::quaternion_state::QuaternionFilterState;
use super::rotation::{inv_norm, renormalized, rotation_from_vector, small_rotation};

/// What the parts of one step share.
struct StepContext<T> {
    dt_s: T,
    /// The step falls in the start-up (fast corrections, no bias learning).
    startup: bool,
    gains: Gains<T>,
    at_rest: bool,
    /// Body → NED after the strapdown, before the step's corrections: one rotation matrix
    /// serves every vector rotated in the step.
    rotation: Matrix3<T>,
    /// |ω − b̂|, rad/s.
    rate_rps: T,
}

/// The heading error `sin ε` of the angle ε of the horizontal field `m_ned` (horizontal
/// norm `horizontal`) east of north, and ±1 beyond ±90°: equal to ε to 0.13 % for
/// |ε| < 5°, and bounded, so a disturbed reading that slips past the tests pulls no harder
/// than a 57° error (the angle itself would pull with up to 180°).
fn heading_error<T: Real>(m_ned: &Vector3<T>, horizontal: T) -> T {
    if m_ned.x >= T::zero() {
        m_ned.y / horizontal
    } else {
        T::one().copysign(m_ned.y)
    }
}

/// The quaternion orientation filter (see the module documentation), computing in `T`
/// (`f64` by default; [`QuaternionFilter::with_precision`] for another).
///
/// ```
/// use nalgebra::Vector3;
/// use truenorth_core::{ImuSample, OrientationEstimator};
/// use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};
///
/// let mut f = QuaternionFilter::new(QuaternionFilterConfig::default())?;
/// // A minute level and still, facing magnetic north, with a 1°/s gyro bias on z.
/// for k in 0..6000 {
///     let s = ImuSample::new_9d(
///         0.01 * k as f64,
///         Vector3::new(0.0, 0.0, 1f64.to_radians()),
///         Vector3::new(0.0, 0.0, -9.81),
///         Vector3::new(20.0, 0.0, 45.0),
///     );
///     f.update(&s)?;
/// }
/// let est = f.estimate();
/// assert!(est.status.at_rest);
/// assert!((est.gyro_bias_rps.z - 1f64.to_radians()).abs() < 0.05f64.to_radians());
/// assert!(est.attitude.angle() < 0.5f64.to_radians());
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct QuaternionFilter<T: Real = f64> {
    pub(super) state: QuaternionFilterState<T>,
    /// Derived from the parameters and the sample interval.
    coefficients: Coefficients<T>,
}

impl QuaternionFilter {
    /// A filter with the given parameters, computing in `f64`.
    pub fn new(config: QuaternionFilterConfig) -> Result<Self> {
        Self::with_precision(config)
    }
}

impl<T: Real> QuaternionFilter<T> {
    /// A filter with the given parameters, computing in `T`:
    /// `QuaternionFilter::<f32>::with_precision(config)` for a single-precision FPU. The
    /// parameters are the same `f64` configuration for every `T`.
    pub fn with_precision(config: QuaternionFilterConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::with_state(QuaternionFilterState::initial(config)))
    }

    /// The filter continuing from a valid `state`.
    pub(super) fn with_state(state: QuaternionFilterState<T>) -> Self {
        Self {
            coefficients: Coefficients::new(&state.config),
            state,
        }
    }

    /// The parameters in use.
    pub fn config(&self) -> &QuaternionFilterConfig {
        &self.state.config
    }

    /// The hard-iron offset currently subtracted from the magnetometer (body frame, the
    /// magnetometer's unit), if one was learned.
    pub fn hard_iron_offset(&self) -> Option<Vector3<T>> {
        self.state.hard_iron.offset()
    }

    /// One step of `dt_s`, in the order of the module documentation: the
    /// strapdown, the σ carried through it, the corrections the sample's readings allow
    /// (applied together at the end: at most 10⁻³ rad each), the gyro bias.
    pub(super) fn step(
        &mut self,
        dt_s: T,
        gyr: Vector3<T>,
        acc: Option<Vector3<T>>,
        mag: Option<Vector3<T>>,
    ) -> AttitudeStatus {
        let startup = self.advance_time(dt_s);
        let gains = self.coefficients.gains(dt_s, startup);
        let omega = self.strapdown(dt_s, gyr);
        let rest = &self.coefficients.rest;
        let at_rest = acc.is_some_and(|a| {
            self.state
                .rest
                .update_with(rest, &gyr, &a, mag.as_ref(), dt_s)
        });
        let step = StepContext {
            dt_s,
            startup,
            gains,
            at_rest,
            rotation: *self.state.attitude.to_rotation_matrix().matrix(),
            rate_rps: omega.norm(),
        };
        if self.state.config.sigma {
            self.propagate_uncertainty(&step, &omega);
        }
        let mut status = AttitudeStatus {
            at_rest,
            ..AttitudeStatus::default()
        };
        // The step's correction, a rotation vector in the reference frame.
        let mut correction = Vector3::zeros();
        if let Some(a) = acc
            && a.norm_squared() > T::of(1e-12)
        {
            self.correct_inclination(&step, &a, &mut correction);
            status.accel_used = true;
        }
        self.state.since_mag_s += dt_s;
        if let Some(m) = mag {
            self.correct_heading(&step, &m, &mut correction, &mut status);
        }
        self.apply_correction(&correction);
        if !startup {
            self.estimate_bias(&step, &correction);
        }
        self.state.status = status;
        status
    }

    /// Counts the step's time and says whether it falls in the start-up.
    fn advance_time(&mut self, dt_s: T) -> bool {
        self.state.since_start_s += dt_s;
        self.state.since_start_s < self.coefficients.startup_s
    }

    /// Strapdown: `q ← q ⊗ exp((ω − b̂) dt / 2)` with the rate the gyro's timing calls for.
    /// Returns the body rate less the bias, `ω − b̂`, rad/s.
    fn strapdown(&mut self, dt_s: T, gyr: Vector3<T>) -> Vector3<T> {
        let s = &mut self.state;
        let rate = match s.config.gyro_timing {
            GyroTiming::IntervalMean => gyr,
            GyroTiming::Instantaneous => (s.last_gyr_rps.unwrap_or(gyr) + gyr) * T::of(0.5),
        };
        s.last_gyr_rps = Some(gyr);
        let omega = rate - s.gyro_bias_rps;
        s.attitude = renormalized(s.attitude.into_inner() * rotation_from_vector(&(omega * dt_s)));
        omega
    }

    /// Carries the σ through the strapdown step at body rate `omega` (bias removed).
    fn propagate_uncertainty(&mut self, step: &StepContext<T>, omega: &Vector3<T>) {
        self.state.uncertainty.propagate(
            &self.coefficients.uncertainty,
            step.dt_s,
            omega,
            step.rate_rps,
            &step.rotation,
        );
    }

    /// The in-motion bias estimate's 1/τ as the σ credits it: none while the bias does not
    /// learn from the corrections (start-up, rest).
    fn bias_inv_tau_credited(&self, step: &StepContext<T>) -> T {
        if step.startup || step.at_rest {
            T::zero()
        } else {
            self.state.bias_inv_tau_motion_per_s
        }
    }

    /// Inclination: the specific force `a` rotated into NED and low-passed there should
    /// point up; adds the turn about the horizontal that moves it there to `correction`.
    fn correct_inclination(
        &mut self,
        step: &StepContext<T>,
        a: &Vector3<T>,
        correction: &mut Vector3<T>,
    ) {
        let inv_tau_bias = self.bias_inv_tau_credited(step);
        let loop_constants = &self.coefficients.taus(step.startup).inclination;
        let s = &mut self.state;
        // Linear in the specific force: the body's own accelerations average out over a
        // swing, where an angle (atan of horizontal over vertical) would not.
        let f = step.rotation * a;
        let lp = match s.acc_lowpass_ned_mps2 {
            Some(lp) => {
                let [p11, p12, p21, p22] = step.gains.acc_lowpass;
                let (e, rate) = (lp - f, s.acc_lowpass_rate_ned_mps3);
                s.acc_lowpass_rate_ned_mps3 = e * p21 + rate * p22;
                f + e * p11 + rate * p12
            }
            None => f,
        };
        s.acc_lowpass_ned_mps2 = Some(lp);
        // The horizontal part over g is the tilt the low-passed force shows, linearised
        // (sin θ ≈ θ); a force of g shows at most sin θ = 1, so a horizontal
        // part beyond g·π/2 (a shock, a saturated or corrupt reading) is no tilt the
        // linearised correction describes and counts as π/2 of it: the step's correction
        // stays within π/2 (and within the 0.1 rad `small_rotation` turns per step).
        let max_h = T::of(STANDARD_GRAVITY_MPS2 * core::f64::consts::FRAC_PI_2);
        let h2 = lp.x * lp.x + lp.y * lp.y;
        let scale = if h2 > max_h * max_h {
            max_h / h2.sqrt()
        } else {
            T::one()
        };
        // The whole tilt the low-passed force shows is corrected at once: the low-pass
        // alone sets the dynamics. down × ẑ with down = −lp/g.
        let k = scale * T::of(1.0 / STANDARD_GRAVITY_MPS2);
        correction.x = -lp.y * k;
        correction.y = lp.x * k;
        if s.config.sigma {
            s.uncertainty.accel_corrected(
                loop_constants,
                step.dt_s,
                (correction.x, correction.y),
                inv_tau_bias,
            );
        }
    }

    /// Heading: the field `m`, less any hard iron learned online, rotated into NED should
    /// point north; adds the turn about the vertical that moves it there by `dt/τ_mag` to
    /// `correction`, unless the reading is judged disturbed.
    fn correct_heading(
        &mut self,
        step: &StepContext<T>,
        m: &Vector3<T>,
        correction: &mut Vector3<T>,
        status: &mut AttitudeStatus,
    ) {
        let mag_dt_s = core::mem::replace(&mut self.state.since_mag_s, T::zero());
        let offset = self.learn_hard_iron(step, m, mag_dt_s);
        status.mag_calibrating = offset.is_some();
        let m_ned = step.rotation * (m - offset.unwrap_or_else(Vector3::zeros));
        let horizontal = m_ned.xy().norm();
        if horizontal > T::zero() {
            let undisturbed = self.state.mag_reference.update_with(
                &self.coefficients.mag,
                horizontal,
                m_ned.z,
                step.rate_rps,
                mag_dt_s,
            );
            status.mag_disturbed = !undisturbed;
            if undisturbed && horizontal > T::of(1e-9) * m_ned.z.abs() {
                let k = self.heading_gain(step, mag_dt_s);
                let dz = -k * heading_error(&m_ned, horizontal);
                correction.z = dz;
                // An offset learned from the attitude cannot also tell its error, but the
                // field it corrects still holds the heading where it was adopted.
                if !self.state.config.sigma {
                    // No σ to carry.
                } else if status.mag_calibrating {
                    self.state.uncertainty.heading_held(k);
                } else {
                    self.credit_heading_uncertainty(step, k, dz, &m_ned, horizontal);
                }
                self.undo_heading_correction(dz);
                status.mag_used = true;
            }
        }
        if !status.mag_used && self.state.config.sigma {
            self.state.uncertainty.heading_untrusted();
        }
    }

    /// The hard-iron offset to subtract from the reading `m`, learned while a field
    /// reference is known; `mag_dt_s` is the time since the previous reading.
    fn learn_hard_iron(
        &mut self,
        step: &StepContext<T>,
        m: &Vector3<T>,
        mag_dt_s: T,
    ) -> Option<Vector3<T>> {
        let reference = self.state.mag_reference.reference_ned()?;
        // A gyro bias not yet learned must not count as turning.
        let turning_rps = if step.at_rest {
            T::zero()
        } else {
            step.rate_rps
        };
        self.state.hard_iron.update_with(
            &self.coefficients.hard_iron,
            m,
            &step.rotation,
            &reference,
            turning_rps,
            mag_dt_s,
        )
    }

    /// The heading correction's gain: at rest or in motion, and covering the samples
    /// without a reading since the last one.
    fn heading_gain(&self, step: &StepContext<T>, mag_dt_s: T) -> T {
        let c = &step.gains;
        match (step.at_rest, mag_dt_s == step.dt_s) {
            (true, true) => c.mag_rest,
            (false, true) => c.mag,
            // A reading after samples without one covers their time too.
            (rest, false) => self
                .coefficients
                .taus(step.startup)
                .mag_gain(mag_dt_s, rest),
        }
    }

    /// The σ of heading after a correction with gain `k` by the field `m_ned` (horizontal
    /// part `horizontal`), judged against the learned reference.
    fn credit_heading_uncertainty(
        &mut self,
        step: &StepContext<T>,
        k: T,
        dz: T,
        m_ned: &Vector3<T>,
        horizontal: T,
    ) {
        let Some(reference) = self.state.mag_reference.reference_ned() else {
            return;
        };
        let inv_tau_bias = self.bias_inv_tau_credited(step);
        let c = &self.coefficients;
        let taus = c.taus(step.startup);
        let correction = HeadingCorrection {
            k,
            tau_s: if step.at_rest {
                taus.mag_rest
            } else {
                taus.mag
            },
            dz,
            inv_tau_bias,
        };
        self.state.uncertainty.mag_corrected(
            &c.uncertainty,
            &taus.inclination,
            &correction,
            (horizontal, m_ned.z),
            (reference.x, reference.z),
        );
    }

    /// Adds the heading correction `dz` to the turn the 6-D attitude undoes:
    /// `Rz(−H/2) ← Rz(−dz/2) Rz(−H/2)`, first order and renormalised.
    fn undo_heading_correction(&mut self, dz: T) {
        let (c, sn) = self.state.undo_heading;
        let h = T::of(0.5) * dz;
        let (c, sn) = (c + sn * h, sn - c * h);
        let n = inv_norm(c * c + sn * sn);
        self.state.undo_heading = (c * n, sn * n);
    }

    /// Turns the attitude by the step's `correction` (in the reference frame), and the
    /// low-passed specific force by the same rotation so that it stays in the frame of `q`.
    /// The same rotation (limited as [`small_rotation`] limits it, and norm-preserving):
    /// a first-order turn `lp + c × lp` by the unlimited correction lengthens `lp` by
    /// `√(1 + |c|²)`, and as `c` is proportional to `lp`, a force far beyond g grew
    /// quadratically each step until it overflowed.
    fn apply_correction(&mut self, correction: &Vector3<T>) {
        if *correction != Vector3::zeros() {
            let s = &mut self.state;
            let turn = small_rotation(correction);
            s.attitude = turn * s.attitude;
            s.acc_lowpass_ned_mps2 = s.acc_lowpass_ned_mps2.map(|lp| turn * lp);
            s.acc_lowpass_rate_ned_mps3 = turn * s.acc_lowpass_rate_ned_mps3;
        }
    }

    /// Gyro bias: at rest it follows the rest detector's mean of the raw rate; in motion it
    /// integrates the rate the step's `correction` implies. Clamped to `max_bias_rps`.
    fn estimate_bias(&mut self, step: &StepContext<T>, correction: &Vector3<T>) {
        if step.at_rest {
            self.learn_bias_at_rest(step);
        } else {
            // A bias the estimate lacks makes the strapdown drift, and the corrections
            // turn against the drift: integrating their rate removes it (the integral term
            // of Mahony et al.). Until a rest has measured the bias, it is learned faster,
            // accepting more of the accelerations that leak into the corrections.
            // Body-frame rate of the correction, Rᵀ·correction/dt, times dt/τ.
            let s = &mut self.state;
            s.gyro_bias_rps -= step.rotation.tr_mul(correction) * s.bias_inv_tau_motion_per_s;
        }
        let lim = self.coefficients.max_bias_rps;
        self.state.gyro_bias_rps = self.state.gyro_bias_rps.map(|b| b.clamp(-lim, lim));
    }

    /// The bias at rest, and how well it is known: the in-motion estimate's time constant
    /// moves from `bias_tau_unknown_s` to `bias_tau_motion_s` as rest time accumulates.
    fn learn_bias_at_rest(&mut self, step: &StepContext<T>) {
        let s = &mut self.state;
        let c = &self.coefficients;
        let k = step.gains.bias_rest;
        s.gyro_bias_rps += (s.rest.gyro_mean() - s.gyro_bias_rps) * k;
        if s.config.sigma {
            s.uncertainty.at_rest(&c.uncertainty, k);
        }
        let known_after_s = c.bias_known_after_rest_s;
        if s.rest_s < known_after_s {
            s.rest_s += step.dt_s;
            let known = (s.rest_s / known_after_s).min(T::one());
            let tau = c.bias_tau_unknown_s + known * c.bias_tau_change_s;
            s.bias_inv_tau_motion_per_s = T::one() / tau;
        }
    }

    /// The estimate after the last sample (before the first: the initial attitude, time
    /// NaN): the attitude, the 6-D attitude with every heading correction undone, the bias
    /// and σ, as the `f64` record every estimator returns. Built from the state when asked
    /// for, so that an update that is not read costs none of it.
    pub(super) fn estimate_now(&self) -> AttitudeEstimate {
        let s = &self.state;
        AttitudeEstimate {
            t_s: s.clock.last_s().unwrap_or(f64::NAN),
            attitude: attitude_f64(&s.attitude),
            attitude_6d: Some(attitude_f64(&self.attitude_6d())),
            gyro_bias_rps: s.gyro_bias_rps.map(T::to_f64),
            sigma_rad: self.sigma_rad().map(|v| v.map(T::to_f64)),
            status: s.status,
        }
    }

    /// The attitude after the last sample, body → NED (Hamilton, scalar first): the
    /// estimate's `attitude`, in the filter's float type.
    pub fn attitude(&self) -> UnitQuaternion<T> {
        self.state.attitude
    }

    /// The 6-D attitude (gyro and accelerometer only, heading relative to the start): the
    /// estimate's `attitude_6d`, in the filter's float type.
    pub fn attitude_6d(&self) -> UnitQuaternion<T> {
        let (c, sn) = self.state.undo_heading;
        if (c, sn) == (T::one(), T::zero()) {
            // No heading correction yet (or since a gap): the attitude itself, bit for bit.
            return self.state.attitude;
        }
        let undo = UnitQuaternion::new_unchecked(Quaternion::new(c, T::zero(), T::zero(), sn));
        undo * self.state.attitude
    }

    /// The gyro bias estimate, rad/s, body axes: the estimate's `gyro_bias_rps`, in the
    /// filter's float type.
    pub fn gyro_bias_rps(&self) -> Vector3<T> {
        self.state.gyro_bias_rps
    }

    /// One σ of the attitude error about north, east and down, rad: the estimate's
    /// `sigma_rad`, in the filter's float type; `None` when the configuration switches the
    /// σ off.
    pub fn sigma_rad(&self) -> Option<Vector3<T>> {
        self.state
            .config
            .sigma
            .then(|| self.state.uncertainty.sigma_rad())
    }
}

/// `q` as an `f64` quaternion (exact: every `T` converts to `f64` exactly).
fn attitude_f64<T: Real>(q: &UnitQuaternion<T>) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::from(q.coords.map(T::to_f64)))
}
