//! The [`QuaternionFilterState`]: everything the [`crate::QuaternionFilter`] carries from one
//! sample to the next, its parameters included, as plain data (as VQF's `getState` /
//! `setState`), so that a filter can be saved and later continue exactly where it stopped.

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{
    AttitudeEstimate, AttitudeStatus, Error, Real, Result, TimeStep, Validate, check_finite,
    check_finite3, check_range,
};

use super::attitude_uncertainty::AttitudeUncertainty;
use super::hard_iron::HardIronEstimator;
use super::mag_reference::MagReference;
use super::quaternion_config::QuaternionFilterConfig;
use super::real_checks::{check_finite_in, check_finite3_in, check_range_in};
use super::rest_detector::RestDetector;
use super::time_gap::GapMonitor;

/// Largest departure of a restored attitude from a unit quaternion in `f64` (serialisation
/// keeps it within a few units of 10⁻¹⁶).
const UNIT_NORM_TOL: f64 = 1e-9;

/// Largest departure of a restored attitude from a unit quaternion in `f32`, in units of
/// its machine epsilon (1.2·10⁻⁷): the filter renormalises every step, leaving a few.
const UNIT_NORM_TOL_EPS: f64 = 16.0;

/// The unit-norm tolerance for a state in `T`: [`UNIT_NORM_TOL`], or a few of `T`'s
/// epsilon when that is coarser.
fn unit_norm_tol<T: Real>() -> f64 {
    UNIT_NORM_TOL.max(UNIT_NORM_TOL_EPS * T::default_epsilon().to_f64())
}

/// What the [`crate::QuaternionFilter`] carries from one sample to the next (see the
/// module documentation), the filter's own quantities in its float type `T`; the
/// parameters, the timestamps and the estimate record stay `f64`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
// `Real` includes serde's bounds on `T`.
#[serde(bound = "")]
pub struct QuaternionFilterState<T: Real = f64> {
    /// The parameters.
    pub config: QuaternionFilterConfig,
    /// The attitude `q`, body → NED.
    pub attitude: UnitQuaternion<T>,
    /// `Rz(−H/2)` as (cos, sin) of `−H/2`, `H` the sum of the heading corrections: what
    /// turns the attitude into the 6-D one.
    pub undo_heading: (T, T),
    /// The gyro bias estimate, rad/s, body axes.
    pub gyro_bias_rps: Vector3<T>,
    /// The low-passed specific force in NED, m/s²; `None` before the first reading.
    pub acc_lowpass_ned_mps2: Option<Vector3<T>>,
    /// The rate of change of the low-passed specific force (the low-pass's second state),
    /// m/s³.
    pub acc_lowpass_rate_ned_mps3: Vector3<T>,
    /// Time spent at rest since the start, s (counted up to `bias_known_after_rest_s`):
    /// how well the bias is known.
    pub rest_s: T,
    /// `1/τ` of the in-motion bias estimate for the rest time so far, 1/s.
    pub bias_inv_tau_motion_per_s: T,
    /// The previous gyro reading, rad/s (for [`crate::GyroTiming::Instantaneous`]).
    pub last_gyr_rps: Option<Vector3<T>>,
    /// Time since the last magnetometer reading, s.
    pub since_mag_s: T,
    /// Time since the start (or the last gap), s: the start-up runs while it is below
    /// `startup_s`.
    pub since_start_s: T,
    /// The attitude has been taken from a reading (or given in the parameters).
    pub initialised: bool,
    /// The σ of the attitude, propagated alongside it.
    pub uncertainty: AttitudeUncertainty<T>,
    /// What the filter made of the last sample (default before the first): with the rest of
    /// the state, the estimate after it, which is built only when it is asked for.
    pub status: AttitudeStatus,
    /// The time of the last sample.
    pub clock: TimeStep,
    /// The steps taken and the gaps among them.
    pub gaps: GapMonitor,
    /// Rest detection.
    pub rest: RestDetector<T>,
    /// The learned field reference (magnetic-disturbance detection).
    pub mag_reference: MagReference<T>,
    /// The hard iron learned online.
    pub hard_iron: HardIronEstimator<T>,
}

