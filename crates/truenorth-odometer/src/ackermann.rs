//! Exact rigid-body geometry of Ackermann-steered front wheels with a kingpin offset.
//!
//! # Model (plan view)
//!
//! Body axes x forward, y right. The rear axle is the line x = 0; the kingpins (steering
//! pivots) are at (B, ∓T_K/2), and each front wheel's ground contact point sits a distance p
//! outboard of its kingpin along that wheel's axle (the "Pitman arm" of US 4,788,645; in
//! today's terms the kingpin offset at the wheel centre). Straight ahead the contact points
//! are T_F = T_K + 2p apart, the nominal front track.
//!
//! Ackermann steering puts every wheel's axle line through one turn centre O on the rear-axle
//! line, a distance R = 1/|κ| from the rear-axle centre (κ: signed path curvature of the
//! rear-axle centre, positive for a right turn). The body then rotates rigidly about O; a
//! point at distance r from O travels `r·|κ|` metres per metre travelled by the rear-axle
//! centre, and a wheel whose axle points at O rolls without side slip.
//!
//! A kingpin is at distance `r_k = √(B² + (R ± T_K/2)²)` from O (+ outer, − inner). The
//! contact point lies on the line from O through the kingpin (the wheel's axle line), p
//! beyond it for the outer wheel and p short of it for the inner one, so
//! `r = r_k ± p`. Per metre of rear-axle-centre travel, with `h = κ·T_K/2`:
//!
//! `f_L = √((Bκ)² + (1 + h)²) + p·κ`,  `f_R = √((Bκ)² + (1 − h)²) − p·κ`,
//!
//! valid for either sign of κ while both steer angles stay below 90° (|h| < 1).
//! Because `(1+h)² − (1−h)² = 2κT_K`, the exact effective track
//! `T_E = (D_L − D_R)/Δψ = (f_L − f_R)/κ` has the form
//!
//! `T_E(κ) = 2·T_K / (√((Bκ)² + (1+h)²) + √((Bκ)² + (1−h)²)) + 2p`,
//!
//! free of the 0/0 at κ = 0 (`T_E(0) = T_K + 2p = T_F`), strictly falling in |κ| (the
//! denominator is a sum of norms of affine functions of κ, so convex and even in κ).
//!
//! What a differential odometer measures is the ratio `c = ΔD/AD = 2(f_L − f_R)/(f_L + f_R)`
//! (US 4,788,645 calls it the curvature of turn). `c(κ)` rises from 0 to a peak `c_peak` at a
//! tight lock (centre steer angle near 45°) and falls beyond; every real car's lock is on the
//! rising branch, so [`AckermannGeometry::curvature_from_ratio`] inverts that branch.
//!
//! The patent's eq. 3/14 is an approximation of the same geometry; it is in
//! [`crate::PatentAckermannTrack`] so that its error against this exact form can be measured.
//! Not modelled: kingpin inclination, caster, camber, tyre slip angles.

use serde::{Deserialize, Serialize};
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{Error, Result, Validate, check_finite, check_positive, check_range};

use crate::{EffectiveTrack, WheelDistances};

/// Dimensions of an Ackermann-steered front axle. Lengths in metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AckermannParams {
    /// Wheelbase B: rear axle to the front kingpins, m.
    pub wheelbase_m: f64,
    /// Nominal (straight-ahead) front track T_F between the wheels' contact points, m.
    pub track_m: f64,
    /// Kingpin offset p: kingpin to wheel contact point along the wheel's axle, m
    /// (0 ≤ p < T_F/2 and p < B).
    pub kingpin_offset_m: f64,
}

impl AckermannParams {
    /// Dimensions from the patent's Pitman-arm ratio P = p / (T_F/2) (US 4,788,645: "the
    /// ratio of single Pitman arm length to one-half the total track"), i.e. p = P·T_F/2.
    pub fn from_pitman_ratio(wheelbase_m: f64, track_m: f64, pitman_ratio: f64) -> Self {
        Self {
            wheelbase_m,
            track_m,
            kingpin_offset_m: 0.5 * pitman_ratio * track_m,
        }
    }

    /// The patent's Pitman-arm ratio P = 2p / T_F.
    pub fn pitman_ratio(&self) -> f64 {
        2.0 * self.kingpin_offset_m / self.track_m
    }
}

impl Validate for AckermannParams {
    /// B > 0, T_F within [`crate::TRACK_RANGE_M`], 0 ≤ p < min(T_F/2, B), all finite.
    fn validate(&self) -> Result<()> {
        check_positive("wheelbase_m", self.wheelbase_m)?;
        crate::check_track("front track_m", self.track_m)?;
        // p = T_F/2 would put both kingpins on the centre line; p ≥ B would let the inner
        // wheel's contact point reach the turn centre. check_range includes its upper end,
        // so that end is refused separately.
        const WHAT: &str = "kingpin_offset_m (must be below half the track and the wheelbase)";
        let max = (0.5 * self.track_m).min(self.wheelbase_m);
        let p = check_range(WHAT, self.kingpin_offset_m, 0.0, max)?;
        if p == max {
            return Err(Error::OutOfRange {
                what: WHAT,
                value: p,
                min: 0.0,
                max,
            });
        }
        Ok(())
    }
}

