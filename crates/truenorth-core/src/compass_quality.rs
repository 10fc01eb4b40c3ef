//! How good a compass calibration is: the report every compass calibrator returns with its
//! solution ([`CompassQuality`]), what the readings determine ([`CompassUncertainty`]) and
//! the verdict read from them ([`crate::Verdict`]).

use serde::{Deserialize, Serialize};

use crate::{FitQuality, Verdict};

#[cfg(not(feature = "std"))]
use crate::Float as _;

/// How good a compass calibration is.
///
/// Heading error has three parts, reported apart so none is mistaken for another:
/// the uncertainty of the fitted parameters (`heading_error_3sigma_deg`), the error the
/// method's model cannot remove whatever the data (`heading_error_systematic_deg`, e.g. a
/// rotated soft iron under a circle-only method), and the noise of each reading, which no
/// calibration removes (`heading_noise_rms_deg`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CompassQuality {
    /// What every calibrator reports.
    pub fit: FitQuality,
    /// Three standard deviations of the heading error caused by the uncertainty of the
    /// fitted parameters, worst over heading, degrees. Excludes per-reading noise.
    #[serde(with = "crate::extended_float::scalar")]
    pub heading_error_3sigma_deg: f64,
    /// Largest heading error the method's model leaves in place even with perfect data,
    /// degrees (0 when the model can represent the distortion it was given).
    #[serde(with = "crate::extended_float::scalar")]
    pub heading_error_systematic_deg: f64,
    /// RMS heading noise of a single calibrated reading, estimated from the residuals,
    /// degrees. Averaging readings reduces it; recalibrating does not.
    #[serde(with = "crate::extended_float::scalar")]
    pub heading_noise_rms_deg: f64,
    /// Fitted field magnitude (horizontal for 2-D, total for 3-D), in the input unit.
    pub field_magnitude: f64,
    /// Fitted field magnitude divided by the expected one (from a geomagnetic model), if
    /// one was supplied. Far from 1 means a disturbed site or wrong units.
    pub field_ratio_to_expected: Option<f64>,
    /// What the readings determine: the dilution of the orientations seen and the predicted
    /// σ of the hard and soft iron, computed by the calibrator with the rest of the report.
    #[serde(default)]
    pub uncertainty: CompassUncertainty,
}

impl CompassQuality {
    /// Bound on the heading error of the calibration itself, degrees: the 3σ parameter
    /// uncertainty plus the systematic part. Per-reading noise comes on top.
    pub fn heading_error_bound_deg(&self) -> f64 {
        self.heading_error_3sigma_deg + self.heading_error_systematic_deg
    }

    /// The verdict on this report: `good`, `usable` or `poor`, and which number decided it.
    ///
    /// A function of the report's own two figures (the bound and the per-reading noise), so
    /// that it can never disagree with them, however the report was made or edited.
    pub fn verdict(&self) -> Verdict {
        Verdict::of(self)
    }
}

/// The dilution `G` of readings spread evenly round a circle (2-D).
pub const DILUTION_EVEN_CIRCLE: f64 = 2.0;

/// The dilution `G` of readings spread evenly over the sphere (3-D): `√13.5`.
pub const DILUTION_EVEN_SPHERE: f64 = 3.674_234_614_174_767;

/// The per-reading error, relative to the field, that a consumer magnetometer keeps after
/// a good calibration and that the determination test assumes: 0.5 %. The real
/// full-sphere recording of an HMC5883L keeps 0.46 %, a tumbled unnamed sensor 1.3 %
/// (truenorth-calib's `tests/real_data.rs`). The test does not use the fit's own residual: a residual made of
/// noise is averaged away by more readings (it is judged by the 3σ bound), and one
/// estimated from a few dozen shots can come out far smaller by chance.
pub const MODEL_ERROR_REL: f64 = 0.005;

