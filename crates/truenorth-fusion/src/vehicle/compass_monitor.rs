//! The compass as the vehicle estimator sees it: a calibration learned online while
//! driving, and the gates that decide which readings may correct the heading.
//!
//! Three gates, because disturbances come in three kinds:
//! * **field magnitude**: a lorry alongside or a bridge deck changes the field's strength;
//!   a reading whose calibrated magnitude is off the fitted one by more than the tolerance
//!   is not used;
//! * **innovation**: a reading whose heading disagrees with the dead-reckoned one by more
//!   than the combined uncertainty allows is not used (a χ² test on one degree of freedom);
//! * **averaged innovation**: a field that *turns* slowly (steel structures, buried pipes,
//!   tram lines alongside) keeps its magnitude and moves the heading by less per reading
//!   than the noise, so neither test above sees it. An exponential average of the
//!   innovations has a much smaller spread than one reading, so a slow drift of a degree or
//!   two stands out of it within seconds; while it does the compass counts as disturbed and
//!   none of its readings is used.
//!
//! The calibration itself is learned by [`super::compass_learning`].

use truenorth_compass::CompassCalibration2d;
use truenorth_core::{CompassQuality, Result, Solution, Validate};

use super::config::CompassGates;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Smallest per-reading heading noise assumed, rad (0.1°): a calibration's own noise
/// estimate can be optimistic after few readings.
const MIN_NOISE_RAD: f64 = 0.1 * core::f64::consts::PI / 180.0;

/// The slow gate lets the compass back once its averaged innovation falls below this share
/// of the threshold that tripped it, one standard deviation: a disturbance fades slowly,
/// and while it does the dead reckoning's own uncertainty grows, so a release at two
/// standard deviations took in readings still turned by it (on the range of drives of
/// `truenorth-fusion/tests/vehicle_ensemble.rs`, 0.7 of the threshold left 2.6 % of the
/// rows of cars with a gyro beyond 3σ and 1.4 % with this).
const RELEASE_SHARE: f64 = 1.0 / 3.0;

/// A calibration in use and what it implies for one reading.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CompassFix {
    /// Hard and soft iron.
    pub calibration: CompassCalibration2d,
    /// The fitted horizontal field, input unit.
    pub field: f64,
    /// Standard deviation of one reading's heading, rad.
    pub noise_rad: f64,
    /// Standard deviation of the heading error the calibration itself leaves (its
    /// parameters' uncertainty and what its model cannot remove), rad. It depends on the
    /// heading, so it changes as the vehicle turns.
    pub calibration_sigma_rad: f64,
    /// The calibration's quality report.
    pub quality: CompassQuality,
}

impl CompassFix {
    /// The fix for a calibrator's solution.
    pub fn from_solution(s: &Solution<CompassCalibration2d>) -> Self {
        Self {
            calibration: s.params,
            field: s.quality.field_magnitude,
            noise_rad: s
                .quality
                .heading_noise_rms_deg
                .to_radians()
                .max(MIN_NOISE_RAD),
            calibration_sigma_rad: (s.quality.heading_error_3sigma_deg / 3.0
                + s.quality.heading_error_systematic_deg)
                .to_radians(),
            quality: s.quality,
        }
    }
}

/// What the gates made of one reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// No calibration yet, or the field magnitude is off.
    Unusable,
    /// Judged disturbed (innovation or averaged innovation).
    Rejected,
    /// Use it: correct the heading with noise variance `variance_rad2`.
    Use {
        /// The reading's noise variance, rad².
        variance_rad2: f64,
    },
}

/// A [`CompassMonitor`]'s calibration and running gate values, as plain data
/// ([`CompassMonitor::state`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CompassMonitorState {
    /// The calibration in use, if any.
    pub fix: Option<CompassFix>,
    /// The time of the last reading judged, s.
    pub last_t_s: Option<f64>,
    /// The exponential average of the innovations, rad.
    pub average_rad: f64,
    /// The averaged innovation marks the compass disturbed.
    pub disturbed: bool,
    /// The averaged innovation is within its spread.
    pub steady: bool,
}

