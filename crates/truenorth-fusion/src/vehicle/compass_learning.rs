//! Which compass readings the vehicle estimator learns its hard and soft iron from.
//!
//! Two online least-squares calibrators, because a calibration cannot be trusted to judge
//! the readings it is learned from:
//! * the **bootstrap** calibrator learns while nothing can be judged against a compass
//!   heading — before the heading is referred to north, or after the calibration in use
//!   has been found wanting — from every reading that is consistent with the dead-reckoned
//!   heading, a test that needs no calibration: the raw vector can move by at most the
//!   locus's largest radius times the heading change since the last reading taken (plus an
//!   allowance for noise), so a reading that jumps while the vehicle drives straight — a
//!   lorry, a bridge — is left out. A bootstrap that cannot fit at all after covering most
//!   of the circle starts again. Once the gates work, it takes gated readings only, so that
//!   the slow disturbances the consistency test cannot see do not creep into it;
//! * the **clean** calibrator takes only readings that passed every gate of
//!   [`super::compass_monitor`], and replaces the bootstrap's calibration as soon as it has
//!   one of its own.
//!
//! Both take a reading only once the heading has moved on since the last one (or enough
//! time has passed), so long straights do not crowd one direction and the per-sample cost
//! stays small.

use nalgebra::Vector2;
use truenorth_calib::OnlineEllipseCalibrator;
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{
    Calibrator, Mag2Sample, OnlineCalibrator, Persistent, Pushed, Result, Solution, wrap_pi,
};

use super::config::CompassGates;

/// Dead-reckoned turning before the raw locus's extent is trusted for the consistency test,
/// rad (half a turn: the bounding box then spans the locus in at least one direction).
const EXTENT_TURN_RAD: f64 = core::f64::consts::PI;

/// Allowance for noise and dead-reckoning drift in the consistency test, as a share of the
/// locus's radius.
const CONSISTENCY_ALLOWANCE: f64 = 0.1;

/// A field that stays away from the last reading taken for this long is taken as a lasting
/// change (a new magnetisation) rather than a disturbance, s.
const LASTING_CHANGE_S: f64 = 30.0;

/// Shortest arc of heading the bootstrap calibrator accepts, degrees: more than a
/// calibration that can be checked needs, since nothing checks this one and a locus seen
/// over little more than half a turn extrapolates poorly to the rest.
const BOOTSTRAP_MIN_ARC_DEG: f64 = 240.0;

/// How the estimator judged a reading it offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Judged {
    /// Nothing could be judged (no heading referred to north, or the calibration in use
    /// was found wanting): the bootstrap decides by the consistency test.
    Unjudged,
    /// Passed every gate.
    Gated,
    /// Rejected by a gate.
    Rejected,
}

/// Pushes to the bootstrap between checks of whether it should start again.
const RESTART_CHECK_PUSHES: u32 = 64;

/// Share of the circle the bootstrap must have covered before a refusal to fit makes it
/// start again.
const RESTART_COVERAGE: f64 = 0.8;

/// The consistency test of raw readings against the dead-reckoned heading.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub(super) struct RawConsistency {
    anchor: Option<(Vector2<f64>, f64, f64)>,
    lo: Vector2<f64>,
    hi: Vector2<f64>,
    turned_rad: f64,
    last_psi: Option<f64>,
    away_since_s: Option<f64>,
}

impl RawConsistency {
    fn check(&mut self, raw: &Vector2<f64>, psi: f64, t_s: f64) -> bool {
        if let Some(p) = self.last_psi {
            self.turned_rad += wrap_pi(psi - p).abs();
        }
        self.last_psi = Some(psi);
        let ok = match self.anchor {
            Some((m, psi0, _)) if self.turned_rad >= EXTENT_TURN_RAD => {
                let radius = 0.5 * (self.hi - self.lo).norm();
                let allow = radius * (wrap_pi(psi - psi0).abs() + CONSISTENCY_ALLOWANCE);
                (raw - m).norm() <= allow
            }
            _ => true,
        };
        let lasting = ok
            || self
                .away_since_s
                .is_some_and(|t0| t_s - t0 >= LASTING_CHANGE_S);
        if lasting {
            self.anchor = Some((*raw, psi, t_s));
            self.away_since_s = None;
            if self.lo == self.hi && self.lo == Vector2::zeros() {
                self.lo = *raw;
                self.hi = *raw;
            }
            self.lo = self.lo.inf(raw);
            self.hi = self.hi.sup(raw);
        } else if self.away_since_s.is_none() {
            self.away_since_s = Some(t_s);
        }
        lasting
    }
}