/// What the readings determine.
///
/// From the information matrix `A = Σ φ(uᵢ)φ(uᵢ)ᵀ` of the calibrated directions `uᵢ` and
/// the gradient `g(u)` of the heading (3-D: field-direction) error at direction `u`, the
/// dilution is `G = max_u √(N · g(u)ᵀ A⁻¹ g(u))`: independent per-reading errors of σ
/// (relative to the field) give a worst-direction heading error of σ·G/√N, and errors of
/// RMS ε of any kind — systematic ones too — at most G·ε (Cauchy–Schwarz). The derivation
/// and its tests are in truenorth-calib's `quality` module.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CompassUncertainty {
    /// The dilution `G` of the orientations seen (each direction cell once; see the module
    /// documentation): worst-direction heading (3-D: field-direction) error, radians, per
    /// unit of per-reading error relative to the field, for `K` directions times `√K`. 2
    /// for an evenly covered circle, 3.67 for an evenly covered sphere; infinite when the
    /// orientations do not determine the calibration at all.
    #[serde(with = "crate::extended_float::scalar")]
    pub dilution: f64,
    /// Predicted standard deviation (1σ) of each hard-iron component, input unit (3-D:
    /// three values; 2-D: two, the third 0).
    #[serde(with = "crate::extended_float::array3")]
    pub hard_iron_sigma: [f64; 3],
    /// Predicted standard deviation (1σ) of the least determined soft-iron entry, relative
    /// (the soft iron is known to `(I + E)·soft_iron`, this is the largest σ of an entry of
    /// `E`).
    #[serde(with = "crate::extended_float::scalar")]
    pub soft_iron_sigma_rel: f64,
}

impl CompassUncertainty {
    /// Nothing determined.
    pub const UNDETERMINED: Self = Self {
        dilution: f64::INFINITY,
        hard_iron_sigma: [f64::INFINITY; 3],
        soft_iron_sigma_rel: f64::INFINITY,
    };

    /// The largest heading (3-D: field-direction) error, degrees, that a per-reading error
    /// of [`MODEL_ERROR_REL`], random or not, could cause on the orientations seen: `G·ε`
    /// (infinite when they do not determine the calibration).
    pub fn geometry_error_deg(&self) -> f64 {
        let w = (self.dilution * MODEL_ERROR_REL).to_degrees();
        if w.is_finite() { w } else { f64::INFINITY }
    }

    /// How much of an even coverage's information per reading the readings give, in
    /// [0, 1]: `(G_even / G)²` (an even circle or sphere: 1; half as many evenly spread
    /// readings would determine the calibration as well as these: 0.5).
    pub fn efficiency(&self, dimensions: usize) -> f64 {
        let even = if dimensions == 2 {
            DILUTION_EVEN_CIRCLE
        } else {
            DILUTION_EVEN_SPHERE
        };
        let e = (even / self.dilution).powi(2);
        if e.is_finite() { e.min(1.0) } else { 0.0 }
    }
}

impl Verdict {
    /// The verdict on a report (also [`CompassQuality::verdict`]): its heading-error bound and
    /// per-reading noise ([`Verdict::from_figures`]).
    pub fn of(q: &CompassQuality) -> Self {
        Self::from_figures(q.heading_error_bound_deg(), q.heading_noise_rms_deg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn heading_bound_is_uncertainty_plus_systematic(a in 0.0f64..90.0, b in 0.0f64..90.0, n in 0.0f64..10.0) {
            let q = CompassQuality {
                heading_error_3sigma_deg: a,
                heading_error_systematic_deg: b,
                heading_noise_rms_deg: n,
                ..Default::default()
            };
            // Per-reading noise is reported apart and never enters the calibration's bound.
            prop_assert_eq!(q.heading_error_bound_deg(), a + b);
        }

        #[test]
        fn a_report_reads_back_bit_for_bit(
            bound in prop_oneof![Just(f64::INFINITY), 0.0f64..90.0],
            dilution in prop_oneof![Just(f64::INFINITY), 2.0f64..1e4],
            sigma in prop_oneof![Just(f64::INFINITY), 0.0f64..1.0],
        ) {
            // An undetermined calibration's infinite figures survive JSON.
            let q = CompassQuality {
                heading_error_3sigma_deg: bound,
                uncertainty: CompassUncertainty {
                    dilution,
                    hard_iron_sigma: [sigma, 0.5 * sigma, 0.0],
                    soft_iron_sigma_rel: sigma,
                },
                ..Default::default()
            };
            let text = serde_json::to_string(&q).unwrap();
            let back: CompassQuality = serde_json::from_str(&text).unwrap();
            prop_assert_eq!(back, q);
            prop_assert_eq!(back.verdict(), q.verdict());
        }
    }
}
