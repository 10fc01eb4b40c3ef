//! The yaw-rate sensor as real vehicles carry it: a MEMS gyro on a robot or a phone, or the
//! ESP's yaw-rate sensor a car sends on its CAN bus, with errors over their physical range.
//!
//! | error | cars (ESP sensor on CAN) | robots (MEMS) | why |
//! |---|---|---|---|
//! | bias | 0.01–3.75 °/s, log-uniform, either sign | 0.02–10 °/s | an ESP yaw-rate sensor's offset over life and temperature is specified to 3.75 °/s (Hyundai shop manual, yaw-rate & lateral G sensor); a consumer MEMS gyro's initial zero-rate output to ±20 °/s (InvenSense MPU-6000/6050 datasheet PS-MPU-6000A-00 rev 3.4, §6.1), a few °/s typically |
//! | scale | ±10 % | ±10 % | sensitivity tolerance ±3 % plus ±2 % over temperature (same datasheet), and a real car's CAN yaw rate read 8 % low against its GNSS/INS reference |
//! | right against left | ±1 % | ±1 % | |
//! | mounting tilt | 0–15 °: the rate reads × cos(tilt) | 0–15 ° | a sensor on a sloping dashboard, bracket or board |
//! | noise | 0.005–0.05 °/s/√Hz | the same | MPU-6050: 0.005 °/s/√Hz |
//! | bias walk | 0.002–0.01 °/s/√s | the same | |
//! | quantum | 0.01 °/s (a real ESP signal on CAN) | 1/131 °/s (16 bits at ±250 °/s) | |

use serde::{Deserialize, Serialize};
use truenorth_core::{NoiseSource, Result, SplitMix64, check_range};
use truenorth_gyro::GyroAxisParams;

use super::span::Span;
use crate::draw::either_sign;

/// The ranges a yaw-rate sensor's errors are drawn from (defaults per vehicle kind in
/// [`YawRateConfig::for_car`] and [`YawRateConfig::for_robot`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct YawRateConfig {
    /// Size of the bias, °/s, drawn log-uniformly, either sign (0–100).
    pub bias_dps: Span,
    /// Bias random walk, °/s/√s, drawn uniformly (0–1).
    pub bias_walk_dps_per_sqrt_s: Span,
    /// Scale error common to both turning directions, drawn uniformly in ±this (0.10; 0–0.5).
    pub scale_error: f64,
    /// Difference between the right and left turns' scale errors, drawn uniformly in ±this
    /// (0.01; 0–0.2).
    pub scale_asymmetry: f64,
    /// Tilt of the sensor's axis from the vertical, degrees, drawn uniformly (0–15; 0–60):
    /// the sensor reads the yaw rate times cos(tilt).
    pub tilt_deg: Span,
    /// White-noise density, °/s/√Hz, drawn log-uniformly (0.005–0.05; 0–10).
    pub noise_dps_per_sqrt_hz: Span,
    /// Quantum of a reading, °/s (0–10; 0: continuous).
    pub quantum_dps: f64,
}

impl Default for YawRateConfig {
    fn default() -> Self {
        Self::for_car()
    }
}

impl YawRateConfig {
    /// A car's ESP yaw-rate sensor as its CAN bus sends it (table in the module
    /// documentation).
    pub const fn for_car() -> Self {
        Self {
            bias_dps: Span::new(0.01, 3.75),
            bias_walk_dps_per_sqrt_s: Span::new(0.002, 0.01),
            scale_error: 0.10,
            scale_asymmetry: 0.01,
            tilt_deg: Span::new(0.0, 15.0),
            noise_dps_per_sqrt_hz: Span::new(0.005, 0.05),
            quantum_dps: 0.01,
        }
    }

    /// A robot's MEMS gyro.
    pub const fn for_robot() -> Self {
        Self {
            bias_dps: Span::new(0.02, 10.0),
            quantum_dps: 1.0 / 131.0,
            ..Self::for_car()
        }
    }

    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        self.bias_dps.check("yaw bias_dps", 0.0, 100.0)?;
        self.bias_walk_dps_per_sqrt_s
            .check("yaw bias_walk_dps_per_sqrt_s", 0.0, 1.0)?;
        check_range("yaw scale_error", self.scale_error, 0.0, 0.5)?;
        check_range("yaw scale_asymmetry", self.scale_asymmetry, 0.0, 0.2)?;
        self.tilt_deg.check("yaw tilt_deg", 0.0, 60.0)?;
        self.noise_dps_per_sqrt_hz
            .check("yaw noise_dps_per_sqrt_hz", 0.0, 10.0)?;
        check_range("yaw quantum_dps", self.quantum_dps, 0.0, 10.0)?;
        Ok(())
    }
}

