//! Whether an estimator's reported uncertainty covers its error: the normalised estimation
//! error squared (NEES) of heading and position at every row of a drive, as estimation
//! people test a filter's consistency (Bar-Shalom, Li & Kirubarajan, *Estimation with
//! Applications to Tracking and Navigation*, 2001, §5.4).
//!
//! For a consistent estimate the heading's error over its σ is standard normal, so 0.27 %
//! of the rows lie beyond 3σ; the position's NEES is χ² with two degrees of freedom, so
//! 0.27 % lie beyond 11.83. The rows of one drive are correlated in time, so these shares
//! are judged over an ensemble of drives.

use truenorth_core::{Error, NavEstimate, Result, angle_diff};

use crate::VehicleTruth;
use crate::drive_score::truth_in_frame;

/// χ² with two degrees of freedom beyond which 0.27 % of a consistent estimate's rows lie
/// (the two-dimensional counterpart of 3σ): `−2 ln 0.0027`.
pub const CHI2_2DOF_3SIGMA: f64 = 11.829;

/// How one quantity's errors compare with its reported uncertainty.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Normalised {
    /// Rows judged (those with a finite, positive uncertainty).
    pub rows: usize,
    /// Rows beyond the 3σ equivalent.
    pub beyond_3sigma: usize,
    /// The largest error over its σ (for position, √NEES).
    pub max_sigmas: f64,
    /// Sum of the NEES over the rows (its mean is the dimension for a consistent estimate).
    pub sum_nees: f64,
}

impl Normalised {
    fn add(&mut self, nees: f64, limit: f64) {
        self.rows += 1;
        self.beyond_3sigma += usize::from(nees > limit);
        self.max_sigmas = self.max_sigmas.max(nees.sqrt());
        self.sum_nees += nees;
    }

    /// Adds another drive's figures.
    pub fn merge(&mut self, other: &Self) {
        self.rows += other.rows;
        self.beyond_3sigma += other.beyond_3sigma;
        self.max_sigmas = self.max_sigmas.max(other.max_sigmas);
        self.sum_nees += other.sum_nees;
    }

    /// Share of the rows beyond the 3σ equivalent.
    pub fn share_beyond(&self) -> f64 {
        if self.rows == 0 {
            0.0
        } else {
            self.beyond_3sigma as f64 / self.rows as f64
        }
    }

    /// Mean NEES.
    pub fn mean_nees(&self) -> f64 {
        if self.rows == 0 {
            0.0
        } else {
            self.sum_nees / self.rows as f64
        }
    }
}

/// Heading and position consistency of a drive's estimates.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Consistency {
    /// Heading error over the reported heading σ.
    pub heading: Normalised,
    /// Position NEES against the reported position covariance.
    pub position: Normalised,
}

impl Consistency {
    /// Judges `estimates` against `truth`, one for one. A heading not yet referred to north
    /// is compared with the true heading change since the first row, and its track with
    /// the truth turned so that the start heading points north.
    pub fn of(truth: &[VehicleTruth], estimates: &[NavEstimate]) -> Result<Self> {
        if estimates.len() != truth.len() || truth.is_empty() {
            return Err(Error::OutOfRange {
                what: "number of estimates (one per row of the drive)",
                value: estimates.len() as f64,
                min: truth.len() as f64,
                max: truth.len() as f64,
            });
        }
        let psi0 = truth[0].heading_rad;
        let mut c = Self::default();
        for (e, t) in estimates.iter().zip(truth) {
            let absolute = e.status.heading_absolute;
            let sigma = e.heading_sigma_rad;
            if sigma.is_finite() && sigma > 1e-9 {
                let reference = if absolute {
                    t.heading_rad
                } else {
                    t.heading_rad - psi0
                };
                let z = angle_diff(e.heading.rad(), reference) / sigma;
                c.heading.add(z * z, 9.0);
            }
            let p = e.position_cov_m2;
            if e.status.position_known
                && p.iter().all(|v| v.is_finite())
                && let Some(inv) = p.try_inverse().filter(|_| p.determinant() > 0.0)
            {
                let (n, ea) = truth_in_frame(t, psi0, absolute);
                let d = nalgebra::Vector2::new(e.north_m - n, e.east_m - ea);
                c.position
                    .add((d.transpose() * inv * d)[(0, 0)], CHI2_2DOF_3SIGMA);
            }
        }
        Ok(c)
    }

    /// Adds another drive's figures.
    pub fn merge(&mut self, other: &Self) {
        self.heading.merge(&other.heading);
        self.position.merge(&other.position);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DriveSpec, SimulatedDrive};
    use truenorth_core::{MagneticHeading, NoiseSource, SplitMix64};

    /// Estimates whose errors are drawn from exactly the σ they report score as a Gaussian
    /// does; errors twice their σ do not.
    #[test]
    fn drawn_errors_score_as_drawn() {
        let d = SimulatedDrive::new(DriveSpec {
            length_m: 3000.0,
            ..DriveSpec::new(1)
        })
        .unwrap();
        for (factor, consistent) in [(1.0, true), (2.0, false)] {
            let mut rng = SplitMix64::new(7);
            let sigma = 0.01;
            let est: Vec<NavEstimate> = d
                .truth
                .iter()
                .map(|t| {
                    let mut e = NavEstimate::at_start(
                        t.t_s,
                        MagneticHeading::new(t.heading_rad + factor * rng.normal(sigma)),
                        sigma,
                    );
                    e.status.heading_absolute = true;
                    e.status.position_known = true;
                    e.north_m = t.north_m + factor * rng.normal(2.0);
                    e.east_m = t.east_m + factor * rng.normal(2.0);
                    e.position_cov_m2 = nalgebra::Matrix2::identity() * 4.0;
                    e
                })
                .collect();
            let c = Consistency::of(&d.truth, &est).unwrap();
            let n = c.heading.rows as f64;
            // 0.27 % beyond 3σ, give or take four binomial standard deviations.
            let slack = 4.0 * (0.0027 * n).sqrt() / n;
            assert_eq!(
                c.heading.share_beyond() < 0.0027 + slack,
                consistent,
                "{c:?}"
            );
            assert_eq!(
                c.position.share_beyond() < 0.0027 + slack,
                consistent,
                "{c:?}"
            );
            assert_eq!((c.heading.mean_nees() - 1.0).abs() < 0.1, consistent);
        }
    }
}
