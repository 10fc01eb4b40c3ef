//! One step of two odometer wheels: their distances over the step (scale errors removed) →
//! distance travelled, speed-corrected difference and, divided by the effective track,
//! heading change with its derivatives with respect to the calibration (US 4,788,645
//! eqs. 2/8 and 3/14).
//!
//! Both [`crate::DifferentialOdometer`] and the vehicle estimator's wheel odometry take
//! their steps here; what stays with them is how they refuse or bound values outside the
//! model (a typed error for the former, a floor for the latter).

use crate::WheelDistances;

/// The gains `(1 + δ/2, 1 − δ/2)` of the left and right wheels under a differential scale δ
/// (raw metres per true metre): the parameterisation [`OdometryTurn::d_heading_d_diff`]
/// differentiates.
#[inline]
pub fn differential_gains(diff: f64) -> (f64, f64) {
    (1.0 + 0.5 * diff, 1.0 + -0.5 * diff)
}

/// The wheels' part of a step: mean distance, speed and the speed-corrected difference.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OdometryStep {
    /// Duration of the step, s.
    pub dt_s: f64,
    /// Mean distance of the two wheels `AD`, m: the distance of the midpoint between them
    /// (negative reversing).
    pub mean_m: f64,
    /// Mean speed of the two wheels `|AD|/dt`, m/s.
    pub speed_mps: f64,
    /// The speed factor `1 + aV²` of eq. 2/8, no lower than the floor it was computed with.
    pub speed_factor: f64,
    /// Difference of the wheels `ΔD = (D_L − D_R)/(1 + aV²)`, m, positive for a right turn.
    pub diff_m: f64,
}

impl OdometryStep {
    /// The step of wheels that rolled `wheels` (per-wheel scale removed) in `dt_s` seconds
    /// under speed coefficient `a` (s²/m²). The speed factor is raised to
    /// `min_speed_factor` if it falls below (pass `f64::NEG_INFINITY` to take it as it is
    /// and judge it afterwards). Plain arithmetic: the caller checks what it must.
    #[inline]
    pub fn new(
        wheels: &WheelDistances,
        dt_s: f64,
        speed_coeff_s2_per_m2: f64,
        min_speed_factor: f64,
    ) -> Self {
        let WheelDistances { left_m, right_m } = *wheels;
        let mean_m = 0.5 * (left_m + right_m);
        let speed_mps = mean_m.abs() / dt_s;
        let speed_factor =
            (1.0 + speed_coeff_s2_per_m2 * speed_mps * speed_mps).max(min_speed_factor);
        Self {
            dt_s,
            mean_m,
            speed_mps,
            speed_factor,
            diff_m: (left_m - right_m) / speed_factor,
        }
    }

    /// The curvature ratio `c = ΔD/AD` (about T/R, signed), zero when the mean distance is.
    #[inline]
    pub fn ratio(&self) -> f64 {
        if self.mean_m != 0.0 {
            self.diff_m / self.mean_m
        } else {
            0.0
        }
    }

    /// The heading change over effective track `track_m` scaled by `track_scale` (`1 + ε`,
    /// ε the track's relative error; 1 for the track as it is), with its derivatives.
    #[inline]
    pub fn turn(&self, track_m: f64, track_scale: f64) -> OdometryTurn {
        let heading = self.diff_m / (track_m * track_scale);
        OdometryTurn {
            heading_change_rad: heading,
            // D_L − D_R falls by the mean distance per unit δ (first order).
            d_heading_d_diff: -self.mean_m / (self.speed_factor * track_m * track_scale),
            d_heading_d_speed_coeff: -heading * self.speed_mps * self.speed_mps / self.speed_factor,
            d_heading_d_track_scale: -heading / track_scale,
        }
    }
}

/// The heading change of an [`OdometryStep`] and how it depends on the calibration.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OdometryTurn {
    /// Heading change `Δθ = ΔD / (T_E·(1 + ε))`, rad, positive right.
    pub heading_change_rad: f64,
    /// ∂Δθ/∂δ under the gains of [`differential_gains`], rad.
    pub d_heading_d_diff: f64,
    /// ∂Δθ/∂a, rad·m²/s².
    pub d_heading_d_speed_coeff: f64,
    /// ∂Δθ/∂ε, rad.
    pub d_heading_d_track_scale: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(diff: f64, a: f64) -> OdometryStep {
        let (gl, gr) = differential_gains(diff);
        let wheels = WheelDistances {
            left_m: 1.03 / gl,
            right_m: 0.97 / gr,
        };
        OdometryStep::new(&wheels, 0.1, a, 0.5)
    }

    #[test]
    fn the_plain_formula_and_its_derivatives() {
        let s = step(0.0, 0.0);
        assert!((s.mean_m - 1.0).abs() < 1e-12 && (s.speed_mps - 10.0).abs() < 1e-12);
        assert!((s.ratio() - 0.06).abs() < 1e-12);
        let t = s.turn(1.5, 1.0);
        assert!((t.heading_change_rad - 0.04).abs() < 1e-12);
        let h = 1e-7;
        let d = (step(h, 0.0).turn(1.5, 1.0).heading_change_rad - t.heading_change_rad) / h;
        assert!((d - t.d_heading_d_diff).abs() < 1e-5);
        let d = (step(0.0, h).turn(1.5, 1.0).heading_change_rad - t.heading_change_rad) / h;
        assert!((d - t.d_heading_d_speed_coeff).abs() < 1e-4);
        let d = (s.turn(1.5, 1.0 + h).heading_change_rad - t.heading_change_rad) / h;
        assert!((d - t.d_heading_d_track_scale).abs() < 1e-5);
    }

    #[test]
    fn standing_still_is_no_turn_and_the_floor_holds() {
        let s = OdometryStep::new(&WheelDistances::default(), 1.0, 0.0, 0.5);
        assert_eq!((s.ratio(), s.turn(1.5, 1.0).heading_change_rad), (0.0, 0.0));
        let fast = WheelDistances {
            left_m: 40.0,
            right_m: 40.0,
        };
        assert_eq!(OdometryStep::new(&fast, 1.0, -1.0, 0.5).speed_factor, 0.5);
        assert!(OdometryStep::new(&fast, 1.0, -1.0, f64::NEG_INFINITY).speed_factor < 0.0);
    }
}
