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
//! Readings reach the calibrator only when they pass all gates (before the heading is
//! referred to north, when nothing can be judged, all do), and only once the heading has
//! moved on since the last one: long straights would otherwise crowd one direction.

use truenorth_calib::OnlineEllipseCalibrator;
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, CompassQuality, Mag2Sample, OnlineCalibrator, Pushed, Result, Solution, wrap_pi,
};

use super::config::CompassGates;

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Smallest per-reading heading noise assumed, rad (0.1°): a calibration's own noise
/// estimate can be optimistic after few readings.
const MIN_NOISE_RAD: f64 = 0.1 * core::f64::consts::PI / 180.0;

/// The slow gate lets the compass back once its averaged innovation falls below this share
/// of the threshold that tripped it (hysteresis, so that a disturbance fading out does not
/// flicker in and out).
const RELEASE_SHARE: f64 = 0.7;

/// A calibration in use and what it implies for one reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompassFix {
    /// Hard and soft iron.
    pub calibration: CompassCalibration2d,
    /// The fitted horizontal field, input unit.
    pub field: f64,
    /// Standard deviation of one reading's heading, rad.
    pub noise_rad: f64,
    /// The calibration's quality report.
    pub quality: CompassQuality,
}

impl CompassFix {
    fn from_solution(s: &Solution<CompassCalibration2d>) -> Self {
        Self {
            calibration: s.params,
            field: s.quality.field_magnitude,
            noise_rad: s
                .quality
                .heading_noise_rms_deg
                .to_radians()
                .max(MIN_NOISE_RAD),
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
    /// Taken into the current average; no correction yet.
    Taken,
    /// Taken, completing an average: correct the heading by `innovation_rad` with noise
    /// variance `variance_rad2`.
    Correct {
        /// Mean innovation of the readings averaged, rad.
        innovation_rad: f64,
        /// Its noise variance, rad².
        variance_rad2: f64,
    },
}

/// The online calibration, its decimation and the gates.
#[derive(Debug, Clone)]
pub struct CompassMonitor {
    gates: CompassGates,
    calibrator: OnlineEllipseCalibrator,
    fix: Option<CompassFix>,
    last_push: Option<(f64, f64)>,
    last_t_s: Option<f64>,
    average_rad: f64,
    disturbed: bool,
    window_sum_rad: f64,
    window_n: u32,
}

impl CompassMonitor {
    /// A monitor with no calibration yet.
    pub fn new(gates: CompassGates) -> Result<Self> {
        Ok(Self {
            gates,
            calibrator: OnlineEllipseCalibrator::new(gates.calibrator)?,
            fix: None,
            last_push: None,
            last_t_s: None,
            average_rad: 0.0,
            disturbed: false,
            window_sum_rad: 0.0,
            window_n: 0,
        })
    }

    /// Starts from a calibration found earlier (kept until the online calibrator, which
    /// starts empty, has one of its own).
    pub fn with_fix(mut self, fix: Option<CompassFix>) -> Self {
        self.fix = fix;
        self
    }

    /// Forgets everything learned.
    pub fn reset(&mut self) {
        self.calibrator.reset();
        self.fix = None;
        self.last_push = None;
        self.last_t_s = None;
        self.restart_gates();
    }

    /// Forgets the gates' memory (after the heading was re-referred).
    pub fn restart_gates(&mut self) {
        self.average_rad = 0.0;
        self.disturbed = false;
        self.window_sum_rad = 0.0;
        self.window_n = 0;
    }

    /// The calibration in use.
    pub fn fix(&self) -> Option<&CompassFix> {
        self.fix.as_ref()
    }

    /// Whether the averaged innovation currently marks the compass as disturbed.
    pub fn disturbed(&self) -> bool {
        self.disturbed
    }

    /// Calibrated heading (rad) and field magnitude over the fitted one, if calibrated.
    pub fn measure(&self, raw: &nalgebra::Vector2<f64>) -> Option<(f64, f64)> {
        let fix = self.fix.as_ref()?;
        let u = fix.calibration.correct(raw);
        Some(((-u.y).atan2(u.x), u.norm() / fix.field))
    }

    /// Whether a field magnitude ratio is within the tolerance.
    pub fn field_ok(&self, ratio: f64) -> bool {
        (ratio - 1.0).abs() <= self.gates.field_tolerance
    }

    /// Offers a reading to the calibrator if the heading `psi_rad` has moved on since the
    /// last one (or enough time has passed). Returns whether the calibration in use changed.
    pub fn offer(&mut self, raw: &nalgebra::Vector2<f64>, t_s: f64, psi_rad: f64) -> bool {
        if let Some((t0, psi0)) = self.last_push {
            let moved =
                wrap_pi(psi_rad - psi0).abs() >= self.gates.calibrator_spacing_deg.to_radians();
            if !moved && t_s - t0 < self.gates.calibrator_interval_s {
                return false;
            }
        }
        self.last_push = Some((t_s, psi_rad));
        match self.calibrator.push(&Mag2Sample { t_s, mag: *raw }) {
            Ok(Pushed::NewEstimate) => match self.calibrator.estimate() {
                Some(s) => {
                    self.fix = Some(CompassFix::from_solution(&s));
                    true
                }
                None => false,
            },
            _ => false,
        }
    }

    /// Judges one calibrated reading with innovation `nu_rad` (reading minus dead-reckoned
    /// heading, wrapped) and field ratio `ratio`, given the heading's variance `p_psi` now.
    pub fn judge(&mut self, t_s: f64, nu_rad: f64, ratio: f64, p_psi: f64) -> Verdict {
        let Some(fix) = self.fix else {
            return Verdict::Unusable;
        };
        let dt = self.last_t_s.map_or(0.0, |t0| (t_s - t0).max(0.0));
        self.last_t_s = Some(t_s);
        if !self.field_ok(ratio) {
            return Verdict::Unusable;
        }
        let r = fix.noise_rad * fix.noise_rad;
        let floor = self.gates.systematic_floor_deg.to_radians();
        // Exponential average of the innovations: for white noise of variance r its
        // variance settles at r·α/(2 − α).
        let alpha = (dt / self.gates.slow_gate_tau_s).min(1.0);
        self.average_rad += alpha * (nu_rad - self.average_rad);
        let spread = (p_psi + r * alpha / (2.0 - alpha) + floor * floor).sqrt();
        let limit = self.gates.slow_gate_sigma * spread;
        if self.disturbed {
            self.disturbed = self.average_rad.abs() > RELEASE_SHARE * limit;
        } else {
            self.disturbed = self.average_rad.abs() > limit;
        }
        let gate = self.gates.innovation_gate_sigma * (p_psi + r + floor * floor).sqrt();
        if self.disturbed || nu_rad.abs() > gate {
            self.window_sum_rad = 0.0;
            self.window_n = 0;
            return Verdict::Rejected;
        }
        self.window_sum_rad += nu_rad;
        self.window_n += 1;
        if self.window_n < self.gates.readings_per_update {
            return Verdict::Taken;
        }
        let n = f64::from(self.window_n);
        let innovation_rad = self.window_sum_rad / n;
        self.window_sum_rad = 0.0;
        self.window_n = 0;
        Verdict::Correct {
            innovation_rad,
            variance_rad2: r / n + floor * floor,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn calibrated() -> CompassMonitor {
        let mut m = CompassMonitor::new(CompassGates::default()).unwrap();
        for k in 0..720 {
            let psi = (k as f64 * 0.5).to_radians();
            let raw = Vector2::new(5.0 + 20.0 * psi.cos(), -3.0 - 20.0 * psi.sin());
            m.offer(&raw, k as f64 * 0.1, psi);
        }
        m
    }

    #[test]
    fn learns_a_calibration_from_a_turn() {
        let m = calibrated();
        let fix = m.fix().expect("calibrated after two turns");
        assert!((fix.calibration.hard_iron - Vector2::new(5.0, -3.0)).norm() < 1e-6);
        let (h, ratio) = m.measure(&Vector2::new(25.0, -3.0)).unwrap();
        assert!(h.abs() < 1e-6 && (ratio - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_slow_drift_is_caught_by_the_average_before_the_single_gate() {
        let mut m = calibrated();
        // A compass with 1 % noise (0.57° per reading) at 10 Hz.
        m.fix.as_mut().unwrap().noise_rad = 0.57f64.to_radians();
        let p = 0.1f64.to_radians().powi(2);
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
