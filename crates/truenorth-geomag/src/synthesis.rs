//! Spherical-harmonic synthesis: the place-dependent terms of the expansion, computed once
//! per point, and the sums that turn them and the Gauss coefficients into the field in the
//! geocentric frame (WMM2025 Technical Report, §1.2, eqs. 9–15).
//!
//! Why a separate "prepared point": everything that depends on the place — the Legendre
//! recursion, cos mλ / sin mλ, the radial powers (a/r)ⁿ⁺² and the geocentric-to-geodetic
//! rotation — is independent of the date. A caller who needs the field at one place for
//! many dates (or repeatedly, as a vehicle's position changes slowly) prepares the point
//! once; each further evaluation is then only the weighted sums over 90 terms.

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

use crate::coefficients::{Coefficients, MAX_DEGREE, index};
use crate::geodetic::Geodetic;
use crate::legendre::SchmidtLegendre;

/// The geomagnetic reference radius a = 6371.2 km of the WMM expansion (WMM2025 Technical
/// Report, eq. 1), metres.
pub const GEOMAGNETIC_REFERENCE_RADIUS_M: f64 = 6_371_200.0;

/// A place with every date-independent term of the expansion precomputed (≈ 2 KB on the
/// stack; no allocation). Build it with [`PreparedPoint::new`] and evaluate it with
/// [`crate::WorldMagneticModel::field_prepared`].
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedPoint {
    geodetic: Geodetic,
    legendre: SchmidtLegendre,
    /// cos(mλ), sin(mλ) for m = 0..=12.
    cos_ml: [f64; MAX_DEGREE + 1],
    sin_ml: [f64; MAX_DEGREE + 1],
    /// (a/r)ⁿ⁺² for n = 0..=12 (slot 0 unused).
    radial: [f64; MAX_DEGREE + 1],
    /// cos φ′, to turn the stored P̆ₙᵐ / cos φ′ back into P̆ₙᵐ.
    cos_gc_lat: f64,
    /// sin and cos of ψ = φ′ − φ, the angle between the geocentric and geodetic verticals.
    sin_psi: f64,
    cos_psi: f64,
}

/// The field (or its secular variation) in the geocentric frame: X′ north, Y′ east, Z′
/// towards the centre, nT (or nT/yr).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Geocentric {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl PreparedPoint {
    /// Precomputes the terms of the expansion at `at`.
    pub fn new(at: &Geodetic) -> Self {
        let sph = at.to_spherical();
        let (sin_gc, cos_gc) = (sph.sin_lat(), sph.cos_lat());
        let legendre = SchmidtLegendre::new(sin_gc, cos_gc);

        // cos mλ, sin mλ by the angle-addition recurrence: one sin_cos instead of twelve.
        let (sin_l, cos_l) = at.lon_rad().sin_cos();
        let mut cos_ml = [0.0; MAX_DEGREE + 1];
        let mut sin_ml = [0.0; MAX_DEGREE + 1];
        cos_ml[0] = 1.0;
        for m in 1..=MAX_DEGREE {
            cos_ml[m] = cos_ml[m - 1] * cos_l - sin_ml[m - 1] * sin_l;
            sin_ml[m] = sin_ml[m - 1] * cos_l + cos_ml[m - 1] * sin_l;
        }

        let ratio = GEOMAGNETIC_REFERENCE_RADIUS_M / sph.radius_m();
        let mut radial = [0.0; MAX_DEGREE + 1];
        // (a/r)² · (a/r)ⁿ, built up by repeated multiplication.
        let mut power = ratio * ratio;
        for r in radial.iter_mut().skip(1) {
            power *= ratio;
            *r = power;
        }

        // ψ = φ′ − φ from the sines and cosines directly (no angle subtraction needed).
        let (sin_gd, cos_gd) = at.lat_rad().sin_cos();
        let sin_psi = sin_gc * cos_gd - cos_gc * sin_gd;
        let cos_psi = cos_gc * cos_gd + sin_gc * sin_gd;

        Self {
            geodetic: *at,
            legendre,
            cos_ml,
            sin_ml,
            radial,
            cos_gc_lat: cos_gc,
            sin_psi,
            cos_psi,
        }
    }

    /// The place this point was prepared for.
    pub fn geodetic(&self) -> &Geodetic {
        &self.geodetic
    }

    /// The Schmidt semi-normalised Legendre functions at this point's geocentric latitude.
    pub fn legendre(&self) -> &SchmidtLegendre {
        &self.legendre
    }

    /// sin and cos of ψ = φ′ − φ, for the rotation to the geodetic frame (eqs. 16–17).
    pub(crate) fn rotation(&self) -> (f64, f64) {
        (self.sin_psi, self.cos_psi)
    }

    /// The main field at `dt_years` after the epoch and its secular variation, both in the
    /// geocentric frame.
    ///
    /// Eq. 9: g(t) = g(t₀) + (t − t₀) ġ(t₀), likewise h. Eqs. 10–12 (main field) and 13–15
    /// (secular variation, the same sums with ġ, ḣ):
    /// X′ = −Σₙ (a/r)ⁿ⁺² Σₘ (g cos mλ + h sin mλ) dP̆ₙᵐ/dφ′,
    /// Y′ = (1/cos φ′) Σₙ (a/r)ⁿ⁺² Σₘ m (g sin mλ − h cos mλ) P̆ₙᵐ,
    /// Z′ = −Σₙ (n+1) (a/r)ⁿ⁺² Σₘ (g cos mλ + h sin mλ) P̆ₙᵐ.
    /// The 1/cos φ′ of Y′ is absorbed by using the stored P̆ₙᵐ / cos φ′ (see `legendre`).
    pub(crate) fn synthesize(&self, c: &Coefficients, dt_years: f64) -> (Geocentric, Geocentric) {
        let l = &self.legendre;
        let cos_gc_lat = self.cos_gc_lat;
        let mut main = Geocentric::default();
        let mut sv = Geocentric::default();
        for n in 1..=MAX_DEGREE {
            let rr = self.radial[n];
            let n1 = (n + 1) as f64;
            let (mut mx, mut my, mut mz) = (0.0, 0.0, 0.0);
            let (mut sx, mut sy, mut sz) = (0.0, 0.0, 0.0);
            for m in 0..=n {
                let k = index(n, m);
                let (cos_m, sin_m) = (self.cos_ml[m], self.sin_ml[m]);
                let (gd, hd) = (c.g_sv[k], c.h_sv[k]);
                let g = c.g[k] + dt_years * gd;
                let h = c.h[k] + dt_years * hd;
                let q = l.scaled[k];
                let p = if m == 0 { q } else { q * cos_gc_lat };
                let dp = l.deriv[k];
                let mf = m as f64;

                let cos_term = g * cos_m + h * sin_m;
                let sin_term = g * sin_m - h * cos_m;
                mx += cos_term * dp;
                my += mf * sin_term * q;
                mz += cos_term * p;

                let cos_term_sv = gd * cos_m + hd * sin_m;
                let sin_term_sv = gd * sin_m - hd * cos_m;
                sx += cos_term_sv * dp;
                sy += mf * sin_term_sv * q;
                sz += cos_term_sv * p;
            }
            main.x -= rr * mx;
            main.y += rr * my;
            main.z -= n1 * rr * mz;
            sv.x -= rr * sx;
            sv.y += rr * sy;
            sv.z -= n1 * rr * sz;
        }
        (main, sv)
    }
}
