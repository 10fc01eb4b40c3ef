//! Online hard-iron re-estimation: a magnet (or a magnetised part) that becomes attached to
//! the sensor adds a field that is constant in the *body* frame, `m = Rᵀ m_ref + b`; the
//! earth's field is constant in the *reference* frame. Given the attitude `R` (which the
//! gyro and accelerometer keep accurate for minutes while heading runs on the gyro alone),
//! the residual `r = m − Rᵀ m_ref` is the offset `b` itself.
//!
//! Whether the residual is such an offset is told by rotation: an offset fixed to the body
//! keeps `r` constant while the body turns, whereas a field fixed in the room (a magnet the
//! sensor moves past, a steel beam) turns in the body frame with the body, and a field
//! that varies from place to place changes as the sensor moves. So an offset is adopted
//! only after the residual has stayed consistent (small spread about its running mean)
//! through a minimum turn of the body; it is then followed while it stays consistent, and
//! dropped when the residual of the raw reading returns to zero (the magnet was removed).
//!
//! This is the hard-iron model of every compass calibration (e.g. the ellipsoid fits in
//! `truenorth-calib`) estimated from the attitude instead of from the shape of the locus:
//! it needs far less rotation than a sphere fit, because the attitude supplies the
//! direction of the earth's field. Filters such as VQF (Laidig & Seel, Information Fusion
//! 91, 2023, §IV-D) and Fusion only reject such a field.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Real, Result, Validate, check_positive, check_range};

use super::min_max::at_most;
use super::real_checks::{check_finite3_in, check_range_in};

/// Thresholds of the [`HardIronEstimator`]. Field quantities are relative to the reference
/// field's norm, so they hold for any magnetometer unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct HardIronConfig {
    /// Estimate the offset at all (default `true`).
    pub enabled: bool,
    /// Time constant of the running mean and spread of the residual, s (default 3).
    pub mean_tau_s: f64,
    /// Smallest offset taken as a hard-iron change, relative to the reference norm
    /// (default 0.15). An offset not much larger than the disturbance tolerance (0.1) is
    /// better rejected than estimated, since its estimate's own error (the residual's
    /// spread, ≈ 5 % of the field) is a large part of it.
    pub min_offset_rel: f64,
    /// Largest RMS spread of the residual about its mean, relative to the reference norm,
    /// for the residual to count as one body-fixed offset (default 0.08). The budget of a
    /// body-fixed offset's residual in motion, as a fraction of a 44 µT field: the
    /// magnetometer's noise (√3 × 0.7 µT, 2.8 %), its latency against the gyro while turning
    /// (≈ 14 ms × 1.5 rad/s × 44 µT, 2 %), the heading drift while the field is rejected
    /// (2° of the 16 µT horizontal field, 1.3 %) and the inclination error (1° of the 41 µT
    /// vertical one, 1.6 %) add to ≈ 4 % RSS; twice that leaves room for the spread
    /// estimate's own scatter. A field fixed in the room and turning with respect to the
    /// body spreads by a good part of its size, 20 % of the field or more for a disturbance
    /// this estimator would take as an offset (`min_offset_rel`).
    pub max_spread_rel: f64,
    /// Rotation of the body, rad, through which the residual must stay consistent before
    /// the offset is adopted (default 90°).
    pub min_turn_rad: f64,
}

impl Default for HardIronConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            mean_tau_s: 3.0,
            min_offset_rel: 0.15,
            max_spread_rel: 0.08,
            min_turn_rad: 90f64.to_radians(),
        }
    }
}

impl Validate for HardIronConfig {
    /// Time constant and tolerances positive, the minimum turn in [0, 100] rad.
    fn validate(&self) -> Result<()> {
        check_positive("hard_iron.mean_tau_s", self.mean_tau_s)?;
        check_positive("hard_iron.min_offset_rel", self.min_offset_rel)?;
        check_positive("hard_iron.max_spread_rel", self.max_spread_rel)?;
        check_range("hard_iron.min_turn_rad", self.min_turn_rad, 0.0, 100.0)?;
        Ok(())
    }
}

/// The thresholds of a [`HardIronConfig`] in the estimator's float type, squared where they
/// are compared with squares: converted once by the filter that owns the estimator, not
/// per sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HardIronThresholds<T> {
    min_offset2: T,
    max_spread2: T,
    min_turn_rad: T,
    /// Twice the statistics' time constant: the consistent time an offset needs.
    min_consistent_s: T,
    /// `1/mean_tau_s`, 1/s.
    inv_mean_tau: T,
}