/// Quantities derived from [`AckermannParams`] once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AckermannCoefficients {
    /// Distance between the kingpins, T_K = T_F − 2p, m.
    pub kingpin_track_m: f64,
    /// Curvatures must stay below this in magnitude (inner steer angle 90°), 1/m.
    pub curvature_limit_per_m: f64,
    /// Curvature at which the measured ratio ΔD/AD peaks, 1/m.
    pub peak_curvature_per_m: f64,
    /// The largest ratio ΔD/AD the geometry can produce.
    pub peak_ratio: f64,
}

/// The exact front-wheel geometry of [`AckermannParams`] (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AckermannGeometry {
    params: AckermannParams,
    coeffs: AckermannCoefficients,
}

/// Path length of the two front contact points per metre of rear-axle-centre travel.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Factors {
    left: f64,
    right: f64,
}

impl AckermannGeometry {
    /// Builds the geometry, finding the peak of ΔD/AD numerically.
    pub fn new(params: AckermannParams) -> Result<Self> {
        params.validate()?;
        let kingpin_track_m = params.track_m - 2.0 * params.kingpin_offset_m;
        let limit = 2.0 / kingpin_track_m;
        let mut g = Self {
            params,
            coeffs: AckermannCoefficients {
                kingpin_track_m,
                curvature_limit_per_m: limit,
                peak_curvature_per_m: 0.0,
                peak_ratio: 0.0,
            },
        };
        let k_peak = g.find_peak(limit);
        g.coeffs.peak_curvature_per_m = k_peak;
        g.coeffs.peak_ratio = g.ratio_unchecked(k_peak);
        Ok(g)
    }

    /// The dimensions.
    pub fn params(&self) -> &AckermannParams {
        &self.params
    }

    /// The derived coefficients.
    pub fn coefficients(&self) -> &AckermannCoefficients {
        &self.coeffs
    }

    /// Largest |ΔD/AD| the geometry can produce (at [`AckermannCoefficients::peak_curvature_per_m`]).
    pub fn peak_ratio(&self) -> f64 {
        self.coeffs.peak_ratio
    }

    /// Largest curvature [`Self::curvature_from_ratio`] can return, 1/m.
    pub fn peak_curvature_per_m(&self) -> f64 {
        self.coeffs.peak_curvature_per_m
    }

    /// Maximises c(κ) on (0, limit): a coarse scan, then golden-section search around the
    /// best grid point. c(κ) is smooth and single-peaked there (checked by a test).
    fn find_peak(&self, limit: f64) -> f64 {
        const SCAN: usize = 256;
        let top = limit * (1.0 - 1e-9);
        let step = top / SCAN as f64;
        let mut best_i = 1;
        let mut best_c = f64::NEG_INFINITY;
        for i in 1..=SCAN {
            let c = self.ratio_unchecked(step * i as f64);
            if c > best_c {
                best_c = c;
                best_i = i;
            }
        }
        let mut a = step * (best_i - 1) as f64;
        let mut b = (step * (best_i + 1) as f64).min(top);
        let inv_phi = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..200 {
            if b - a <= 1e-15 * b {
                break;
            }
            let x1 = b - inv_phi * (b - a);
            let x2 = a + inv_phi * (b - a);
            if self.ratio_unchecked(x1) < self.ratio_unchecked(x2) {
                a = x1;
            } else {
                b = x2;
            }
        }
        0.5 * (a + b)
    }

    fn check_curvature(&self, curvature_per_m: f64) -> Result<f64> {
        let k = check_finite("curvature_per_m", curvature_per_m)?;
        let limit = self.coeffs.curvature_limit_per_m;
        if k.abs() >= limit {
            return Err(Error::OutOfRange {
                what: "curvature_per_m (inner front wheel would steer 90° or more)",
                value: k,
                min: -limit,
                max: limit,
            });
        }
        Ok(k)
    }

    /// √((Bκ)² + (1 ± κT_K/2)²): kingpin distance from the turn centre times |κ|.
    #[inline]
    fn kingpin_factors(&self, k: f64) -> (f64, f64) {
        let bk = self.params.wheelbase_m * k;
        let h = 0.5 * k * self.coeffs.kingpin_track_m;
        (bk.hypot(1.0 + h), bk.hypot(1.0 - h))
    }

    #[inline]
    fn factors(&self, k: f64) -> Factors {
        let (rho_l, rho_r) = self.kingpin_factors(k);
        let pk = self.params.kingpin_offset_m * k;
        Factors {
            left: rho_l + pk,
            right: rho_r - pk,
        }
    }

    #[inline]
    fn track_unchecked(&self, k: f64) -> f64 {
        let (rho_l, rho_r) = self.kingpin_factors(k);
        2.0 * self.coeffs.kingpin_track_m / (rho_l + rho_r) + 2.0 * self.params.kingpin_offset_m
    }

    #[inline]
    fn ratio_unchecked(&self, k: f64) -> f64 {
        let f = self.factors(k);
        // ΔD/AD = 2(f_L − f_R)/(f_L + f_R) with f_L − f_R = κ·T_E, exact near κ = 0.
        2.0 * k * self.track_unchecked(k) / (f.left + f.right)
    }