/// The calibration in use and the gates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompassMonitor {
    gates: CompassGates,
    fix: Option<CompassFix>,
    last_t_s: Option<f64>,
    average_rad: f64,
    disturbed: bool,
    steady: bool,
}

impl CompassMonitor {
    /// A monitor with no calibration yet, with validated `gates`.
    pub fn new(gates: CompassGates) -> Result<Self> {
        gates.validate()?;
        Ok(Self {
            gates,
            fix: None,
            last_t_s: None,
            average_rad: 0.0,
            disturbed: false,
            steady: false,
        })
    }

    /// Forgets the calibration and the readings judged; keeps the gates.
    pub fn reset(&mut self) {
        *self = Self {
            gates: self.gates,
            fix: None,
            last_t_s: None,
            average_rad: 0.0,
            disturbed: false,
            steady: false,
        };
    }

    /// The calibration in use and the gates' running values (the gates' settings come
    /// with the configuration).
    pub fn state(&self) -> CompassMonitorState {
        CompassMonitorState {
            fix: self.fix,
            last_t_s: self.last_t_s,
            average_rad: self.average_rad,
            disturbed: self.disturbed,
            steady: self.steady,
        }
    }

    /// The monitor with `gates`, continuing from `state`.
    pub fn with_state(gates: CompassGates, state: CompassMonitorState) -> Result<Self> {
        let mut m = Self::new(gates)?;
        m.fix = state.fix;
        m.last_t_s = state.last_t_s;
        m.average_rad = state.average_rad;
        m.disturbed = state.disturbed;
        m.steady = state.steady;
        Ok(m)
    }

    /// Uses `fix` from now on.
    pub fn set_fix(&mut self, fix: CompassFix) {
        self.fix = Some(fix);
    }

    /// Forgets the gates' memory (after the heading was re-referred).
    pub fn restart_gates(&mut self) {
        self.average_rad = 0.0;
        self.disturbed = false;
        self.steady = false;
    }

    /// The calibration in use.
    pub fn fix(&self) -> Option<&CompassFix> {
        self.fix.as_ref()
    }

    /// Whether the averaged innovation currently marks the compass as disturbed.
    pub fn disturbed(&self) -> bool {
        self.disturbed
    }

    /// Whether the averaged innovation was within one standard deviation at the last
    /// reading: no trend under way that a field turning slowly would start.
    pub fn steady(&self) -> bool {
        self.steady
    }

    /// The calibrated horizontal field and its magnitude over the fitted one, if
    /// calibrated and the calibrated field is a number: a raw reading near the largest
    /// float (no sensor reads one; a corrupted word does) overflows the soft-iron
    /// correction, and a field of infinite magnitude points nowhere, so it is no
    /// measurement of the heading.
    pub fn measure(&self, raw: &nalgebra::Vector2<f64>) -> Option<(nalgebra::Vector2<f64>, f64)> {
        let fix = self.fix.as_ref()?;
        let u = fix.calibration.correct(raw);
        let ratio = u.norm() / fix.field;
        ratio.is_finite().then_some((u, ratio))
    }

    /// Whether a field magnitude ratio is within the tolerance.
    pub fn field_ok(&self, ratio: f64) -> bool {
        (ratio - 1.0).abs() <= self.gates.field_tolerance
    }