impl<T: Real> QuaternionFilterState<T> {
    /// The state before any sample, for validated parameters.
    pub(crate) fn initial(config: QuaternionFilterConfig) -> Self {
        Self {
            config,
            attitude: initial_attitude(&config),
            undo_heading: (T::one(), T::zero()),
            gyro_bias_rps: Vector3::zeros(),
            acc_lowpass_ned_mps2: None,
            acc_lowpass_rate_ned_mps3: Vector3::zeros(),
            rest_s: T::zero(),
            bias_inv_tau_motion_per_s: T::of(1.0 / config.bias_tau_unknown_s),
            last_gyr_rps: None,
            since_mag_s: T::zero(),
            since_start_s: T::zero(),
            initialised: config.initial_attitude.is_some(),
            uncertainty: AttitudeUncertainty::new(config.uncertainty, !config.use_mag),
            status: AttitudeStatus::default(),
            clock: TimeStep::new(),
            gaps: GapMonitor::new(config.max_gap_s),
            rest: RestDetector::with_config(config.rest),
            mag_reference: MagReference::with_config(config.mag),
            hard_iron: HardIronEstimator::with_config(config.hard_iron),
        }
    }
}

impl<T: Real> Validate for QuaternionFilterState<T> {
    /// Valid parameters; a unit attitude and heading undo; finite vectors; a bias within
    /// `max_bias_rps`; times ≥ 0; parts built for these parameters.
    fn validate(&self) -> Result<()> {
        let cfg = &self.config;
        cfg.validate()?;
        let q = self.attitude.as_ref();
        let tol = unit_norm_tol::<T>();
        for v in q.coords.iter() {
            check_finite_in("attitude component", *v)?;
        }
        check_range_in("attitude norm", q.norm(), 1.0 - tol, 1.0 + tol)?;
        let (c, s) = self.undo_heading;
        check_finite_in("undo_heading cos", c)?;
        check_finite_in("undo_heading sin", s)?;
        let n = (c * c + s * s).sqrt();
        check_range_in("undo_heading norm", n, 1.0 - tol, 1.0 + tol)?;
        check_finite3_in("gyro_bias_rps", &self.gyro_bias_rps)?;
        if self.gyro_bias_rps.amax() > T::of(cfg.max_bias_rps) {
            return Err(Error::InvalidSnapshot {
                reason: "the gyro bias exceeds max_bias_rps",
            });
        }
        for v in [
            self.acc_lowpass_ned_mps2,
            Some(self.acc_lowpass_rate_ned_mps3),
            self.last_gyr_rps,
        ]
        .iter()
        .flatten()
        {
            check_finite3_in("saved vector", v)?;
        }
        for (what, v) in [
            ("rest_s", self.rest_s),
            ("bias_inv_tau_motion_per_s", self.bias_inv_tau_motion_per_s),
            ("since_mag_s", self.since_mag_s),
            ("since_start_s", self.since_start_s),
        ] {
            check_range_in(what, v, 0.0, f64::MAX)?;
        }
        if let Some(t) = self.clock.last_s() {
            check_finite("time of the last sample", t)?;
        }
        self.uncertainty.check(&cfg.uncertainty)?;
        self.gaps.check(cfg.max_gap_s)?;
        self.rest.check(&cfg.rest)?;
        self.mag_reference.check(&cfg.mag)?;
        self.hard_iron.check(&cfg.hard_iron)
    }
}

/// A saved estimate's numbers: finite, σ ≥ 0.
pub(crate) fn check_estimate(e: &AttitudeEstimate) -> Result<()> {
    check_finite("estimate t_s", e.t_s)?;
    for q in core::iter::once(&e.attitude).chain(&e.attitude_6d) {
        for v in q.coords.iter() {
            check_finite("estimate attitude component", *v)?;
        }
    }
    check_finite3("estimate gyro_bias_rps", &e.gyro_bias_rps)?;
    if let Some(sigma) = &e.sigma_rad {
        for v in sigma.iter() {
            check_range("estimate sigma_rad", *v, 0.0, f64::MAX)?;
        }
    }
    Ok(())
}

/// The attitude the parameters start from: the given one, or level and facing north until
/// the first reading.
fn initial_attitude<T: Real>(config: &QuaternionFilterConfig) -> UnitQuaternion<T> {
    match config.initial_attitude {
        Some([w, x, y, z]) => UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            T::of(w),
            T::of(x),
            T::of(y),
            T::of(z),
        )),
        None => UnitQuaternion::identity(),
    }
}
