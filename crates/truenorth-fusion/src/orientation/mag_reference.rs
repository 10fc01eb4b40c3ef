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
use truenorth_core::{Error, Real, Result, Validate, check_positive, check_range};

use super::min_max::at_most;
use super::real_checks::{check_finite_in, check_range_in};

#[cfg(not(feature = "std"))]
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

/// The tolerances of a [`MagReferenceConfig`] in the reference's float type, as
/// [`MagReference`] compares with them: converted once by the filter that owns it, not per
/// sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MagThresholds<T> {
    /// `(1 − norm_tol_rel)²` (0 beyond a tolerance of 1) and `(1 + norm_tol_rel)²`.
    norm_low2: T,
    norm_high2: T,
    new_reference_s: T,
    /// The moving time a candidate needs, a fifth of `new_reference_s`.
    new_reference_moving_s: T,
    new_reference_min_rate_rps: T,
    /// `1/reference_tau_s` and `1/new_reference_s`, 1/s.
    inv_reference_tau: T,
    inv_new_reference: T,
}

impl<T: Real> MagThresholds<T> {
    pub(crate) fn of(config: &MagReferenceConfig) -> Self {
        let tol = T::of(config.norm_tol_rel);
        let low = if tol < T::one() {
            T::one() - tol
        } else {
            T::zero()
        };
        let high = T::one() + tol;
        Self {
            norm_low2: low * low,
            norm_high2: high * high,
            new_reference_s: T::of(config.new_reference_s),
            new_reference_moving_s: T::of(0.2 * config.new_reference_s),
            new_reference_min_rate_rps: T::of(config.new_reference_min_rate_rps),
            inv_reference_tau: T::of(1.0 / config.reference_tau_s),
            inv_new_reference: T::of(1.0 / config.new_reference_s),
        }
    }
}

/// The learned field reference and the candidate for a new one, each kept as its horizontal
/// and vertical components in the level frame (so that no angle has to be computed per
/// sample: the dip test compares `sin(dip − dip_ref)`, a cross product of the two).
///
/// In the float type `T`; the tolerances stay `f64`, converted for each update (the filter
/// converts them once).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
// `Real` includes serde's bounds on `T`.
#[serde(bound = "")]
pub struct MagReference<T: Real = f64> {
    config: MagReferenceConfig,
    /// `sin(dip_tol_rad)` (the tolerance is at most 90°).
    sin_dip_tol: T,
    horizontal: T,
    vertical: T,
    candidate_horizontal: T,
    candidate_vertical: T,
    candidate_s: T,
    candidate_moving_s: T,
    valid: bool,
    /// The reference's gain for the last interval (recomputed when it changes).
    gain: (T, T),
}

impl MagReference {
    /// No reference yet: the first field offered becomes it. Invalid tolerances are
    /// refused.
    pub fn new(config: MagReferenceConfig) -> Result<Self> {
        Self::with_precision(config)
    }
}

