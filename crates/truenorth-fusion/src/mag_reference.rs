//! Magnetic-disturbance detection: the earth's field has a fixed strength and dip at a
//! place, so a reading whose norm or dip (in the estimated level frame) strays from the
//! learned reference is disturbed, and heading must not be corrected with it.
//!
//! A field that stays different but self-consistent for long enough while the sensor moves
//! is taken as the new reference (the sensor was carried to another place or mounted
//! differently), as the magnetic-disturbance rejection of Laidig & Seel, *VQF* (2023),
//! §IV-D does; a field whose norm and dip keep changing with orientation (a magnet attached
//! to the sensor) never becomes consistent and stays rejected.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_positive, check_range};

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Tolerances of the disturbance detector.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MagReferenceConfig {
    /// Largest relative deviation of the field norm from the reference (default 0.1).
    pub norm_tol_rel: f64,
    /// Largest deviation of the dip from the reference, rad (default 10°).
    pub dip_tol_rad: f64,
    /// Time constant with which an accepted field refines the reference, s (default 20).
    pub reference_tau_s: f64,
    /// Time a different but self-consistent field must last, with the sensor moving,
    /// before it becomes the new reference, s (default 20).
    pub new_reference_s: f64,
    /// Smallest rotation rate that counts as moving for the new-reference test, rad/s
    /// (default 20°/s): a field seen only from one orientation cannot be told from a
    /// disturbance.
    pub new_reference_min_rate_rps: f64,
}

impl Default for MagReferenceConfig {
    fn default() -> Self {
        Self {
            norm_tol_rel: 0.1,
            dip_tol_rad: 10f64.to_radians(),
            reference_tau_s: 20.0,
            new_reference_s: 20.0,
            new_reference_min_rate_rps: 20f64.to_radians(),
        }
    }
}

impl Validate for MagReferenceConfig {
    /// Every tolerance and time positive, the minimum rate in [0, 1000] rad/s.
    fn validate(&self) -> Result<()> {
        check_positive("mag.norm_tol_rel", self.norm_tol_rel)?;
        check_positive("mag.dip_tol_rad", self.dip_tol_rad)?;
        check_positive("mag.reference_tau_s", self.reference_tau_s)?;
        check_positive("mag.new_reference_s", self.new_reference_s)?;
        check_range(
            "mag.new_reference_min_rate_rps",
            self.new_reference_min_rate_rps,
            0.0,
            1e3,
        )?;
        Ok(())
    }
}

/// The learned field reference and the candidate for a new one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MagReference {
    config: MagReferenceConfig,
    norm: f64,
    dip_rad: f64,
    candidate_norm: f64,
    candidate_dip_rad: f64,
    candidate_s: f64,
    candidate_moving_s: f64,
    valid: bool,
}

impl MagReference {
    /// No reference yet: the first field offered becomes it.
    pub fn new(config: MagReferenceConfig) -> Self {
        Self {
            config,
            norm: 0.0,
            dip_rad: 0.0,
            candidate_norm: 0.0,
            candidate_dip_rad: 0.0,
            candidate_s: 0.0,
            candidate_moving_s: 0.0,
            valid: false,
        }
    }

    /// Judges one field reading (norm in the sensor's unit, dip in the estimated level
    /// frame) taken `dt_s` after the previous one, while rotating at `rate_rps`. Returns
    /// `true` when it is undisturbed (and may correct heading).
    pub fn update(&mut self, norm: f64, dip_rad: f64, rate_rps: f64, dt_s: f64) -> bool {
        if !self.valid {
            self.adopt(norm, dip_rad);
            return true;
        }
        let k = (dt_s / self.config.reference_tau_s).min(1.0);
        if self.agrees(self.norm, self.dip_rad, norm, dip_rad) {
            self.norm += (norm - self.norm) * k;
            self.dip_rad += (dip_rad - self.dip_rad) * k;
            self.candidate_s = 0.0;
            self.candidate_moving_s = 0.0;
            return true;
        }
        if self.candidate_s > 0.0
            && self.agrees(self.candidate_norm, self.candidate_dip_rad, norm, dip_rad)
        {
            self.candidate_s += dt_s;
            if rate_rps >= self.config.new_reference_min_rate_rps {
                self.candidate_moving_s += dt_s;
            }
            let kc = (dt_s / self.config.new_reference_s).min(1.0);
            self.candidate_norm += (norm - self.candidate_norm) * kc;
            self.candidate_dip_rad += (dip_rad - self.candidate_dip_rad) * kc;
        } else {
            self.candidate_norm = norm;
            self.candidate_dip_rad = dip_rad;
            self.candidate_s = dt_s.max(f64::MIN_POSITIVE);
            self.candidate_moving_s = 0.0;
        }
        if self.candidate_s >= self.config.new_reference_s
            && self.candidate_moving_s >= 0.2 * self.config.new_reference_s
        {
            self.adopt(self.candidate_norm, self.candidate_dip_rad);
            return true;
        }
        false
    }

    /// The reference field norm (sensor unit) and dip (rad), once one was learned.
    pub fn reference(&self) -> Option<(f64, f64)> {
        self.valid.then_some((self.norm, self.dip_rad))
    }

    fn agrees(&self, ref_norm: f64, ref_dip: f64, norm: f64, dip: f64) -> bool {
        (norm - ref_norm).abs() <= self.config.norm_tol_rel * ref_norm
            && (dip - ref_dip).abs() <= self.config.dip_tol_rad
    }

    fn adopt(&mut self, norm: f64, dip_rad: f64) {
        self.norm = norm;
        self.dip_rad = dip_rad;
        self.candidate_s = 0.0;
        self.candidate_moving_s = 0.0;
        self.valid = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn the_learned_field_is_never_disturbed(norm in 1.0f64..100.0, dip in -1.4f64..1.4, n in 1usize..500) {
            let mut r = MagReference::new(MagReferenceConfig::default());
            for _ in 0..n {
                prop_assert!(r.update(norm, dip, 1.0, 0.01));
            }
        }

        #[test]
        fn a_field_that_changes_with_orientation_is_never_adopted(
            norm in 10.0f64..100.0, dip in -1.0f64..1.0, swing in 0.3f64..1.0, seconds in 30.0f64..120.0,
        ) {
            // An attached magnet: the norm swings by ±swing of itself as the sensor turns,
            // never consistent for `new_reference_s`, so it stays rejected.
            let cfg = MagReferenceConfig::default();
            let mut r = MagReference::new(cfg);
            r.update(norm, dip, 0.0, 0.01);
            let steps = (seconds / 0.01) as usize;
            for k in 0..steps {
                let t = k as f64 * 0.01;
                let seen = norm * (1.0 + swing * (t * 2.0).sin().signum() * (0.5 + 0.5 * (t * 7.0).sin().abs()));
                let ok = r.update(seen, dip, 1.0, 0.01);
                if (seen - norm).abs() > cfg.norm_tol_rel * norm * 1.5 {
                    prop_assert!(!ok, "adopted a swinging field at t = {t}");
                }
            }
        }
    }
}
