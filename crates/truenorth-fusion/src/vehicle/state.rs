//! The vehicle estimator's state as plain data: saved with
//! [`Persistent::state`] / [`Persistent::snapshot`], it rebuilds an estimator that continues
//! bit for bit where the saved one stopped (see ARCHITECTURE.md, "Persistence").
//!
//! What the configuration determines (the coefficients, the steered wheels' track table,
//! the gates' settings) is rebuilt from it, not saved. A state read back is checked before
//! it is used: the configuration validates, every number that must be finite is, the
//! filters' covariances are symmetric with non-negative variances, and the compass
//! calibrators accept their own states; anything else is [`Error::InvalidSnapshot`].

use serde::{Deserialize, Serialize};
use truenorth_core::extended_float::check_plain_numbers_finite;
use truenorth_core::{Error, NavEstimate, Persistent, Result, TimeStep, Validate};

use super::compass_learning::{CompassLearner, CompassLearnerState};
use super::compass_monitor::{CompassFix, CompassMonitor, CompassMonitorState};
use super::config::VehicleConfig;
use super::estimator::{Coefficients, VehicleEstimator};
use super::nav_filter::{DIM, NavFilter};
use super::tracking::VehicleTracking;
use super::wheel_odometry::{TrackModel, WheelOdometry, WheelOdometryState};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Everything a [`VehicleEstimator`] needs to continue bit for bit: its configuration, both
/// filters, the last estimate, the clock, the wheels', compass's and compass learner's
/// running values, and the estimator's own bookkeeping.
///
/// ```
/// use truenorth_core::{HeadingEstimator, Persistent, VehicleSample};
/// use truenorth_fusion::{VehicleConfig, VehicleEstimator};
///
/// let mut nav = VehicleEstimator::new(VehicleConfig::default())?;
/// for k in 0..50 {
///     let t_s = 0.1 * f64::from(k);
///     nav.update(&VehicleSample::at(t_s).with_wheels(5.0 * t_s, 5.0 * t_s).with_gyro(0.01))?;
/// }
/// let mut again = VehicleEstimator::restore(nav.snapshot())?;
/// let row = VehicleSample::at(5.0).with_wheels(25.0, 25.1).with_gyro(0.02);
/// assert_eq!(again.update(&row)?, nav.update(&row)?);
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VehicleEstimatorState {
    /// The configuration (validated again when the state is read back).
    pub config: VehicleConfig,
    /// The filter as the estimator started, which [`truenorth_core::HeadingEstimator::reset`]
    /// returns to.
    pub initial_filter: NavFilter,
    /// The filter now: nominal values and error covariance.
    pub filter: NavFilter,
    /// The last estimate published.
    pub estimate: NavEstimate,
    /// The last accepted timestamp.
    pub clock: TimeStep,
    /// The compass calibration the estimator started with, if any (reset returns to it).
    pub initial_fix: Option<CompassFix>,
    /// The wheels' last reading and averaged curvature.
    pub wheels: WheelOdometryState,
    /// The compass calibration in use and its gates' running values.
    pub compass: CompassMonitorState,
    /// The compass calibrators learning from the drive.
    pub learner: CompassLearnerState,
    /// The estimator's own bookkeeping between samples.
    pub tracking: VehicleTracking,
}

/// Refuses a filter whose numbers are not finite, whose covariance is not symmetric (to
/// rounding: the sparse prediction adds the same terms in a different order on each side)
/// or has a negative variance.
pub(super) fn check_filter(f: &NavFilter) -> Result<()> {
    let invalid = |reason| Err(Error::InvalidSnapshot { reason });
    if f.x
        .iter()
        .chain(f.p.iter().flatten())
        .any(|v| !v.is_finite())
    {
        return invalid("a filter value is not finite");
    }
    for i in 0..DIM {
        if f.p[i][i] < 0.0 {
            return invalid("a filter variance is negative");
        }
        for j in 0..i {
            let scale = (f.p[i][i] * f.p[j][j]).sqrt();
            if (f.p[i][j] - f.p[j][i]).abs() > 1e-9 * scale {
                return invalid("a filter covariance is not symmetric");
            }
        }
    }
    Ok(())
}

/// Refuses an estimate with a NaN anywhere but its time (NaN before the first sample), or an
/// infinite time.
pub(super) fn check_estimate(e: &NavEstimate) -> Result<()> {
    if e.t_s.is_infinite() || e.position_cov_m2.iter().any(|v| v.is_nan()) {
        return Err(Error::InvalidSnapshot {
            reason: "the saved estimate's time or position covariance is not a number",
        });
    }
    Ok(())
}

/// Refuses a compass calibration that could not scale a reading (a field that is not
/// positive).
pub(super) fn check_fix(fix: Option<&CompassFix>) -> Result<()> {
    match fix {
        Some(f) if !(f.field > 0.0 && f.noise_rad > 0.0) => Err(Error::InvalidSnapshot {
            reason: "a saved compass calibration has no positive field or noise",
        }),
        _ => Ok(()),
    }
}

impl Persistent for VehicleEstimator {
    type State = VehicleEstimatorState;
    // 2: the filter gained the odometer's mean scale and the wheels' delay (13 states).
    const SNAPSHOT_VERSION: u32 = 2;

    fn state(&self) -> VehicleEstimatorState {
        VehicleEstimatorState {
            config: self.config,
            initial_filter: self.initial,
            filter: self.filter,
            estimate: self.est,
            clock: self.clock,
            initial_fix: self.initial_fix,
            wheels: self.wheels.state(),
            compass: self.compass.state(),
            learner: self.learner.state(),
            tracking: self.tracking,
        }
    }

    fn from_state(s: VehicleEstimatorState) -> Result<Self> {
        s.config.validate()?;
        check_plain_numbers_finite(&s)?;
        check_filter(&s.initial_filter)?;
        check_filter(&s.filter)?;
        check_estimate(&s.estimate)?;
        check_fix(s.initial_fix.as_ref())?;
        check_fix(s.compass.fix.as_ref())?;
        let t = &s.tracking;
        if t.unobserved_at_s.is_nan() || t.learned_until_s.is_nan() {
            return Err(Error::InvalidSnapshot {
                reason: "a saved time is not a number",
            });
        }
        Ok(Self {
            coeffs: Coefficients::new(&s.config),
            initial: s.initial_filter,
            filter: s.filter,
            wheels: WheelOdometry::with_state(s.config.wheels, TrackModel::Exact, s.wheels)?,
            compass: CompassMonitor::with_state(s.config.compass, s.compass)?,
            initial_fix: s.initial_fix,
            learner: CompassLearner::with_state(s.config.compass, s.learner)?,
            clock: s.clock,
            tracking: s.tracking,
            est: s.estimate,
            config: s.config,
        })
    }
}
