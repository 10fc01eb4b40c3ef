//! The fit stages of the refresh (1–5): the direct fit of Li & Griffiths (2004) in three
//! steps (reduction, constrained minimum, ellipsoid), the explanation of a failed fit by the
//! share of the sphere seen, the coverage of the calibrated directions, and the residual and
//! information matrix with the direct fit's bias.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use truenorth_compass::CompassCalibration3d;
use truenorth_core::Error;

use super::{PARAMS, Refresh, coverage_of};
use crate::fits::ellipsoid::direct::{
    Ellipsoid, constrained_quadric, quadric_to_ellipsoid, reduce, second_moments,
};
use crate::numerics::linalg::sym_eigen3;
use crate::online::conic::noise_factor;
use crate::online::conic_sums::LAYOUT_3D;
use crate::online::ellipsoid::config::OnlineEllipsoidConfig;
use crate::quality;
use crate::quality::{anisotropy_3d, direct_fit_bias_rad};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

impl Refresh {
    /// After a stage of the fit: a fit that failed on readings that, seen from the centre
    /// of their bounding box, fill less than [`OnlineEllipsoidConfig::min_coverage`] of the
    /// direction cells is better explained by that (a turn about one axis, a small patch of
    /// orientations) than by the symptom (a hyperboloid, a flat quadric). Explains; never
    /// refuses a fit that succeeded, so more readings cannot turn into a refusal here.
    pub(super) fn explain_failure(&mut self, cfg: &OnlineEllipsoidConfig, lifetime: u64) {
        if !matches!(
            self.base.outcome,
            Some(Err(Error::NotAnEllipse { .. } | Error::Degenerate { .. }))
        ) {
            return;
        }
        let now = self.base.sums.count;
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in self.base.slots.live(now, lifetime) {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let centre = (lo + hi) * 0.5;
        let pre = quality::sphere_coverage(self.base.slots.live(now, lifetime), &centre);
        if let Err(e) = quality::require_sphere_coverage(pre, cfg.min_coverage) {
            self.base.map = Some(CompassCalibration3d {
                hard_iron: centre,
                soft_iron: Matrix3::identity(),
            })
            .filter(|m| m.hard_iron.iter().all(|x| x.is_finite()));
            self.base.outcome = Some(Err(e));
        }
    }

    /// Normalise; refuse equal and coplanar readings (the start of stage 1).
    fn normalise(&mut self) {
        let Some((s, centre, scale)) = self.base.sums.normalised(&LAYOUT_3D) else {
            return self.fail(Error::Degenerate {
                reason: "all readings are equal; the sensor must turn so the field direction changes",
            });
        };
        (self.scatter, self.centre, self.scale) = (s, centre, scale);
        let cov = second_moments(&s, self.base.sums.weight());
        match sym_eigen3(&cov) {
            None => self.fail(Error::Degenerate {
                reason: "the readings could not be analysed",
            }),
            Some((l, _)) if l[0] <= 1e-12 => self.fail(Error::Degenerate {
                reason: "the readings lie in a plane (or on a line); tumble the sensor about more than one axis",
            }),
            Some(_) => {}
        }
    }

    /// Stage 1: normalise, then the first step of the direct fit ([`reduce`]): eliminate the
    /// linear terms and refuse a hyperboloid.
    pub(super) fn reduce_stage(&mut self) {
        self.normalise();
        if self.base.outcome.is_some() {
            return;
        }
        match reduce(&self.scatter) {
            Ok(r) => self.reduced = r,
            Err(e) => self.fail(e),
        }
    }

    /// Stage 2: the constrained minimum of the direct fit ([`constrained_quadric`]).
    pub(super) fn constrained_stage(&mut self) {
        match constrained_quadric(&self.reduced) {
            Ok(k) => self.quadric = k,
            Err(e) => self.fail(e),
        }
    }

    /// Stage 3: the ellipsoid of the quadric and its calibration.
    pub(super) fn fit(&mut self, cfg: &OnlineEllipsoidConfig) {
        let e = match quadric_to_ellipsoid(&self.quadric, cfg.limits.max_axis_ratio) {
            Ok(e) => e,
            Err(err) => return self.fail(err),
        };
        let raw = Ellipsoid {
            centre: self.centre + e.centre * self.scale,
            unit_map: e.unit_map / self.scale,
        };
        let (cal, field) = raw.calibration();
        if !(field.is_finite() && field > 0.0 && cal.soft_iron.iter().all(|x| x.is_finite())) {
            return self.fail(Error::Degenerate {
                reason: "the fitted ellipsoid is not finite; check the input scale",
            });
        }
        self.ellipsoid = Some(e);
        (self.cal, self.field) = (cal, field);
        self.base.map = Some(cal);
    }

    /// Stage 4: coverage of the calibrated directions.
    pub(super) fn cover(&mut self, lifetime: u64) {
        self.coverage = coverage_of(&self.base.slots, self.base.sums.count, lifetime, &self.cal);
    }

    /// Stage 5: residual and information matrix from the scatter of the calibrated
    /// readings' design vector (see the two-axis module), and its inverse factor.
    pub(super) fn inform(&mut self) {
        let Some(e) = self.ellipsoid else { return };
        let t = LAYOUT_3D.design_map(&e.unit_map, &(-(e.unit_map * e.centre)));
        let su = t * self.scatter * t.transpose();
        let mut k0 = SVector::<f64, 10>::zeros();
        (k0[0], k0[1], k0[2], k0[9]) = (1.0, 1.0, 1.0, -1.0);
        let ss = 0.25 * (k0.transpose() * su * k0)[0].max(0.0);
        let w = self.base.sums.weight();
        self.residual_rms_rel = (ss / w).sqrt();
        // φ(u) = (−u, u_x², 2u_xu_y, 2u_xu_z, u_y², 2u_yu_z, u_z²) = P ξ(u), with
        // ξ(u) = (u_x², u_y², u_z², 2u_yu_z, 2u_xu_z, 2u_xu_y, 2u_x, 2u_y, 2u_z, 1).
        let mut p = SMatrix::<f64, PARAMS, 10>::zeros();
        for (row, (col, f)) in [
            (6, -0.5),
            (7, -0.5),
            (8, -0.5),
            (0, 1.0),
            (5, 1.0),
            (4, 1.0),
            (1, 1.0),
            (3, 1.0),
            (2, 1.0),
        ]
        .into_iter()
        .enumerate()
        {
            p[(row, col)] = f;
        }
        let info = p * su * p.transpose();
        self.info = (info + info.transpose()) * 0.5;
        (self.sigma, self.l_inv) = noise_factor(&self.base.sums, ss, &self.info);
        // The design vector's sums, (Σx², Σy², Σz², 2Σyz, 2Σxz, 2Σxy, 2Σx, 2Σy, 2Σz, Σ1) of
        // the calibrated directions: their harmonics (h₂ the distance of their second
        // moment from I/3, over √(2/3), its value for readings all in one direction), and
        // the anisotropy of B².
        let c = su.column(9);
        let n = c[9];
        let h1 = Vector3::new(c[6], c[7], c[8]).norm() / (2.0 * n);
        let m = Matrix3::new(
            c[0],
            0.5 * c[5],
            0.5 * c[4],
            0.5 * c[5],
            c[1],
            0.5 * c[3],
            0.5 * c[4],
            0.5 * c[3],
            c[2],
        ) / n
            - Matrix3::identity() / 3.0;
        let h2 = m.norm() / (2.0f64 / 3.0).sqrt();
        let kappa = anisotropy_3d(&(e.unit_map * e.unit_map)).unwrap_or(1.0);
        self.bias_rad = direct_fit_bias_rad(self.sigma, kappa, h1, h2);
    }
}
