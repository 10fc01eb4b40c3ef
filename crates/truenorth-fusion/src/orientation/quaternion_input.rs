//! How readings enter the [`crate::QuaternionFilter`]: their checks, the time step and its
//! gaps, the first sample; the per-sample entry for any float type
//! ([`QuaternionFilter::update_readings`]) and, for `f64`, the [`OrientationEstimator`],
//! [`Persistent`] and [`Default`] every estimator has.
//!
//! The traits stay `f64`, as do [`ImuSample`] and [`AttitudeEstimate`]: a
//! `QuaternionFilter<f32>` takes its readings as `f32` vectors through `update_readings`
//! and gives its attitude in `f32` ([`QuaternionFilter::attitude`]). Timestamps are `f64`
//! in both (an `f32` count of seconds loses the millisecond after 4.6 hours).

use nalgebra::Vector3;
use truenorth_core::{
    AttitudeEstimate, AttitudeStatus, Error, ImuSample, OrientationEstimator, Persistent, Real,
    Result, Validate,
};

use super::quaternion_config::QuaternionFilterConfig;
use super::quaternion_filter::QuaternionFilter;
use super::quaternion_state::QuaternionFilterState;
use super::real_checks::{check_finite_time, check_finite3_in};
use super::sample_bounds::check_bounds;
use super::time_gap::Step;
use super::triad::attitude_from;

impl<T: Real> QuaternionFilter<T> {
    /// One sample in the filter's float type: the time `t_s`, the gyro's rates (rad/s) and,
    /// when the sample has them, the accelerometer's specific force (m/s²) and the
    /// magnetometer's field (any unit), all body axes. Returns what the filter made of
    /// the sample; the attitude is then [`Self::attitude`]. The rules of
    /// [`OrientationEstimator::update`] apply: a non-finite value, a reading beyond any
    /// sensor's range or a timestamp that does not increase is an error and changes nothing.
    ///
    /// ```
    /// use nalgebra::Vector3;
    /// use truenorth_fusion::{QuaternionFilter, QuaternionFilterConfig};
    ///
    /// let mut f = QuaternionFilter::<f32>::with_precision(QuaternionFilterConfig::default())?;
    /// for k in 0..1000 {
    ///     f.update_readings(
    ///         0.01 * k as f64,
    ///         Vector3::new(0.0, 0.0, 0.0),
    ///         Some(Vector3::new(0.0, 0.0, -9.81)),
    ///         Some(Vector3::new(20.0, 0.0, 45.0)),
    ///     )?;
    /// }
    /// assert!(f.attitude().angle() < 1e-3);
    /// # Ok::<(), truenorth_core::Error>(())
    /// ```
    pub fn update_readings(
        &mut self,
        t_s: f64,
        gyr_rps: Vector3<T>,
        acc_mps2: Option<Vector3<T>>,
        mag: Option<Vector3<T>>,
    ) -> Result<AttitudeStatus> {
        check_finite_time("timestamp t_s", t_s)?;
        check_finite3_in("gyro reading", &gyr_rps)?;
        if let Some(a) = &acc_mps2 {
            check_finite3_in("accelerometer reading", a)?;
        }
        if let Some(m) = &mag {
            check_finite3_in("magnetometer reading", m)?;
        }
        let mag = if self.state.config.use_mag { mag } else { None };
        self.update_finite(t_s, gyr_rps, acc_mps2, mag)
    }

    /// Back to the state before any sample, with the same parameters
    /// ([`OrientationEstimator::reset`] for `f64`).
    pub fn start_over(&mut self) {
        *self = Self::with_state(QuaternionFilterState::initial(self.state.config));
    }

    /// One sample of finite readings (the magnetometer left out when it is not used).
    fn update_finite(
        &mut self,
        t_s: f64,
        gyr: Vector3<T>,
        acc: Option<Vector3<T>>,
        mag: Option<Vector3<T>>,
    ) -> Result<AttitudeStatus> {
        // Readings beyond any sensor's range could overflow the update; they are refused
        // before anything changes, so the update needs no copy of the state to fall back to.
        let mut clock = self.state.clock;
        let dt = clock.dt_s(t_s)?;
        check_bounds(&gyr, acc.as_ref(), mag.as_ref(), dt)?;
        let step = dt.map(|d| self.state.gaps.classify(d)).transpose()?;
        self.state.clock = clock;
        if let Some(step) = step {
            self.state.gaps.count(step);
        }
        if let (Some(gap_s), Some(Step::Gap)) = (dt, step) {
            return Ok(self.restart(gap_s, gyr, acc, mag));
        }
        let Some(dt_s) = dt else {
            self.first_sample(gyr, acc, mag);
            return Ok(AttitudeStatus::default());
        };
        let status = self.step(T::of(dt_s), gyr, acc, mag);
        debug_assert!(self.state.attitude.coords.iter().all(|v| v.is_finite()));
        Ok(status)
    }