    /// Path lengths of the left and right front contact points while the rear-axle centre
    /// travels `ds_m` (signed; negative when reversing) on curvature `curvature_per_m`.
    pub fn wheel_paths_m(&self, ds_m: f64, curvature_per_m: f64) -> Result<WheelDistances> {
        let ds = check_finite("ds_m", ds_m)?;
        let f = self.factors(self.check_curvature(curvature_per_m)?);
        Ok(WheelDistances {
            left_m: check_finite("left wheel path (ds_m too large)", ds * f.left)?,
            right_m: check_finite("right wheel path (ds_m too large)", ds * f.right)?,
        })
    }

    /// Steer angles of the left and right wheels, radians, positive to the right:
    /// `atan(Bκ / (1 ± κT_K/2))` — each wheel's axle then points at the turn centre.
    pub fn steer_angles_rad(&self, curvature_per_m: f64) -> Result<(f64, f64)> {
        let k = self.check_curvature(curvature_per_m)?;
        let bk = self.params.wheelbase_m * k;
        let h = 0.5 * k * self.coeffs.kingpin_track_m;
        Ok((bk.atan2(1.0 + h), bk.atan2(1.0 - h)))
    }

    /// Exact effective track `T_E = (D_L − D_R)/Δψ` at curvature κ, m.
    pub fn effective_track_at_curvature_m(&self, curvature_per_m: f64) -> Result<f64> {
        Ok(self.track_unchecked(self.check_curvature(curvature_per_m)?))
    }

    /// The ratio ΔD/AD the front wheels produce at curvature κ (signed like κ).
    pub fn ratio_at_curvature(&self, curvature_per_m: f64) -> Result<f64> {
        Ok(self.ratio_unchecked(self.check_curvature(curvature_per_m)?))
    }

    /// The curvature κ (on the rising branch, |κ| ≤ peak) whose ratio ΔD/AD is `ratio`.
    /// Bisection to full `f64` precision (c(κ) is increasing there), so it costs about a
    /// hundred square roots; [`crate::EffectiveTrackTable`] is the cheap alternative.
    pub fn curvature_from_ratio(&self, ratio: f64) -> Result<f64> {
        let c = check_finite("curvature ratio ΔD/AD", ratio)?;
        let peak = self.coeffs.peak_ratio;
        if c.abs() > peak {
            return Err(Error::OutOfRange {
                what: "curvature ratio ΔD/AD (beyond the tightest turn the front-wheel geometry can make)",
                value: c,
                min: -peak,
                max: peak,
            });
        }
        let target = c.abs();
        let (mut lo, mut hi) = (0.0, self.coeffs.peak_curvature_per_m);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if self.ratio_unchecked(mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let k = if (self.ratio_unchecked(hi) - target).abs()
            < (target - self.ratio_unchecked(lo)).abs()
        {
            hi
        } else {
            lo
        };
        Ok(if c < 0.0 { -k } else { k })
    }

    /// Rear-axle-centre distance and heading change from the front wheels' true path lengths
    /// (the inverse of [`Self::wheel_paths_m`] on the rising branch).
    pub fn motion_from_paths(&self, left_m: f64, right_m: f64) -> Result<RigidMotion> {
        let l = check_finite("left wheel distance", left_m)?;
        let r = check_finite("right wheel distance", right_m)?;
        let sum = check_finite("sum of wheel distances (inputs too large)", l + r)?;
        if sum == 0.0 {
            if l - r == 0.0 {
                return Ok(RigidMotion::default());
            }
            // Front wheels of an Ackermann vehicle cannot turn it on the spot.
            return Err(Error::OutOfRange {
                what: "curvature ratio ΔD/AD (wheels moved in opposite directions by equal amounts)",
                value: f64::INFINITY,
                min: -self.coeffs.peak_ratio,
                max: self.coeffs.peak_ratio,
            });
        }
        let k = self.curvature_from_ratio(2.0 * (l - r) / sum)?;
        let f = self.factors(k);
        let ds_m = sum / (f.left + f.right);
        check_finite("distance (inputs too large)", k * ds_m)?;
        Ok(RigidMotion {
            ds_m,
            heading_change_rad: k * ds_m,
        })
    }
}

impl EffectiveTrack for AckermannGeometry {
    /// Exact: the curvature whose ratio is `ratio`, then `T_E` there.
    fn effective_track_m(&self, ratio: f64) -> Result<f64> {
        Ok(self.track_unchecked(self.curvature_from_ratio(ratio)?))
    }

    fn max_ratio(&self) -> f64 {
        self.coeffs.peak_ratio
    }
}

/// Motion of the rear-axle centre over one step, as recovered from wheel distances.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct RigidMotion {
    /// Distance travelled by the rear-axle centre, m (negative when reversing).
    pub ds_m: f64,
    /// Heading change, radians, positive for a right turn.
    pub heading_change_rad: f64,
}

#[cfg(test)]
#[path = "ackermann_tests.rs"]
mod tests;
