//! A straight line fitted through a run of compass innovations (reading minus
//! dead-reckoned heading) in time: where it ends is the heading's offset now, its residuals
//! say whether the readings agree with each other, and its slope how fast the dead
//! reckoning drifts against them.
//!
//! It refers the heading to north the first time, and again after a long outage, when the
//! dead-reckoned heading may have drifted by more than its variance says.

use truenorth_core::wrap_pi;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// What a completed run of readings says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineFit {
    /// The line's value at the last reading, rad.
    pub offset_rad: f64,
    /// Its standard deviation, rad: `σ √(1/n + (t_end − t̄)²/S_tt)` for reading noise σ.
    pub sigma_rad: f64,
    /// Standard deviation of the readings about the line, rad.
    pub residual_rad: f64,
    /// The line's slope, rad/s.
    pub slope_rps: f64,
}

/// Running sums of the fit, relative to the first reading so that they stay well
/// conditioned and the innovations unwrapped.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InnovationLine {
    first: Option<(f64, f64)>,
    n: u32,
    s_t: f64,
    s_tt: f64,
    s_v: f64,
    s_tv: f64,
    s_vv: f64,
    last_t: f64,
}

impl InnovationLine {
    /// Readings gathered so far.
    pub fn len(&self) -> u32 {
        self.n
    }

    /// Adds innovation `nu_rad` taken at `t_s`. One that is not a number says nothing
    /// about the heading and is left out: counted, it would turn every sum, and so the
    /// offset the line gives, into NaN.
    pub fn push(&mut self, t_s: f64, nu_rad: f64) {
        if !(t_s.is_finite() && nu_rad.is_finite()) {
            return;
        }
        let (t0, nu0) = *self.first.get_or_insert((t_s, nu_rad));
        let (t, v) = (t_s - t0, wrap_pi(nu_rad - nu0));
        self.n += 1;
        self.s_t += t;
        self.s_tt += t * t;
        self.s_v += v;
        self.s_tv += t * v;
        self.s_vv += v * v;
        self.last_t = t;
    }

    /// The fit, given the noise `noise_rad` of one reading; `None` before three readings.
    pub fn fit(&self, noise_rad: f64) -> Option<LineFit> {
        let (_, nu0) = self.first?;
        if self.n < 3 {
            return None;
        }
        let n = f64::from(self.n);
        let (mt, mv) = (self.s_t / n, self.s_v / n);
        let stt = self.s_tt - n * mt * mt;
        let stv = self.s_tv - n * mt * mv;
        let svv = self.s_vv - n * mv * mv;
        let slope = if stt > 0.0 { stv / stt } else { 0.0 };
        let lever = if stt > 0.0 {
            (self.last_t - mt).powi(2) / stt
        } else {
            0.0
        };
        Some(LineFit {
            offset_rad: wrap_pi(nu0 + mv + slope * (self.last_t - mt)),
            sigma_rad: noise_rad * (1.0 / n + lever).sqrt(),
            residual_rad: ((svv - slope * stv) / (n - 2.0)).max(0.0).sqrt(),
            slope_rps: slope,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Innovations on a line (any offset, any drift, across ±π) give that line back.
        #[test]
        fn recovers_a_drifting_offset(offset in -3.1f64..3.1, drift in -0.05f64..0.05) {
            let mut line = InnovationLine::default();
            for k in 0..20 {
                let t = 100.0 + 0.1 * k as f64;
                line.push(t, wrap_pi(offset + drift * (t - 100.0)));
            }
            let fit = line.fit(0.01).unwrap();
            prop_assert!(wrap_pi(fit.offset_rad - (offset + drift * 1.9)).abs() < 1e-9);
            prop_assert!((fit.slope_rps - drift).abs() < 1e-9);
            // The residual is the square root of a difference of sums of squares, so its
            // rounding floor is √(ε·Σv²) ≈ 1e-9 here, not ε.
            prop_assert!(fit.residual_rad < 1e-7);
        }
    }

    #[test]
    fn an_innovation_that_is_not_a_number_is_left_out() {
        let mut line = InnovationLine::default();
        for (k, nu) in [0.1, f64::NAN, 0.2, f64::INFINITY, 0.3]
            .into_iter()
            .enumerate()
        {
            line.push(3600.0 * k as f64, nu);
        }
        assert_eq!(line.len(), 3);
        let fit = line.fit(0.01).unwrap();
        assert!((fit.offset_rad - 0.3).abs() < 1e-9, "{fit:?}");
        assert!(
            fit.residual_rad < 1e-6 && fit.sigma_rad.is_finite(),
            "{fit:?}"
        );
    }

    #[test]
    fn too_few_readings_give_no_fit() {
        let mut line = InnovationLine::default();
        assert!(line.fit(0.01).is_none());
        line.push(0.0, 0.1);
        line.push(0.1, 0.1);
        assert!(line.fit(0.01).is_none());
    }
}