impl<T: Real> MagReference<T> {
    /// As [`MagReference::new`], computing in `T` (`MagReference::<f32>::with_precision(config)`).
    pub fn with_precision(config: MagReferenceConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::with_config(config))
    }

    /// No reference yet, for tolerances already validated (by the filter's config).
    pub(crate) fn with_config(config: MagReferenceConfig) -> Self {
        Self {
            config,
            sin_dip_tol: T::of(config.dip_tol_rad.min(core::f64::consts::FRAC_PI_2).sin()),
            horizontal: T::zero(),
            vertical: T::zero(),
            candidate_horizontal: T::zero(),
            candidate_vertical: T::zero(),
            candidate_s: T::zero(),
            candidate_moving_s: T::zero(),
            valid: false,
            gain: (T::zero(), T::zero()),
        }
    }

    /// Forgets the reference and any candidate; the tolerances stay.
    pub fn reset(&mut self) {
        *self = Self::with_config(self.config);
    }

    /// Judges one field reading, given as its horizontal magnitude and its vertical (down)
    /// component in the estimated level frame (sensor unit), taken `dt_s` after the previous
    /// one while rotating at `rate_rps`. Returns `true` when it is undisturbed (and may
    /// correct heading).
    pub fn update(&mut self, horizontal: T, vertical: T, rate_rps: T, dt_s: T) -> bool {
        let th = MagThresholds::of(&self.config);
        self.update_with(&th, horizontal, vertical, rate_rps, dt_s)
    }

    /// [`Self::update`] with the tolerances already converted (`th` of this reference's
    /// configuration).
    pub(crate) fn update_with(
        &mut self,
        th: &MagThresholds<T>,
        horizontal: T,
        vertical: T,
        rate_rps: T,
        dt_s: T,
    ) -> bool {
        if !self.valid {
            self.adopt(horizontal, vertical);
            return true;
        }
        if self.gain.0 != dt_s {
            self.gain = (dt_s, at_most(dt_s * th.inv_reference_tau, T::one()));
        }
        let k = self.gain.1;
        if self.agrees(th, self.horizontal, self.vertical, horizontal, vertical) {
            self.horizontal += (horizontal - self.horizontal) * k;
            self.vertical += (vertical - self.vertical) * k;
            self.candidate_s = T::zero();
            self.candidate_moving_s = T::zero();
            return true;
        }
        if self.candidate_s > T::zero()
            && self.agrees(
                th,
                self.candidate_horizontal,
                self.candidate_vertical,
                horizontal,
                vertical,
            )
        {
            self.candidate_s += dt_s;
            if rate_rps >= th.new_reference_min_rate_rps {
                self.candidate_moving_s += dt_s;
            }
            let kc = at_most(dt_s * th.inv_new_reference, T::one());
            self.candidate_horizontal += (horizontal - self.candidate_horizontal) * kc;
            self.candidate_vertical += (vertical - self.candidate_vertical) * kc;
        } else {
            self.candidate_horizontal = horizontal;
            self.candidate_vertical = vertical;
            // Positive, as it marks a candidate (in `f32` a step may round to 0).
            self.candidate_s = dt_s.max(T::of(f64::MIN_POSITIVE));
            self.candidate_moving_s = T::zero();
        }
        if self.candidate_s >= th.new_reference_s
            && self.candidate_moving_s >= th.new_reference_moving_s
        {
            self.adopt(self.candidate_horizontal, self.candidate_vertical);
            return true;
        }
        false
    }

    /// The reference field norm (sensor unit) and dip (rad, positive down), once one was
    /// learned.
    pub fn reference(&self) -> Option<(T, T)> {
        self.valid.then(|| {
            (
                self.horizontal.hypot(self.vertical),
                self.vertical.atan2(self.horizontal),
            )
        })
    }

    /// The reference field in the level frame of magnetic north, `(H, 0, Z)` (north, east,
    /// down), once one was learned.
    pub fn reference_ned(&self) -> Option<nalgebra::Vector3<T>> {
        self.valid
            .then(|| nalgebra::Vector3::new(self.horizontal, T::zero(), self.vertical))
    }

    /// Norm within `norm_tol_rel` and dip within `dip_tol_rad` of the reference `(h0, v0)`:
    /// `|sin(dip − dip₀)| = |v·h₀ − h·v₀| / (|m| |m₀|)`, the dips being within ±90°. Both
    /// tests are taken squared, which needs no square root: `(1 − tol)² |m₀|² ≤ |m|² ≤
    /// (1 + tol)² |m₀|²` and `(v·h₀ − h·v₀)² ≤ sin²(dip_tol) |m|² |m₀|²`.
    fn agrees(&self, th: &MagThresholds<T>, h0: T, v0: T, h: T, v: T) -> bool {
        // Components of real fields (and of the clamped readings the filter passes) are far
        // from overflowing a square or a product of two.
        let n02 = h0 * h0 + v0 * v0;
        let n2 = h * h + v * v;
        let cross = v * h0 - h * v0;
        let sin2 = self.sin_dip_tol * self.sin_dip_tol;
        n2 <= th.norm_high2 * n02 && n2 >= th.norm_low2 * n02 && cross * cross <= sin2 * n2 * n02
    }

    /// Checks a restored reference against the tolerances `config` of its filter: the same
    /// tolerances, finite components, times ≥ 0.
    pub(crate) fn check(&self, config: &MagReferenceConfig) -> Result<()> {
        if self.config != *config || self.sin_dip_tol != Self::with_config(*config).sin_dip_tol {
            return Err(Error::InvalidSnapshot {
                reason: "the field reference's tolerances differ from the filter's",
            });
        }
        for v in [
            self.horizontal,
            self.vertical,
            self.candidate_horizontal,
            self.candidate_vertical,
        ] {
            check_finite_in("mag reference component", v)?;
        }
        check_range_in("mag.candidate_s", self.candidate_s, 0.0, f64::MAX)?;
        check_range_in(
            "mag.candidate_moving_s",
            self.candidate_moving_s,
            0.0,
            f64::MAX,
        )?;
        check_range_in("mag.gain", self.gain.1, 0.0, 1.0)?;
        check_range_in("mag.gain interval", self.gain.0, 0.0, f64::MAX)?;
        Ok(())
    }

    fn adopt(&mut self, horizontal: T, vertical: T) {
        self.horizontal = horizontal;
        self.vertical = vertical;
        self.candidate_s = T::zero();
        self.candidate_moving_s = T::zero();
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
            let mut r = MagReference::new(MagReferenceConfig::default()).unwrap();
            for _ in 0..n {
                prop_assert!(r.update(norm * dip.cos(), norm * dip.sin(), 1.0, 0.01));
            }
            let (n0, d0) = r.reference().unwrap();
            prop_assert!((n0 - norm).abs() < 1e-9 * norm && (d0 - dip).abs() < 1e-9);
        }

        #[test]
        fn a_field_that_changes_with_orientation_is_never_adopted(
            norm in 10.0f64..100.0, dip in -1.0f64..1.0, swing in 0.3f64..1.0, seconds in 30.0f64..120.0,
        ) {
            // An attached magnet: the norm swings by ±swing of itself as the sensor turns,
            // never consistent for `new_reference_s`, so it stays rejected.
            let cfg = MagReferenceConfig::default();
            let mut r = MagReference::new(cfg).unwrap();
            r.update(norm * dip.cos(), norm * dip.sin(), 0.0, 0.01);
            let steps = (seconds / 0.01) as usize;
            for k in 0..steps {
                let t = k as f64 * 0.01;
                let seen = norm * (1.0 + swing * (t * 2.0).sin().signum() * (0.5 + 0.5 * (t * 7.0).sin().abs()));
                let ok = r.update(seen * dip.cos(), seen * dip.sin(), 1.0, 0.01);
                if (seen - norm).abs() > cfg.norm_tol_rel * norm * 1.5 {
                    prop_assert!(!ok, "adopted a swinging field at t = {t}");
                }
            }
        }
    }
}
