//! The turn between two yaw-rate samples: the trapezoid rule, with its error.
//!
//! Each sample is the instantaneous rate at its timestamp (the convention of
//! [`truenorth_core::GyroSample`]). Between two samples the rate is taken to vary linearly,
//! so the turn is `(ω_prev + ω_now)/2 · dt`: exact for a constant or linearly changing rate.
//! A rate that changes otherwise can change anywhere in the interval, which leaves an error
//! uniform within `±|Δω|·dt/2`, of variance `(Δω·dt)²/12`; the rectangle rule on either end
//! point would be off by up to `|Δω|·dt` (`dt²/2 · |ω̇|` for a steady change).

/// Two consecutive rate samples and the time between them.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct YawIncrement {
    /// The earlier rate, rad/s.
    pub prev_rps: f64,
    /// The later rate, rad/s.
    pub now_rps: f64,
    /// Time between the two samples, s.
    pub dt_s: f64,
}

impl YawIncrement {
    /// The interval from a sample of rate `prev_rps` to one of `now_rps`, `dt_s` later.
    #[inline]
    pub fn new(prev_rps: f64, now_rps: f64, dt_s: f64) -> Self {
        Self {
            prev_rps,
            now_rps,
            dt_s,
        }
    }

    /// The mean rate over the interval, `(ω_prev + ω_now)/2`, rad/s.
    #[inline]
    pub fn mean_rate_rps(&self) -> f64 {
        0.5 * (self.prev_rps + self.now_rps)
    }

    /// The turn over the interval, rad (positive right for a yaw gyro).
    #[inline]
    pub fn angle_rad(&self) -> f64 {
        self.mean_rate_rps() * self.dt_s
    }

    /// The turn of raw samples under zero `zero_rps` and gain `gain`:
    /// `((ω_prev + ω_now)/2 − zero)/gain · dt`, rad.
    #[inline]
    pub fn corrected_rad(&self, zero_rps: f64, gain: f64) -> f64 {
        (self.mean_rate_rps() - zero_rps) / gain * self.dt_s
    }

    /// Variance of the trapezoid's error when the rate may change anywhere in the interval,
    /// `(Δω·dt)²/12`, rad².
    #[inline]
    pub fn error_variance_rad2(&self) -> f64 {
        let spread = (self.now_rps - self.prev_rps) * self.dt_s;
        spread * spread / 12.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_rate_is_integrated_exactly() {
        // ω = 0.1 + 0.2 t from t = 1 to 3: ∫ = 0.2 + 0.1 (9 − 1) = 1.0.
        let step = YawIncrement::new(0.3, 0.7, 2.0);
        assert!((step.angle_rad() - 1.0).abs() < 1e-15);
        assert!((step.corrected_rad(0.1, 2.0) - 0.4).abs() < 1e-15);
        assert!((step.error_variance_rad2() - 0.64 / 12.0).abs() < 1e-15);
        assert_eq!(YawIncrement::new(0.5, 0.5, 1.0).error_variance_rad2(), 0.0);
    }
}
