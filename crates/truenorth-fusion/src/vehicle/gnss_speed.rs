//! The odometer's mean scale from the receiver's speed over ground.
//!
//! A fix's position error is correlated over tens of seconds, so positions alone measure
//! the odometer's scale only over kilometres; the receiver's speed (from the carrier's
//! Doppler shift) is accurate to a few cm/s and nearly white from one second to the next.
//! Between two fixes that report a speed, the distance the receiver says was driven —
//! their mean speed times the time between them (the trapezoid rule) — is compared with
//! what the odometer read over the same time: `z = ½(v₁ + v₂)Δt` against `D(1 + k)`, which
//! measures `k` with coefficient `D`.

use truenorth_core::GnssFix;

use super::estimator::VehicleEstimator;
use super::gnss_track::SpeedMark;
use super::nav_filter::WHEEL_SCALE;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Longest time between the two fixes of one comparison, s: over longer the trapezoid
/// rule misses how the speed changed in between.
const MAX_SPAN_S: f64 = 2.5;

/// Shortest time between them, s: the fixes' interval the estimator uses at most.
const MIN_SPAN_S: f64 = 1.0;

/// A speed over ground at least this many times its standard deviation starts or ends a
/// comparison (10): the magnitude of a noisy velocity reads long by `σ²/2v` (the Rice
/// distribution's mean), which at ten standard deviations is half a percent.
const MIN_SPEED_SIGMAS: f64 = 10.0;

impl VehicleEstimator {
    /// Compares the distance the receiver's speeds say was driven since the last fix with
    /// a speed with the odometer's over the same time, when both ends are fast enough and
    /// close enough in time. `t_s` is the fix's epoch.
    pub(super) fn correct_with_speed(&mut self, t_s: f64, fix: &GnssFix) {
        let cfg = self.config.gnss;
        let min_speed = (MIN_SPEED_SIGMAS * cfg.speed_sigma_mps).max(cfg.min_course_speed_mps);
        let odometer = self.tracking.gnss.odometer.at(t_s);
        let mark = match (fix.speed_mps, odometer) {
            (Some(v), Some(odometer_m)) if v >= min_speed => SpeedMark {
                t_s,
                fix_mps: v,
                odometer_m,
            },
            _ => {
                self.tracking.gnss.speed_mark = None;
                return;
            }
        };
        let Some(last) = self.tracking.gnss.speed_mark else {
            self.tracking.gnss.speed_mark = Some(mark);
            return;
        };
        let span = t_s - last.t_s;
        if span < MIN_SPAN_S {
            return;
        }
        self.tracking.gnss.speed_mark = Some(mark);
        if span > MAX_SPAN_S {
            return;
        }
        let odometer = mark.odometer_m - last.odometer_m;
        let fixes = 0.5 * (mark.fix_mps + last.fix_mps) * span;
        let nu = fixes - odometer * (1.0 + self.filter.x[WHEEL_SCALE]);
        let sv = cfg.speed_sigma_mps;
        let rice = sv * sv / (2.0 * mark.fix_mps.min(last.fix_mps)) * span;
        // The delay is known to its spread: the odometer's span may be shifted by as much,
        // which changes its distance by the change of speed times the shift. Each end is
        // interpolated between readings a pulse apart at worst.
        let resolution = self.coeffs.priors.wheel_resolution_m;
        let r = 0.5 * (sv * span).powi(2)
            + rice * rice
            + (cfg.latency_sigma_s * (mark.fix_mps - last.fix_mps)).powi(2)
            + resolution * resolution / 6.0;
        self.flush();
        let s = odometer * odometer * self.filter.p[WHEEL_SCALE][WHEEL_SCALE] + r;
        let gate = cfg.gate_sigma;
        if nu * nu <= gate * gate * s {
            self.filter.update(&[(WHEEL_SCALE, odometer)], nu, r);
        }
    }
}