/// The state of an [`OnlineEllipseCalibrator`].
type EllipseState = <OnlineEllipseCalibrator as Persistent>::State;

/// A [`CompassLearner`]'s two calibrators and running values, as plain data
/// ([`CompassLearner::state`]); opaque beyond serde.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CompassLearnerState {
    pub(super) bootstrap: EllipseState,
    pub(super) clean: EllipseState,
    pub(super) clean_in_use: bool,
    pub(super) last_push: Option<(f64, f64)>,
    pub(super) consistency: RawConsistency,
    pub(super) bootstrap_pushes: u32,
}

/// The bootstrap and clean calibrators and the choice between them.
#[derive(Debug, Clone)]
pub struct CompassLearner {
    gates: CompassGates,
    bootstrap: OnlineEllipseCalibrator,
    clean: OnlineEllipseCalibrator,
    clean_in_use: bool,
    last_push: Option<(f64, f64)>,
    consistency: RawConsistency,
    bootstrap_pushes: u32,
}

impl CompassLearner {
    /// Learners with nothing learned.
    pub fn new(gates: CompassGates) -> Result<Self> {
        let mut bootstrap = gates.calibrator;
        bootstrap.min_arc_deg = bootstrap.min_arc_deg.max(BOOTSTRAP_MIN_ARC_DEG);
        Ok(Self {
            gates,
            bootstrap: OnlineEllipseCalibrator::new(bootstrap)?,
            clean: OnlineEllipseCalibrator::new(gates.calibrator)?,
            clean_in_use: false,
            last_push: None,
            consistency: RawConsistency::default(),
            bootstrap_pushes: 0,
        })
    }

    /// Forgets everything.
    pub fn reset(&mut self) {
        self.bootstrap.reset();
        self.clean.reset();
        self.clean_in_use = false;
        self.last_push = None;
        self.consistency = RawConsistency::default();
        self.bootstrap_pushes = 0;
    }

    /// Both calibrators' states and the decimation and consistency test's running values
    /// (the gates come with the configuration).
    pub fn state(&self) -> CompassLearnerState {
        CompassLearnerState {
            bootstrap: self.bootstrap.state(),
            clean: self.clean.state(),
            clean_in_use: self.clean_in_use,
            last_push: self.last_push,
            consistency: self.consistency,
            bootstrap_pushes: self.bootstrap_pushes,
        }
    }

    /// The learner with `gates`, continuing from `state`; a calibrator state that its
    /// calibrator refuses is refused.
    pub fn with_state(gates: CompassGates, state: CompassLearnerState) -> Result<Self> {
        Ok(Self {
            gates,
            bootstrap: OnlineEllipseCalibrator::from_state(state.bootstrap)?,
            clean: OnlineEllipseCalibrator::from_state(state.clean)?,
            clean_in_use: state.clean_in_use,
            last_push: state.last_push,
            consistency: state.consistency,
            bootstrap_pushes: state.bootstrap_pushes,
        })
    }

    /// Starts learning afresh, for when the calibration in use has been found wanting: the
    /// clean calibrator is emptied and the bootstrap's calibration is used until it has one
    /// again.
    pub fn relearn(&mut self) {
        self.clean.reset();
        self.clean_in_use = false;
        self.bootstrap.reset();
        self.bootstrap_pushes = 0;
    }

    /// The calibrator whose calibration is in use.
    pub fn calibrator(&self) -> &OnlineEllipseCalibrator {
        if self.clean_in_use {
            &self.clean
        } else {
            &self.bootstrap
        }
    }

    /// Whether the calibration in use was learned from gated readings only.
    pub fn clean_in_use(&self) -> bool {
        self.clean_in_use
    }

