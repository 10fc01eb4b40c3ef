//! The patent's closed-form effective front track (US 4,788,645 eq. 3 = eq. 14, claims 14,
//! 19, 35, 40):
//!
//! `T_E = T_F·[P + (1 − P)·√(0.5 + 0.5·√(1 − c²/(1 − 0.25c²)·(2B/T_F)²))]`,
//!
//! c = ΔD/AD, P the Pitman-arm ratio (= 2p/T_F for kingpin offset p), B the wheelbase,
//! T_F the nominal front track.
//!
//! How it relates to the exact geometry ([`crate::AckermannGeometry`]): `T_F·P = 2p` is the
//! offsets' contribution, which is exact; `T_F(1 − P) = T_K` times the root approximates the
//! kingpins' own foreshortening. Worked exactly for the kingpins alone, the relation is
//! `u = (T_E,K/T_K)² = ½(1 + c²/4) + ½(1 − c²/4)·√(1 − c²(2B/T_K)²/(1 − c²/4)²)`;
//! the patent drops the c²/4 factors outside the root, uses one power of (1 − c²/4) inside it,
//! puts T_F where T_K belongs and evaluates at the ratio of the wheels rather than of the
//! kingpins. The measured consequence (table in the crate docs and the `ackermann_error`
//! example) is an error below 0.1 % on gentle curves that grows to several per cent near
//! the formula's limit.
//!
//! The inner root goes negative past `c_max = 1/√((2B/T_F)² + 1/4)` (about 0.28 for a
//! typical car; the patent says "approximately 0.27"): that is [`Error::OutOfRange`], never
//! NaN.

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{Error, Result, Validate, check_finite, check_positive, check_range};

use crate::{AckermannParams, EffectiveTrack};

/// US 4,788,645 eq. 14 for one vehicle, with its derived coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatentAckermannTrack {
    wheelbase_m: f64,
    track_m: f64,
    pitman_ratio: f64,
    /// (2B/T_F)².
    aspect_sq: f64,
    /// Where the inner root reaches zero.
    max_ratio: f64,
}

impl PatentAckermannTrack {
    /// The formula for wheelbase B, nominal front track T_F and Pitman-arm ratio P ∈ [0, 1).
    /// The patent gives P as "approx. 1/8" in one place and "approximately 1/3" in another,
    /// so it is a parameter.
    pub fn new(wheelbase_m: f64, track_m: f64, pitman_ratio: f64) -> Result<Self> {
        check_positive("wheelbase_m", wheelbase_m)?;
        check_positive("front track_m", track_m)?;
        // P = 1 would leave no kingpin track at all; check_range includes its upper end.
        let p = check_range("pitman_ratio", pitman_ratio, 0.0, 1.0)?;
        if p == 1.0 {
            return Err(Error::OutOfRange {
                what: "pitman_ratio (must be below 1)",
                value: p,
                min: 0.0,
                max: 1.0,
            });
        }
        let aspect_sq = (2.0 * wheelbase_m / track_m).powi(2);
        Ok(Self {
            wheelbase_m,
            track_m,
            pitman_ratio: p,
            aspect_sq,
            // 1 − c²/(1 − c²/4)·A = 0  ⇔  c² (A + 1/4) = 1.
            max_ratio: 1.0 / (aspect_sq + 0.25).sqrt(),
        })
    }

    /// The formula for a vehicle given by its kingpin offset: P = 2p/T_F.
    pub fn from_params(params: &AckermannParams) -> Result<Self> {
        params.validate()?;
        Self::new(params.wheelbase_m, params.track_m, params.pitman_ratio())
    }

    /// Wheelbase B, m.
    pub fn wheelbase_m(&self) -> f64 {
        self.wheelbase_m
    }

    /// Nominal front track T_F, m.
    pub fn track_m(&self) -> f64 {
        self.track_m
    }

    /// Pitman-arm ratio P.
    pub fn pitman_ratio(&self) -> f64 {
        self.pitman_ratio
    }
}

impl EffectiveTrack for PatentAckermannTrack {
    fn effective_track_m(&self, ratio: f64) -> Result<f64> {
        let c = check_finite("curvature ratio ΔD/AD", ratio)?;
        if c.abs() > self.max_ratio {
            return Err(Error::OutOfRange {
                what: "curvature ratio ΔD/AD (beyond the maximum of US 4,788,645 eq. 14)",
                value: c,
                min: -self.max_ratio,
                max: self.max_ratio,
            });
        }
        let c2 = c * c;
        // Rounding can leave the inner term a hair below zero at exactly c_max.
        let inner = (1.0 - c2 / (1.0 - 0.25 * c2) * self.aspect_sq).max(0.0);
        let root = (0.5 + 0.5 * inner.sqrt()).sqrt();
        let p = self.pitman_ratio;
        Ok(self.track_m * (p + (1.0 - p) * root))
    }

    fn max_ratio(&self) -> f64 {
        self.max_ratio
    }
}