    /// The first sample: the attitude from its accelerometer (and magnetometer) unless one
    /// was given.
    fn first_sample(&mut self, gyr: Vector3<T>, acc: Option<Vector3<T>>, mag: Option<Vector3<T>>) {
        let s = &mut self.state;
        if !s.initialised
            && let Some(q) = acc.and_then(|a| attitude_from(&a, mag.as_ref()))
        {
            s.attitude = q;
            s.initialised = true;
        }
        s.last_gyr_rps = Some(gyr);
        s.status = AttitudeStatus::default();
    }

    /// Starts again after a gap of `gap_s` that the gyro cannot bridge: the attitude from
    /// this sample's accelerometer (and magnetometer) when it has one, the start-up's fast
    /// corrections again, the σ widened; the learned bias, field reference and hard iron
    /// are properties of the sensor and carry over.
    fn restart(
        &mut self,
        gap_s: f64,
        gyr: Vector3<T>,
        acc: Option<Vector3<T>>,
        mag: Option<Vector3<T>>,
    ) -> AttitudeStatus {
        let s = &mut self.state;
        if let Some(q) = acc.and_then(|a| attitude_from(&a, mag.as_ref())) {
            s.attitude = q;
        }
        s.undo_heading = (T::one(), T::zero());
        s.acc_lowpass_ned_mps2 = None;
        s.acc_lowpass_rate_ned_mps3 = Vector3::zeros();
        s.last_gyr_rps = Some(gyr);
        s.since_mag_s = T::zero();
        s.since_start_s = T::zero();
        s.uncertainty.restart(false, gap_s);
        s.rest.reset();
        s.status = AttitudeStatus {
            gap: true,
            ..AttitudeStatus::default()
        };
        s.status
    }
}

impl Default for QuaternionFilter {
    /// The filter with [`QuaternionFilterConfig::default`], as the calibrators' `Default`.
    fn default() -> Self {
        // The default configuration passes validation (held by the test
        // `the_default_filter_is_the_default_configuration`), so this cannot fail.
        Self::new(QuaternionFilterConfig::default())
            .expect("the default quaternion filter configuration is valid")
    }
}

impl OrientationEstimator for QuaternionFilter {
    /// Needs a gyro triad; the accelerometer and magnetometer triads may be absent on any
    /// sample (a slower sensor). A non-finite value, a reading beyond any sensor's range
    /// (gyro 10⁴ rad/s, accelerometer 10⁶ m/s², field 10¹²), a timestamp that does not
    /// increase or a gap over 10⁶ s is an error and changes nothing. A step longer than
    /// `max_gap_s` restarts the attitude from the sample (status `gap`); a step that would
    /// make such gaps the majority of the steps is an [`Error::Implausible`] time base.
    fn update(&mut self, sample: &ImuSample) -> Result<AttitudeEstimate> {
        let gyr = sample.gyr_rps.as_xyz().ok_or(Error::Unsupported {
            reason: "the quaternion filter needs a three-axis gyro; use the Euler detector for two gyros",
        })?;
        let acc = sample.acc_mps2.as_xyz();
        let mag = if self.state.config.use_mag {
            sample.mag.as_xyz()
        } else {
            None
        };
        // The usual sample is a finite 9-D one: test it in one pass, and let the sample's
        // own check name the offending reading otherwise.
        let finite = sample.t_s.is_finite()
            && gyr.iter().all(|v| v.is_finite())
            && acc.is_some_and(|a| a.iter().all(|v| v.is_finite()))
            && sample
                .mag
                .as_xyz()
                .is_some_and(|m| m.iter().all(|v| v.is_finite()));
        if !finite {
            sample.check_finite()?;
        }
        self.update_finite(sample.t_s, gyr, acc, mag)?;
        Ok(self.estimate())
    }

    /// The estimate after the last sample; before the first, the initial attitude with
    /// its σ.
    fn estimate(&self) -> AttitudeEstimate {
        self.estimate_now()
    }

    /// Back to the state before any sample, with the same parameters.
    fn reset(&mut self) {
        self.start_over();
    }
}

impl Persistent for QuaternionFilter {
    type State = QuaternionFilterState;
    /// 2: the inclination low-pass became second order (its rate joined the state, its
    /// time constant replaced `acc_lowpass_s`) and the state keeps the last status instead
    /// of the last estimate.
    const SNAPSHOT_VERSION: u32 = 2;

    fn state(&self) -> QuaternionFilterState {
        self.state
    }

    /// Refuses a state that is not valid (see [`QuaternionFilterState`]'s `validate`).
    fn from_state(state: QuaternionFilterState) -> Result<Self> {
        state.validate()?;
        Ok(Self::with_state(state))
    }
}