impl<T: Real> HardIronThresholds<T> {
    pub(crate) fn of(config: &HardIronConfig) -> Self {
        let (min, max) = (T::of(config.min_offset_rel), T::of(config.max_spread_rel));
        Self {
            min_offset2: min * min,
            max_spread2: max * max,
            min_turn_rad: T::of(config.min_turn_rad),
            min_consistent_s: T::of(2.0 * config.mean_tau_s),
            inv_mean_tau: T::of(1.0 / config.mean_tau_s),
        }
    }
}

/// The running residual statistics and the adopted offset, in the float type `T` (the
/// thresholds stay `f64`, converted for each update; the filter converts them once).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
// `Real` includes serde's bounds on `T`.
#[serde(bound = "")]
pub struct HardIronEstimator<T: Real = f64> {
    config: HardIronConfig,
    mean: Vector3<T>,
    spread2: T,
    turned_rad: T,
    consistent_s: T,
    primed: bool,
    offset: Option<Vector3<T>>,
    /// The running statistics' gain for the last interval (recomputed when it changes).
    gain: (T, T),
}

impl HardIronEstimator {
    /// No offset yet; invalid thresholds are refused.
    pub fn new(config: HardIronConfig) -> Result<Self> {
        Self::with_precision(config)
    }
}

impl<T: Real> HardIronEstimator<T> {
    /// As [`HardIronEstimator::new`], computing in `T` (`HardIronEstimator::<f32>::with_precision(config)`).
    pub fn with_precision(config: HardIronConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::with_config(config))
    }

    /// No offset yet, for thresholds already validated (by the filter's config).
    pub(crate) fn with_config(config: HardIronConfig) -> Self {
        Self {
            config,
            mean: Vector3::zeros(),
            spread2: T::zero(),
            turned_rad: T::zero(),
            consistent_s: T::zero(),
            primed: false,
            offset: None,
            gain: (T::zero(), T::zero()),
        }
    }

    /// Forgets the statistics and any adopted offset; the thresholds stay.
    pub fn reset(&mut self) {
        *self = Self::with_config(self.config);
    }

    /// Takes one raw field reading `m` (body frame), the attitude `r` (body → level frame of
    /// magnetic north, as a rotation matrix) at the time of the reading, the reference field in that frame, the
    /// body's rotation rate (pass 0 while the sensor is known to rest: a gyro bias not yet
    /// learned must not count as turning) and the time since the previous reading. Returns the offset to
    /// subtract from `m`, if one is adopted.
    pub fn update(
        &mut self,
        m: &Vector3<T>,
        r: &Matrix3<T>,
        reference_ned: &Vector3<T>,
        rate_rps: T,
        dt_s: T,
    ) -> Option<Vector3<T>> {
        let th = HardIronThresholds::of(&self.config);
        self.update_with(&th, m, r, reference_ned, rate_rps, dt_s)
    }

    /// [`Self::update`] with the thresholds already converted (`th` of this estimator's
    /// configuration).
    pub(crate) fn update_with(
        &mut self,
        th: &HardIronThresholds<T>,
        m: &Vector3<T>,
        r: &Matrix3<T>,
        reference_ned: &Vector3<T>,
        rate_rps: T,
        dt_s: T,
    ) -> Option<Vector3<T>> {
        if !self.config.enabled {
            return None;
        }
        let r = m - r.tr_mul(reference_ned);
        if !self.primed {
            self.mean = r;
            self.primed = true;
            return self.offset;
        }
        if self.gain.0 != dt_s {
            self.gain = (dt_s, at_most(dt_s * th.inv_mean_tau, T::one()));
        }
        let k = self.gain.1;
        self.mean += (r - self.mean) * k;
        self.spread2 += ((r - self.mean).norm_squared() - self.spread2) * k;
        let n2 = reference_ned.norm_squared();
        if self.mean.norm_squared() < T::of(0.25) * th.min_offset2 * n2 {
            // The raw reading agrees with the earth's field again: the magnet is gone.
            // (No consistency is asked for: removing it is a transient.)
            self.offset = None;
            self.turned_rad = T::zero();
            self.consistent_s = T::zero();
            return None;
        }
        if self.spread2 > th.max_spread2 * n2 {
            // Not one body-fixed offset (or the attitude is off): keep what was adopted.
            self.turned_rad = T::zero();
            self.consistent_s = T::zero();
            return self.offset;
        }
        self.turned_rad += rate_rps * dt_s;
        self.consistent_s += dt_s;
        // Only a residual that stayed consistent while the body turned tells a body-fixed
        // offset from a heading error (at rest both are constant), so the offset is adopted
        // and followed only then, and only once the running statistics span twice their
        // time constant of such a period.
        if self.turned_rad >= th.min_turn_rad
            && self.consistent_s >= th.min_consistent_s
            && self.mean.norm_squared() > th.min_offset2 * n2
        {
            self.offset = Some(self.mean);
        }
        self.offset
    }

    /// The adopted offset (body frame, sensor unit), if any.
    pub fn offset(&self) -> Option<Vector3<T>> {
        self.offset
    }

    /// Checks a restored estimator against the thresholds `config` of its filter: the same
    /// thresholds, finite statistics, spread, turn and time ≥ 0.
    pub(crate) fn check(&self, config: &HardIronConfig) -> Result<()> {
        if self.config != *config {
            return Err(Error::InvalidSnapshot {
                reason: "the hard-iron estimator's thresholds differ from the filter's",
            });
        }
        check_finite3_in("hard_iron.mean", &self.mean)?;
        if let Some(b) = &self.offset {
            check_finite3_in("hard_iron.offset", b)?;
        }
        check_range_in("hard_iron.spread2", self.spread2, 0.0, f64::MAX)?;
        check_range_in("hard_iron.turned_rad", self.turned_rad, 0.0, f64::MAX)?;
        check_range_in("hard_iron.consistent_s", self.consistent_s, 0.0, f64::MAX)?;
        check_range_in("hard_iron.gain", self.gain.1, 0.0, 1.0)?;
        check_range_in("hard_iron.gain interval", self.gain.0, 0.0, f64::MAX)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use truenorth_core::EulerZyx;

    fn reference() -> Vector3<f64> {
        Vector3::new(16.0, 0.0, 41.0)
    }

    fn attitude(t: f64) -> nalgebra::UnitQuaternion<f64> {
        EulerZyx {
            yaw_rad: 0.9 * t,
            pitch_rad: 0.5 * (0.7 * t).sin(),
            roll_rad: 0.6 * (0.5 * t).cos(),
        }
        .to_quaternion()
    }

    proptest! {
        /// A body-fixed offset of any direction and of 0.2–2 × the field is adopted while the
        /// body turns, and its estimate is the offset.
        #[test]
        fn a_body_fixed_offset_is_learned(
            dir in proptest::array::uniform3(-1.0f64..1.0), size in 0.2f64..2.0,
        ) {
            let d = Vector3::from(dir);
            prop_assume!(d.norm() > 0.1);
            let b = d.normalize() * size * reference().norm();
            let mut h = HardIronEstimator::new(HardIronConfig::default()).unwrap();
            let mut got = None;
            for k in 0..3000 {
                let t = k as f64 * 0.01;
                let q = attitude(t);
                let m = q.inverse_transform_vector(&reference()) + b;
                got = h.update(&m, q.to_rotation_matrix().matrix(), &reference(), 1.0, 0.01);
            }
            let got = got.expect("adopted");
            prop_assert!((got - b).norm() < 1e-6 * b.norm());
        }

        /// A field fixed in the room (it turns with respect to the body) is never adopted,
        /// from 20 % of the field (the smallest offset adopted, 15 %, with a margin) up.
        #[test]
        fn a_room_fixed_disturbance_is_not_adopted(
            dir in proptest::array::uniform3(-1.0f64..1.0), size in 0.2f64..2.0,
        ) {
            let d = Vector3::from(dir);
            prop_assume!(d.norm() > 0.1);
            let disturbance = d.normalize() * size * reference().norm();
            let mut h = HardIronEstimator::new(HardIronConfig::default()).unwrap();
            for k in 0..3000 {
                let t = k as f64 * 0.01;
                let q = attitude(t);
                let m = q.inverse_transform_vector(&(reference() + disturbance));
                prop_assert!(h.update(&m, q.to_rotation_matrix().matrix(), &reference(), 1.0, 0.01).is_none(), "adopted at t = {t}");
            }
        }
    }

    #[test]
    fn a_removed_magnet_is_dropped() {
        // Adopted within 10 s of turning at 1 rad/s, dropped once the magnet is gone.
        let b = Vector3::new(-3.0, 0.5, 27.0);
        let mut h = HardIronEstimator::new(HardIronConfig::default()).unwrap();
        for k in 0..6000 {
            let t = k as f64 * 0.01;
            let q = attitude(t);
            let offset = if t < 30.0 { b } else { Vector3::zeros() };
            let m = q.inverse_transform_vector(&reference()) + offset;
            let got = h.update(&m, q.to_rotation_matrix().matrix(), &reference(), 1.0, 0.01);
            if (20.0..30.0).contains(&t) {
                assert!(got.is_some(), "t = {t}");
            }
        }
        assert!(h.offset().is_none());
    }
}