    /// Judges one calibrated reading with innovation `nu_rad` (reading minus predicted
    /// reading, wrapped) and field ratio `ratio`, given the innovation's variance without
    /// the reading's own noise, `p_nu` (heading and compass-bias errors together).
    pub fn judge(&mut self, t_s: f64, nu_rad: f64, ratio: f64, p_nu: f64) -> Verdict {
        let Some(fix) = self.fix else {
            return Verdict::Unusable;
        };
        let dt = self.last_t_s.map_or(0.0, |t0| (t_s - t0).max(0.0));
        self.last_t_s = Some(t_s);
        if !self.field_ok(ratio) {
            return Verdict::Unusable;
        }
        let r = fix.noise_rad * fix.noise_rad;
        // Exponential average of the innovations: for white noise of variance r its
        // variance settles at r·α/(2 − α); the state's error is common to all readings.
        let alpha = (dt / self.gates.slow_gate_tau_s).min(1.0);
        self.average_rad += alpha * (nu_rad - self.average_rad);
        let spread = (p_nu + r * alpha / (2.0 - alpha)).sqrt();
        let limit = self.gates.slow_gate_sigma * spread;
        let release = if self.disturbed { RELEASE_SHARE } else { 1.0 };
        self.disturbed = self.average_rad.abs() > release * limit;
        self.steady = self.average_rad.abs() <= spread;
        let gate = self.gates.innovation_gate_sigma * (p_nu + r).sqrt();
        if self.disturbed || nu_rad.abs() > gate {
            return Verdict::Rejected;
        }
        Verdict::Use { variance_rad2: r }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn calibrated() -> CompassMonitor {
        use super::super::compass_learning::{CompassLearner, Judged};
        let mut learner = CompassLearner::new(CompassGates::default()).unwrap();
        let mut m = CompassMonitor::new(CompassGates::default()).unwrap();
        for k in 0..1440 {
            let psi = (k as f64 * 0.5).to_radians();
            let raw = Vector2::new(5.0 + 20.0 * psi.cos(), -3.0 - 20.0 * psi.sin());
            if let Some(s) = learner.offer(&raw, k as f64 * 0.1, psi, Judged::Unjudged) {
                m.set_fix(CompassFix::from_solution(&s));
            }
        }
        m
    }

    #[test]
    fn measures_with_the_calibration_it_was_given() {
        let m = calibrated();
        let fix = m.fix().expect("calibrated after two turns");
        assert!((fix.calibration.hard_iron - Vector2::new(5.0, -3.0)).norm() < 1e-6);
        let (u, ratio) = m.measure(&Vector2::new(25.0, -3.0)).unwrap();
        assert!((-u.y).atan2(u.x).abs() < 1e-6 && (ratio - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_reading_that_overflows_the_calibration_is_no_measurement() {
        let m = calibrated();
        for raw in [
            Vector2::new(-1146.8, -1.349_105_284_904_501e308),
            Vector2::new(f64::MAX, -f64::MAX),
            Vector2::new(1e200, 1e200),
        ] {
            assert_eq!(m.measure(&raw), None, "{raw:?}");
        }
        assert!(m.measure(&Vector2::new(1e6, -1e6)).is_some());
    }

    #[test]
    fn a_slow_drift_is_caught_by_the_average_before_the_single_gate() {
        let mut m = calibrated();
        // A compass with 1 % noise (0.57° per reading) at 10 Hz.
        m.fix.as_mut().unwrap().noise_rad = 0.57f64.to_radians();
        let p = 0.3f64.to_radians().powi(2);
        // 0.5°/s of drift: the averaged innovation marks the compass disturbed before any
        // single reading is past its gate.
        let mut caught = None;
        for k in 0..100 {
            let t = 100.0 + 0.1 * k as f64;
            let nu = (0.05 * k as f64).to_radians();
            let single_gate =
                3.5 * (p + 0.57f64.to_radians().powi(2) + 0.3f64.to_radians().powi(2)).sqrt();
            m.judge(t, nu, 1.0, p);
            if m.disturbed() {
                caught = Some(nu);
                assert!(
                    nu < single_gate,
                    "{} ≥ {}",
                    nu.to_degrees(),
                    single_gate.to_degrees()
                );
                break;
            }
        }
        let nu = caught.expect("caught");
        assert!(nu.to_degrees() < 2.0, "caught only at {}°", nu.to_degrees());
    }

    #[test]
    fn a_strong_field_change_is_unusable() {
        let mut m = calibrated();
        assert_eq!(m.judge(1.0, 0.0, 1.3, 1e-4), Verdict::Unusable);
        let mut n = CompassMonitor::new(CompassGates::default()).unwrap();
        assert_eq!(n.judge(1.0, 0.0, 1.0, 1e-4), Verdict::Unusable);
    }
}