    /// Offers reading `raw` at dead-reckoned heading `psi_rad`, judged as `judged`. Returns
    /// a new calibration to use, if this reading brought one.
    pub fn offer(
        &mut self,
        raw: &Vector2<f64>,
        t_s: f64,
        psi_rad: f64,
        judged: Judged,
    ) -> Option<Solution<CompassCalibration2d>> {
        if judged == Judged::Rejected {
            return None;
        }
        // Decimation first: it is cheap, and only readings that would be taken need the
        // consistency test.
        if let Some((t0, psi0)) = self.last_push {
            let moved =
                wrap_pi(psi_rad - psi0).abs() >= self.gates.calibrator_spacing_deg.to_radians();
            if !moved && t_s - t0 < self.gates.calibrator_interval_s {
                return None;
            }
        }
        let gated = judged == Judged::Gated;
        if !gated && !self.consistency.check(raw, psi_rad, t_s) {
            return None;
        }
        self.last_push = Some((t_s, psi_rad));
        let sample = Mag2Sample { t_s, mag: *raw };
        if gated && matches!(self.clean.push(&sample), Ok(Pushed::NewEstimate)) {
            self.clean_in_use = true;
            return self.clean.estimate();
        }
        if self.clean_in_use {
            return None;
        }
        let pushed = self.bootstrap.push(&sample);
        self.bootstrap_pushes += 1;
        if self.bootstrap_pushes.is_multiple_of(RESTART_CHECK_PUSHES)
            && self.bootstrap.estimate().is_none()
        {
            let p = self.bootstrap.progress();
            if !p.ready && p.coverage >= RESTART_COVERAGE {
                self.bootstrap.reset();
            }
        }
        match pushed {
            Ok(Pushed::NewEstimate) => self.bootstrap.estimate(),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn turn(
        learner: &mut CompassLearner,
        from_deg: f64,
        span_deg: f64,
        t0: f64,
    ) -> Option<Solution<CompassCalibration2d>> {
        let mut last = None;
        let n = (span_deg.abs() * 2.0) as usize;
        for k in 0..=n {
            let psi = (from_deg + span_deg * k as f64 / n as f64).to_radians();
            let raw = Vector2::new(5.0 + 20.0 * psi.cos(), -3.0 - 14.0 * psi.sin());
            if let Some(s) = learner.offer(&raw, t0 + 0.1 * k as f64, psi, Judged::Unjudged) {
                last = Some(s);
            }
        }
        last
    }

    #[test]
    fn a_jump_on_a_straight_is_left_out_of_the_bootstrap() {
        let mut l = CompassLearner::new(CompassGates::default()).unwrap();
        turn(&mut l, 0.0, 200.0, 0.0);
        // Straight at 200°: a 0.5 × field jump is inconsistent with no heading change.
        let psi = 200f64.to_radians();
        let raw = Vector2::new(5.0 + 20.0 * psi.cos(), -3.0 - 14.0 * psi.sin());
        assert!(
            !l.consistency
                .check(&(raw + Vector2::new(10.0, 0.0)), psi, 100.0)
        );
        // The clean reading is fine.
        assert!(l.consistency.check(&raw, psi, 100.1));
        // A field that stays changed for long is a lasting change and is taken.
        assert!(
            !l.consistency
                .check(&(raw + Vector2::new(10.0, 0.0)), psi, 200.0)
        );
        assert!(l.consistency.check(
            &(raw + Vector2::new(10.0, 0.0)),
            psi,
            200.0 + LASTING_CHANGE_S
        ));
    }

    #[test]
    fn the_bootstrap_calibrates_and_the_clean_one_takes_over() {
        let mut l = CompassLearner::new(CompassGates::default()).unwrap();
        let s = turn(&mut l, 0.0, 400.0, 0.0).expect("calibrated by a turn");
        assert!((s.params.hard_iron - Vector2::new(5.0, -3.0)).norm() < 1e-6);
        assert!(!l.clean_in_use());
        let mut took_over = false;
        for k in 0..800 {
            let psi = (k as f64 * 0.5).to_radians();
            let raw = Vector2::new(5.0 + 20.0 * psi.cos(), -3.0 - 14.0 * psi.sin());
            took_over |= l
                .offer(&raw, 100.0 + 0.1 * k as f64, psi, Judged::Gated)
                .is_some();
        }
        assert!(took_over && l.clean_in_use());
    }
}