/// One yaw-rate sensor's true errors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct YawRateErrors {
    /// The sensing element's errors (bias, walk, scale per direction, noise).
    pub gyro: GyroAxisParams,
    /// Tilt of the sensing axis from the vertical, rad.
    pub tilt_rad: f64,
    /// Quantum of a reading, rad/s (0: continuous).
    pub quantum_rps: f64,
}

impl YawRateErrors {
    /// A sensor drawn from `config`.
    pub fn draw(config: &YawRateConfig, rng: &mut SplitMix64) -> Self {
        let bias = either_sign(rng) * config.bias_dps.draw_log(rng);
        let common = config.scale_error * (2.0 * rng.uniform() - 1.0);
        let half = 0.5 * config.scale_asymmetry * (2.0 * rng.uniform() - 1.0);
        Self {
            gyro: GyroAxisParams {
                bias_rps: bias.to_radians(),
                bias_walk_rps_per_sqrt_s: config.bias_walk_dps_per_sqrt_s.draw(rng).to_radians(),
                scale_error_pos: common + half,
                scale_error_neg: common - half,
                noise_density_rps_per_sqrt_hz: config
                    .noise_dps_per_sqrt_hz
                    .draw_log(rng)
                    .to_radians(),
                ..GyroAxisParams::PERFECT
            },
            tilt_rad: config.tilt_deg.draw(rng).to_radians(),
            quantum_rps: config.quantum_dps.to_radians(),
        }
    }

    /// What the reading is per unit of true yaw rate in a right (`true`) or left turn,
    /// before bias and noise: `cos(tilt) · (1 + scale error)`.
    pub fn gain(&self, right: bool) -> f64 {
        let scale = if right {
            self.gyro.scale_error_pos
        } else {
            self.gyro.scale_error_neg
        };
        self.tilt_rad.cos() * (1.0 + scale)
    }
}

/// `x` to the nearest whole multiple of `quantum` (unchanged when `quantum` is 0).
pub(crate) fn quantized(x: f64, quantum: f64) -> f64 {
    if quantum > 0.0 {
        (x / quantum).round() * quantum
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drawn_errors_cover_their_ranges() {
        let mut rng = SplitMix64::new(11);
        let config = YawRateConfig::for_car();
        let draws: Vec<YawRateErrors> = (0..400)
            .map(|_| YawRateErrors::draw(&config, &mut rng))
            .collect();
        let span = |f: &dyn Fn(&YawRateErrors) -> f64| {
            draws
                .iter()
                .map(f)
                .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)))
        };
        // Scale errors spread over ±10 % (and ±0.5 % more between directions), tilts over
        // 0–15°: the gains from 0.966·0.895 to 1.105.
        let (lo, hi) = span(&|e| e.gyro.scale_error_pos);
        assert!(
            (-0.105..-0.09).contains(&lo) && hi > 0.09 && hi <= 0.105,
            "{lo} {hi}"
        );
        let (lo, hi) = span(&|e| e.tilt_rad.to_degrees());
        assert!(
            (0.0..1.0).contains(&lo) && hi > 14.0 && hi <= 15.0,
            "{lo} {hi}"
        );
        let (lo, hi) = span(&|e| e.gain(false));
        assert!(
            (0.966 * 0.895..0.91).contains(&lo) && hi > 1.08 && hi <= 1.105,
            "{lo} {hi}"
        );
        let biases: Vec<f64> = draws.iter().map(|e| e.gyro.bias_rps.to_degrees()).collect();
        assert!(biases.iter().all(|b| (0.01..=3.75).contains(&b.abs())));
        assert!(biases.iter().any(|b| b.abs() < 0.03) && biases.iter().any(|b| b.abs() > 2.5));
        let positive = biases.iter().filter(|b| **b > 0.0).count();
        assert!((150..250).contains(&positive), "{positive}");
    }

    #[test]
    fn quantizing_rounds_to_whole_quanta() {
        assert_eq!(quantized(0.126, 0.01), 0.13);
        assert_eq!(quantized(-0.124, 0.01), -0.12);
        assert_eq!(quantized(0.3, 0.0), 0.3);
    }
}
